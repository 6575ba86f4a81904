"""``Demonstrator``: the scripted caregiver of the imitation task, who shows one action.

| | |
|---|---|
| reads | at reset and each step, from the task (duck-typed: ``env.task.demonstrated_action``, the name of the episode's action, and ``env.task.demo_steps``, the length of the demonstration phase in steps; ``env.task.step_count``) |
| acts | through its own arm motors only (``actuation="positional"``: the controls are target angles, :func:`~mimo_social.body.actuation.positional_controls`): holds its start pose for ``lead_s``, moves its arms to the action's pose (:data:`ACTION_POSES`) in ``move_s`` (the targets interpolated linearly), holds it ``hold_s``, moves back in ``move_s`` and holds its start pose for the rest of the episode (still during the learner's turn). A demonstration phase shorter than the script compresses it in proportion |
| poses | per action, target angles (deg) of the arm joints, the same for the kneeling adult and an 18-month-old (found by a grid search over shoulder, elbow angles, `tests/tasks/test_imitation.py` checks that each produces its outcome for both bodies): `head_touch` right hand on top of the head; `hand_raise` right arm straight up; `clap` both arms forward, hands together in front of the chest |

The same poses are what the scripted learner
(:class:`~mimo_social.partners.controllers.imitation.ImitationController`) reproduces.
"""

from __future__ import annotations

import numpy as np

from ..util.checks import check_number
from .base import Partner, agent_index, motor_action

__all__ = ["Demonstrator", "ACTION_POSES", "PoseScript"]

#: the arm pose (joint -> degrees) that produces each action's outcome
ACTION_POSES: dict[str, dict[str, float]] = {
    "head_touch": {"right_shoulder_abduction": 140.0, "right_shoulder_horizontal": 60.0,
                   "right_shoulder_rotation": -60.0, "right_elbow": -130.0},
    "hand_raise": {"right_shoulder_abduction": 170.0, "right_elbow": -10.0},
    "clap": {"right_shoulder_abduction": 90.0, "right_shoulder_horizontal": 110.0,
             "right_elbow": -30.0, "left_shoulder_abduction": 90.0,
             "left_shoulder_horizontal": 110.0, "left_elbow": -30.0},
}


class PoseScript:
    """Positional controls of one agent that go from its start pose (the arm angles at reset)
    to an action's pose and, optionally, back: ``controls(k)`` at step ``k`` of the script
    (``start``, ``move`` and ``hold`` in steps; ``back``: return to the start pose after the
    hold)."""

    def __init__(self, env, agent: str, who: str):
        i = agent_index(env, agent)
        act = env.actuation[i]
        if getattr(act, "name", None) != "positional":
            raise ValueError(f"{who}: {agent} has actuation={getattr(act, 'name', act)!r}; "
                             "allowed: 'positional' (its controls are target angles)")
        a = env.world.agents[i]
        names = a.actuated_names
        q = env.world.data.qpos[a.qpos_adr[a.actuated_joint_idx]]
        self.act = act
        self.start = act.controls_for(dict(zip(names, q))).astype(np.float32)
        self.names = names

    def pose_controls(self, action: str) -> np.ndarray:
        """Controls that target ``action``'s pose (its other arm joints at the start pose)."""
        pose = {k: np.deg2rad(v) for k, v in ACTION_POSES[action].items() if k in self.names}
        start = dict(zip(self.names, self.act.targets(self.start)))
        return self.act.controls_for({**start, **pose}).astype(np.float32)

    @staticmethod
    def blend(a: np.ndarray, b: np.ndarray, x: float) -> np.ndarray:
        x = float(np.clip(x, 0.0, 1.0))
        return ((1.0 - x) * a + x * b).astype(np.float32)


class Demonstrator(Partner):
    """Shows the task's action of the episode, then holds still (see the module table)."""

    def __init__(self, lead_s: float = 0.3, move_s: float = 0.5, hold_s: float = 1.0):
        self.lead_s = check_number("Demonstrator", "lead_s", lead_s, 0.0, 10.0)
        self.move_s = check_number("Demonstrator", "move_s", move_s, 0.01, 10.0)
        self.hold_s = check_number("Demonstrator", "hold_s", hold_s, 0.01, 10.0)

    def __repr__(self):
        return (f"Demonstrator(lead_s={self.lead_s}, move_s={self.move_s}, "
                f"hold_s={self.hold_s})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        task = env.task
        if not hasattr(task, "demonstrated_action"):
            raise ValueError(f"Demonstrator: the task {task.name!r} demonstrates no action; "
                             "allowed: the imitation task")
        self._script = PoseScript(env, agent, "Demonstrator")
        self._target = self._script.pose_controls(task.demonstrated_action)
        dt = float(env.dt)
        total = (self.lead_s + 2 * self.move_s + self.hold_s) / dt
        squeeze = min(1.0, 0.95 * task.demo_steps / total)
        self._lead = self.lead_s / dt * squeeze
        self._move = max(1.0, self.move_s / dt * squeeze)
        self._hold = self.hold_s / dt * squeeze

    def act(self, env, agent, observation):
        k = env.task.step_count     # the step about to be taken is k + 1
        s = self._script
        t = k - self._lead
        if t <= 0:
            u = s.start
        elif t <= self._move:
            u = s.blend(s.start, self._target, t / self._move)
        elif t <= self._move + self._hold:
            u = self._target
        else:
            u = s.blend(self._target, s.start, (t - self._move - self._hold) / self._move)
        return motor_action(env.action_space(agent), u)
