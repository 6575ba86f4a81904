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

    def __init__(self, action: str | None = None, move_s: float = 0.3):
        if action is not None and not (isinstance(action, str) and action in ACTION_POSES):
            raise ValueError(f"ImitationController: action={action!r}; allowed: None or one "
                             f"of {list(ACTION_POSES)}")
        self.action = action
        self.move_s = check_number("ImitationController", "move_s", move_s, 0.01, 10.0)

    def __repr__(self):
        return f"ImitationController(action={self.action!r}, move_s={self.move_s})"

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
        self._since = 0

    def act(self, env, agent, observation):
        if env.task.turn:
            self._since += 1
        u = PoseScript.along(self._path, self._since / self._move)
        return motor_action(env.action_space(agent), u)
