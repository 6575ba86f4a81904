"""``ImitationController``: the scripted learner of the imitation task (an oracle baseline).

reads:
    from the task (duck-typed): the episode's demonstrated action (``env.task.demonstrated_action``)
    and whether the learner's turn has begun (``env.task.turn``): what a learner has to find out
    from its eyes
acts:
    through its own arm motors only (``actuation="positional"``): holds its start pose through the
    demonstration, then moves its arms through the action's poses
    (:data:`~mimo_social.tasks.imitation.demonstrator.ACTION_POSES`, the demonstrator's own),
    ``move_s`` (0.3 s) each, and holds the last; it needs ``actuation="positional"``; it writes no
    state
prepare:
    with ``prepare`` > 0 (0: off) it starts the act while it watches: ``prepare_at_s`` (0.8 s, when
    the demonstrator's arm has reached its first pose: its ``lead_s`` + ``move_s``) into the
    demonstration it moves that share (at most 0.7: at 0.9 the raised palm is already over the
    head) of the way to the act's first pose (over ``move_s``), short of the act's outcome, and
    holds it; in its turn it goes on from there. What it saw is then kept
    in its own posture: the demonstration a policy without memory can clone (its posture and the
    ``turn`` flag are all its turn needs), where the plain script (``prepare`` 0) acts from a
    memory a feed-forward policy does not have

``ImitationController(action="clap")`` performs one fixed action whatever was demonstrated (the
"always the same act" hack, and the way the tests make each action's outcome on purpose).
Measured success on ``imitation_v0``: see the task's table.
"""

from __future__ import annotations

from ...util.checks import check_number
from ...partners.base import Partner, motor_action
from .demonstrator import ACTION_POSES, PoseScript
from .task import Imitation

__all__ = ["ImitationController"]


class ImitationController(Partner):
    """Reproduce the demonstrated action in the learner's turn (see the module table);
    ``action``: a fixed action instead (a name of
    :data:`~mimo_social.tasks.imitation.demonstrator.ACTION_POSES`)."""

    def __init__(self, action: str | None = None, move_s: float = 0.3, prepare: float = 0.0,
                 prepare_at_s: float = 0.8):
        if action is not None and not (isinstance(action, str) and action in ACTION_POSES):
            raise ValueError(f"ImitationController: action={action!r}; allowed: None or one "
                             f"of {list(ACTION_POSES)}")
        self.action = action
        self.move_s = check_number("ImitationController", "move_s", move_s, 0.01, 10.0)
        self.prepare = check_number("ImitationController", "prepare", prepare, 0.0, 0.7)
        self.prepare_at_s = check_number("ImitationController", "prepare_at_s", prepare_at_s,
                                         0.0, 10.0)

    def __repr__(self):
        return (f"ImitationController(action={self.action!r}, move_s={self.move_s}, "
                f"prepare={self.prepare}, prepare_at_s={self.prepare_at_s})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        task = env.task
        if not isinstance(task, Imitation):
            raise ValueError(f"ImitationController: the task {task.name!r} demonstrates no "
                             "action; allowed: the imitation task")
        self._script = PoseScript(env, agent, "ImitationController")
        action = self.action or task.demonstrated_action
        self._path = self._script.path(action)
        self._move = max(1.0, self.move_s / float(env.dt))
        self._prepare_at = self.prepare_at_s / float(env.dt)
        self._since = 0
        self._x = 0.0       # how far along the act's path its arms are sent (in poses)

    def act(self, env, agent, observation):
        task = env.task
        if task.turn:
            self._since += 1
            x = self._x + self._since / self._move
        else:               # the step about to be taken is step_count + 1
            k = task.step_count + 1 - self._prepare_at
            self._x = x = self.prepare * min(1.0, max(0.0, k / self._move))
        u = PoseScript.along(self._path, x)
        return motor_action(env.action_space(agent), u)
