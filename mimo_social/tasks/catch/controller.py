"""``CatchController``: the scripted solution of the catch task, through the infant's own muscles.

The infant stands with the right arm stretched forward, palm up; only the right wrist and the
fingers move (the catch task). The controller

wrist:
    holds the palm tilted into a shallow cup: the palm's normal leans ``tilt[0]`` (slope, default
    0.2) toward the thumb and ``tilt[1]`` (0.05) toward the wrist, so a ball landing in it rolls
    against the thumb and the base of the fingers instead of off the little finger's side (solved
    once per reset by damped least squares on a scratch copy of the state). PD control per joint
    toward those angles, gains from the joint's own inertia plus a ball of ``ball_mass`` kg 5 cm
    away (natural frequency ``frequency`` 6 Hz, damping ratio ``damping`` 1), plus gravity /
    passive-spring compensation read from MuJoCo (``qfrc_bias``, ``qfrc_spring``)
fingers:
    before the ball touches the hand: PD toward a loose cup (``cup``: mcp, pip, dip degrees, default
    20, 20, 10; spread and the little finger's cup at their start angles); from the first step the
    ball touches the hand on: a constant flexing command ``grip`` (0.3 of full activation, or of the
    motor's strength with spring-damper motors) on every mcp, pip and dip joint
controls:
    muscles: the agonist's activation giving the wanted torque at the current length on top of the
    passive muscle forces (isometric curve, clipped to [0, 1], antagonist off):
    :func:`torque_controls`; spring-damper motors: ``u = tau / T_max`` clipped to [-1, 1]
reads:
    the joint state, MuJoCo's bias forces, and whether the ball touches the hand (the contacts); it
    writes nothing but the agent's action
state:
    ``touched`` (bool: the ball has touched the hand this episode), ``target_angles`` (rad, per
    motor)

It needs the right wrist's 3 joints and the fingers' joints in the agent's action (the catch
task's action). Measured success rate: the catch tests (``tests/tasks/test_catch.py``).
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...body.joint_groups import RIGHT_WRIST
from ...core.kinematics import hand_geoms
from ...util.checks import ConfigError, check_number, check_numbers, show
from ...partners.base import (Partner, agent_motors, motor_action, pd_gains,
                               require_prop, torque_controls)

__all__ = ["CatchController", "palm_cup_angles"]

FLEXORS = ("mcp", "pip", "dip")


def _number(name, value, lo, hi):
    return check_number("CatchController", name, value, lo, hi)


def palm_cup_angles(world, i: int, tilt=(0.2, 0.05), iters: int = 100) -> np.ndarray:
    """Angles (rad) of agent ``i``'s right wrist joints (:data:`RIGHT_WRIST` order) at which the
    right palm faces up, its normal leaning ``tilt[0]`` toward the thumb and ``tilt[1]`` toward
    the wrist (slopes); damped least squares from the current state, on a scratch copy."""
    m = world.model
    a = world.agents[i]
    k = [a.joint_names.index(n) for n in RIGHT_WRIST]
    qadr, dadr = a.qpos_adr[k], a.dof_adr[k]
    lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
    d = mujoco.MjData(m)
    d.qpos[:] = world.data.qpos
    hand = int(m.site_bodyid[a.palm_sites[0]])
    jr = np.zeros((3, m.nv))
    for _ in range(iters):
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        R = d.xmat[hand].reshape(3, 3)
        normal = -R[:, 1]                      # the right palm faces the hand's -y
        want = np.array([0.0, 0.0, 1.0]) + tilt[0] * R[:, 0] - tilt[1] * R[:, 2]
        want[2] = 1.0
        err = np.cross(normal, want / np.linalg.norm(want))
        if np.linalg.norm(err) < 1e-6:
            break
        mujoco.mj_jacBody(m, d, None, jr, hand)
        J = jr[:, dadr]
        step = J.T @ np.linalg.solve(J @ J.T + 1e-4 * np.eye(3), err)
        d.qpos[qadr] = np.clip(d.qpos[qadr] + np.clip(step, -0.2, 0.2), lo, hi)
    return d.qpos[qadr].copy()


class CatchController(Partner):
    """Catch the falling ball in a cupped palm and close the fingers on it (see the module table).

    ``tilt``: the palm's lean (slopes toward the thumb, toward the wrist); ``frequency`` (Hz) and
    ``damping`` (ratio): the PD loop; ``ball_mass``: the ball (kg) the wrist gains allow for;
    ``cup``: the fingers' mcp, pip, dip angles (deg) before the touch; ``grip``: the fingers'
    flexing command after it, in [0, 1]; ``prop``: the ball's prop name.
    """

    def __init__(self, tilt=(0.2, 0.05), frequency: float = 6.0, damping: float = 1.0,
                 ball_mass: float = 0.3, cup=(20.0, 20.0, 10.0), grip: float = 0.3,
                 prop: str = "ball"):
        self.tilt = check_numbers("CatchController", "tilt", tilt, 2, -2.0, 2.0,
                                  "(toward the thumb, toward the wrist), two slopes within "
                                  "[-2, 2]")
        self.cup = check_numbers("CatchController", "cup", cup, 3, 0.0, 90.0,
                                 "(mcp, pip, dip) degrees, each from 0 to 90")
        if not isinstance(prop, str) or not prop:
            raise ConfigError(f"CatchController: prop={show(prop)} not allowed; allowed: the "
                              "ball's prop name")
        self.frequency = _number("frequency", frequency, 0.1, 30.0)
        self.damping = _number("damping", damping, 0.1, 5.0)
        self.ball_mass = _number("ball_mass", ball_mass, 0.0, 10.0)
        self.grip = _number("grip", grip, 0.0, 1.0)
        self.prop = prop

    def __repr__(self):
        return (f"CatchController(tilt={self.tilt}, frequency={self.frequency}, "
                f"grip={self.grip})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        w = env.world
        m, d = w.model, w.data
        motors = agent_motors("CatchController", env, agent, RIGHT_WRIST, "it needs the right "
                              "wrist's and fingers' motors in its action (the catch task)")
        require_prop("CatchController", w, self.prop)
        i, names, self._act = motors.index, motors.names, motors.act
        self._qadr, self._dadr = motors.qpos_adr, motors.dof_adr
        wrist = np.array([n in RIGHT_WRIST for n in names])
        self._flex = np.array([n not in RIGHT_WRIST and "thumb" not in n
                               and n.split("_")[-1] in FLEXORS for n in names])
        target = d.qpos[self._qadr].copy()
        target[wrist] = palm_cup_angles(w, i, self.tilt)[[RIGHT_WRIST.index(n)
                                                         for n in names if n in RIGHT_WRIST]]
        cup = dict(zip(FLEXORS, np.deg2rad(self.cup)))
        for k, n in enumerate(names):
            if self._flex[k]:
                target[k] = cup[n.split("_")[-1]]
        self.target_angles = np.clip(target, motors.lo, motors.hi)
        ball = np.zeros(len(self._dadr))
        ball[wrist] = self.ball_mass * 0.05 ** 2
        self._kp, self._kd = pd_gains(m, d, self._dadr, self.frequency, self.damping, ball)
        self._ball = int(np.flatnonzero(m.geom_bodyid == w.prop_bodies[self.prop])[0])
        self._hand = np.zeros(m.ngeom, bool)
        self._hand[hand_geoms(w, i, 0)] = True
        self.touched = False

    def _ball_on_hand(self, d) -> bool:
        n = d.ncon
        if n == 0:
            return False
        c = d.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        on = ((g1 == self._ball) & self._hand[g2]) | ((g2 == self._ball) & self._hand[g1])
        return bool(np.any(on & (c.dist[:n] <= 0.0)))

    def act(self, env, agent, observation):
        d = env.world.data
        if not self.touched and self._ball_on_hand(d):
            self.touched = True
        q, qd = d.qpos[self._qadr], d.qvel[self._dadr]
        tau = self._kp * (self.target_angles - q) - self._kd * qd
        tau += d.qfrc_bias[self._dadr] - d.qfrc_spring[self._dadr]
        u = torque_controls(self._act, q, tau)
        if self.touched:
            flex = self._flex
            if self._act.name == "muscle":
                n = len(flex)
                u[:n][flex] = 0.0
                u[n:][flex] = self.grip
            else:
                u[flex] = self.grip
        return motor_action(env.action_space(agent), u)
