"""``Demonstrator``: the scripted caregiver of the imitation task, who shows one action.

reads:
    at reset and each step, from the task (duck-typed: ``env.task.demonstrated_action``, the name of
    the episode's action, and ``env.task.demo_steps``, the length of the demonstration phase in
    steps; ``env.task.step_count``)
acts:
    through its own arm motors only (``actuation="positional"``: the controls are target angles,
    :func:`~mimo_social.body.actuation.positional_controls`): holds its start pose for ``lead_s``,
    moves its arms through the action's poses (:data:`ACTION_POSES`), ``move_s`` each (the targets
    interpolated linearly), holds the last ``hold_s``, moves back the same way and holds its start
    pose for the rest of the episode (still during the learner's turn). A demonstration phase
    shorter than the script compresses it in proportion
poses:
    per action, target angles (deg) of the arm joints (:data:`ACTION_POSES`), the same for the
    kneeling adult and an 18-month-old, found by searches over shoulder and elbow angles
    (kinematics, then simulation with both bodies): `head_touch` right hand on the head;
    `hand_raise` right arm straight up; `clap` both arms forward, hands together in front of the
    chest; `push_box` two poses: the right hand lifted behind its box, then reaching forward through
    it (`tests/tasks/test_imitation.py` checks that each produces its outcome alone, for both
    bodies)

The same poses are what the scripted learner
(:class:`~mimo_social.tasks.imitation.controller.ImitationController`) reproduces.
"""

from __future__ import annotations

import numpy as np

from ...util.checks import check_number
from ...partners.base import Partner, agent_index, motor_action

__all__ = ["Demonstrator", "ACTION_POSES", "PoseScript"]

#: the arm pose (joint -> degrees) that produces each action's outcome
ACTION_POSES: dict[str, dict[str, float]] = {
    "head_touch": {"right_shoulder_abduction": 140.0, "right_shoulder_horizontal": 60.0,
                   "right_shoulder_rotation": -60.0, "right_elbow": -130.0},
    "hand_raise": {"right_shoulder_abduction": 170.0, "right_elbow": -10.0},
    "clap": {"right_shoulder_abduction": 90.0, "right_shoulder_horizontal": 110.0,
             "right_elbow": -30.0, "left_shoulder_abduction": 90.0,
             "left_shoulder_horizontal": 110.0, "left_elbow": -30.0},
    "push_box": [{"right_shoulder_abduction": 100.0, "right_shoulder_horizontal": 0.0,
                  "right_shoulder_rotation": 60.0, "right_elbow": -90.0},
                 {"right_shoulder_abduction": 70.0, "right_shoulder_horizontal": 40.0,
                  "right_shoulder_rotation": 30.0, "right_elbow": -20.0}],
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

    def path(self, action: str) -> list[np.ndarray]:
        """The controls of the start pose, then of each of ``action``'s poses (its other arm
        joints at the start pose)."""
        poses = ACTION_POSES[action]
        poses = [poses] if isinstance(poses, dict) else list(poses)
        start = dict(zip(self.names, self.act.targets(self.start)))
        out = [self.start]
        for pose in poses:
            angles = {k: np.deg2rad(v) for k, v in pose.items() if k in self.names}
            out.append(self.act.controls_for({**start, **angles}).astype(np.float32))
        return out

    @staticmethod
    def along(path: list[np.ndarray], x: float) -> np.ndarray:
        """The controls ``x`` segments along ``path`` (0: its first pose, ``len(path) - 1``:
        its last; linear between)."""
        x = float(np.clip(x, 0.0, len(path) - 1))
        k = min(int(x), len(path) - 2)
        f = x - k
        return ((1.0 - f) * path[k] + f * path[k + 1]).astype(np.float32)


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
        self._path = self._script.path(task.demonstrated_action)
        n = len(self._path) - 1        # moves out (and as many back)
        dt = float(env.dt)
        total = (self.lead_s + 2 * n * self.move_s + self.hold_s) / dt
        squeeze = min(1.0, 0.95 * task.demo_steps / total)
        self._lead = self.lead_s / dt * squeeze
        self._move = max(1.0, self.move_s / dt * squeeze)
        self._hold = self.hold_s / dt * squeeze

    def act(self, env, agent, observation):
        k = env.task.step_count     # the step about to be taken is k + 1
        path = self._path
        n = len(path) - 1
        t = (k - self._lead) / self._move          # in moves since the start of the first
        if t <= n:
            u = PoseScript.along(path, t)
        else:
            t -= n + self._hold / self._move
            u = PoseScript.along(path, n - max(t, 0.0))
        return motor_action(env.action_space(agent), u)
