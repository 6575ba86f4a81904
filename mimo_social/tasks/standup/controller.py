"""``StandupController``: a scripted solution of the standup task (pull to stand on the crib rail).

push and pull:
    the feet and hands are welded, so the body rises by pushing them: each foot pushes on the floor
    with ``foot_force`` (N, world frame; default 60 N down) and each hand pulls on the rail with
    ``hand_force`` (default 10 N down and 10 N back toward the body); the joint torques are ``J^T
    F`` over the agent's motors (``J``: the foot's or hand's Jacobian, read from MuJoCo at every
    step)
posture:
    plus a compliant PD per joint toward a *standing posture* (:data:`STAND_DEG`: trunk, hips, knees
    and ankles straight; the other joints keep their start angle), gains ``stiffness`` (0.3) times
    those of a ``frequency`` (3 Hz) loop from the joint's own inertia (the diagonal of the
    joint-space mass matrix at reset), critically damped, plus gravity / Coriolis and passive-spring
    compensation (``qfrc_bias``, ``qfrc_spring``)
controls:
    the torque becomes the agent's controls ``u = tau / T_max``, clipped to [-1, 1]
acts through:
    the agent's own motors only (no state writes, no model edits); it reads the state (joint angles,
    velocities, Jacobians)

Spring-damper motors only (the standup task's actuation); both hand versions. Measured
(``python tests/tasks/test_standup.py 20``): 20/20 seeded episodes succeed (the head 22.8 cm up
and held; it passes 20 cm after 0.58 s), return 226.6; with the start perturbation 10 times
the task's (``task_options={"perturbation": 0.1}``) 10/10, the head 21.3-22.8 cm up.
"""

from __future__ import annotations

from collections.abc import Mapping

import mujoco
import numpy as np

from ...util.checks import check_number, check_numbers
from ...partners.base import (Partner, agent_index, check_angles, motor_action,
                              push_torques, torque_motors)

__all__ = ["STAND_DEG", "StandupController"]

#: the standing posture of the compliant PD (degrees): trunk, hips, knees and ankles straight
STAND_DEG = {
    "lower_trunk_bend": 0.0,
    "right_hip_flexion": 0.0, "left_hip_flexion": 0.0,
    "right_knee": 0.0, "left_knee": 0.0,
    "right_ankle_flexion": 0.0, "left_ankle_flexion": 0.0,
}
FOOT_FORCE = (0.0, 0.0, -60.0)   # N, world frame, on each foot (pushes the body up)
HAND_FORCE = (-10.0, 0.0, -10.0)  # N, world frame, on each hand (pulls the body up and forward)


class StandupController(Partner):
    """Push with the feet, pull with the hands, and lean toward a standing posture (merged over
    :data:`STAND_DEG`), through the infant's own motors (see the module table)."""

    def __init__(self, posture: Mapping[str, float] | None = None,
                 foot_force=FOOT_FORCE, hand_force=HAND_FORCE, stiffness: float = 0.3,
                 frequency: float = 3.0):
        self.posture_deg = {**STAND_DEG, **check_angles("StandupController", "posture",
                                                        {} if posture is None else posture)}
        self.foot_force = self._force("foot_force", foot_force)
        self.hand_force = self._force("hand_force", hand_force)
        self.stiffness = check_number("StandupController", "stiffness", stiffness, 0.0, 10.0)
        self.frequency = check_number("StandupController", "frequency", frequency, 0.1, 20.0)

    @staticmethod
    def _force(name, value) -> np.ndarray:
        return np.array(check_numbers("StandupController", name, value, 3, -500.0, 500.0,
                                      "(x, y, z) in N, world frame, each within 500"))

    def __repr__(self):
        return (f"StandupController(foot_force={tuple(self.foot_force)}, "
                f"hand_force={tuple(self.hand_force)}, stiffness={self.stiffness})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        w = env.world
        m, d = w.model, w.data
        a = w.agents[agent_index(env, agent)]
        motors = torque_motors("StandupController", env, agent)
        self._act, names = motors.act, motors.names
        self._qadr, self._dadr, lo, hi = motors.qpos_adr, motors.dof_adr, motors.lo, motors.hi
        self._q0 = d.qpos[self._qadr].copy()
        goal = [np.deg2rad(self.posture_deg[n]) if n in self.posture_deg else self._q0[k]
                for k, n in enumerate(names)]
        self.target_angles = np.clip(goal, lo, hi)
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M)
        inertia = np.diag(M)[self._dadr]
        omega = 2 * np.pi * self.frequency
        self._kp = self.stiffness * inertia * omega ** 2
        self._kd = 2 * np.sqrt(self.stiffness) * inertia * omega  # critically damped
        pre = a.name + "/"
        self._pushers = [(m.body(pre + f"{s}_foot").id, self.foot_force) for s in ("right", "left")] \
            + [(m.body(pre + f"{s}_hand").id, self.hand_force) for s in ("right", "left")]
        self._jac = np.zeros((3, m.nv))

    def act(self, env, agent, observation):
        m, d = env.world.model, env.world.data
        q, qd = d.qpos[self._qadr], d.qvel[self._dadr]
        tau = self._kp * (self.target_angles - q) - self._kd * qd
        tau += d.qfrc_bias[self._dadr] - d.qfrc_spring[self._dadr]
        tau += push_torques(m, d, self._jac, self._dadr, self._pushers)
        u = np.clip(np.where(tau >= 0, tau / self._act.torque_pos, tau / self._act.torque_neg),
                    -1.0, 1.0).astype(np.float32)
        return motor_action(env.action_space(agent), u)
