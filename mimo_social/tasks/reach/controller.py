"""``ReachController``: the scripted solution of the reach task (an oracle baseline).

reads:
    at reset, from the world: where the ball is (the prop body ``ball``), the right shoulder, the
    right arm's joints; each step: the arm's joint angles and speeds, and MuJoCo's passive and bias
    forces on them
target:
    the arm posture whose right fingertips lie ``depth`` inside the ball on the line from the
    shoulder to the ball's centre, the fingers straight: damped least squares over shoulder, elbow
    and wrist, once per reset, on a scratch copy of the state, from the middle of the joint ranges
    (the hand leads: the arm stretches toward the ball)
arm:
    PD control per joint toward the target angles, gains from each joint's own inertia (the diagonal
    of the joint-space mass matrix at reset; natural frequency ``frequency``, damping ratio
    ``damping``), plus compensation of MuJoCo's bias forces (``qfrc_bias``) and joint springs
    (``qfrc_spring``); the torque becomes the agent's controls: spring-damper motors ``u = tau /
    T_max`` clipped to [-1, 1]; muscles: the agonist's activation giving ``tau`` at the current
    length on top of the passive muscle forces (isometric curve, clipped to [0, 1], antagonist off)
acts:
    only through the agent's action; it writes no state and changes no model value

Measured success on ``reach_v0`` (tests/tasks/test_reach.py): see the task's table.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...body.joint_groups import RIGHT_SHOULDER_ELBOW, RIGHT_WRIST
from ...core.kinematics import reach_sites
from ...util.checks import check_number
from ...partners.base import Partner, agent_motors, motor_action, pd_gains, require_prop

__all__ = ["ReachController"]

ARM = RIGHT_SHOULDER_ELBOW + RIGHT_WRIST
BALL_RADIUS_FALLBACK = 0.025


class ReachController(Partner):
    """Stretch the right arm so that the fingertips go ``depth`` (m) into the ball, by PD control
    through the agent's own motors (see the module table); ``prop``: the ball's prop name;
    ``frequency`` (Hz) and ``damping`` (ratio): the PD loop."""

    def __init__(self, depth: float = 0.01, prop: str = "ball", frequency: float = 3.0,
                 damping: float = 1.0):
        self.depth = check_number("ReachController", "depth", depth, 0.0, 0.05)
        if not isinstance(prop, str) or not prop:
            raise ValueError(f"ReachController: prop={prop!r}; allowed: the name of a prop")
        self.prop = prop
        self.frequency = check_number("ReachController", "frequency", frequency, 0.1, 20.0)
        self.damping = check_number("ReachController", "damping", damping, 0.1, 5.0)

    def __repr__(self):
        return (f"ReachController(depth={self.depth}, frequency={self.frequency}, "
                f"damping={self.damping})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        w = env.world
        m, d = w.model, w.data
        motors = agent_motors("ReachController", env, agent, ARM, "it needs the right arm's "
                              "motors (shoulder, elbow, wrist) in its action")
        require_prop("ReachController", w, self.prop)
        i, a, names, lo, hi = motors.index, motors.tables, motors.names, motors.lo, motors.hi
        self._qadr, self._dadr = motors.qpos_adr, motors.dof_adr
        arm = np.array([names.index(n) for n in ARM])
        # the goal: `depth` inside the ball, on the line from the shoulder to its centre
        body = w.prop_bodies[self.prop]
        geoms = np.flatnonzero(m.geom_bodyid == body)
        radius = float(m.geom_size[geoms[0], 0]) if len(geoms) else BALL_RADIUS_FALLBACK
        ball = d.xpos[body].copy()
        shoulder = d.xpos[m.jnt_bodyid[m.dof_jntid[self._dadr[arm[0]]]]].copy()
        u = (ball - shoulder) / np.linalg.norm(ball - shoulder)
        self.goal = ball - (radius - self.depth) * u
        # inverse kinematics on a scratch copy: the arm from the middle of its ranges, fingers
        # straight (0 within their ranges)
        s = mujoco.MjData(m)
        s.qpos[:] = d.qpos
        target = np.clip(np.zeros(len(names)), lo, hi)
        target[arm] = 0.5 * (lo[arm] + hi[arm])
        s.qpos[self._qadr] = target
        self.residual = reach_sites(m, s, self._qadr[arm], self._dadr[arm], lo[arm], hi[arm],
                                    int(a.fingertip_sites[0]), self.goal, iters=100)
        target[arm] = s.qpos[self._qadr[arm]]
        self.target_angles = target
        self._kp, self._kd = pd_gains(m, d, self._dadr, self.frequency, self.damping)
        self._act = env.actuation[i]
        self._muscle = self._act.name == "muscle"
        if not self._muscle:
            self._tneg, self._tpos = self._act.torque_neg, self._act.torque_pos

    def torques(self, env) -> np.ndarray:
        """The joint torques wanted now (PD + compensation), one per motor."""
        d = env.world.data
        q, qd = d.qpos[self._qadr], d.qvel[self._dadr]
        tau = self._kp * (self.target_angles - q) - self._kd * qd
        return tau + d.qfrc_bias[self._dadr] - d.qfrc_spring[self._dadr]

    def act(self, env, agent, observation):
        tau = self.torques(env)
        if self._muscle:
            act = self._act
            q = env.world.data.qpos[self._qadr]
            n_full, p_full = act.isometric_torque(q, 1.0)
            n_rest, p_rest = act.isometric_torque(q, 0.0)
            need = tau - (n_rest + p_rest)
            neg = np.clip(need / np.minimum(n_full - n_rest, -1e-9), 0.0, 1.0)
            pos = np.clip(need / np.maximum(p_full - p_rest, 1e-9), 0.0, 1.0)
            u = np.concatenate([neg, pos])
        else:
            u = np.clip(np.where(tau >= 0, tau / self._tpos, tau / self._tneg), -1.0, 1.0)
        return motor_action(env.action_space(agent), u)
