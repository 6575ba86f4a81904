"""``ReceiveController``: the scripted receiver of the handover task, through the infant's motors.

The receiver stands facing the giver, who holds a ball out on its upturned right palm. The
controller holds its own right hand out, open and palm up, next to the giver's hand (the
request gesture of give-and-take games), lets the ball roll into it and closes the fingers on it:

reads:
    the ball's position (the prop body ``prop``) at reset and at each phase change, the right arm's
    joints, MuJoCo's bias and spring forces on them, and the ball's contacts (whether it touches the
    own right hand, whether another agent's hand still touches it); it writes nothing but the
    agent's action
posture:
    the *cup*: the palm centre ``offset`` (forward, left, up; m, in the receiver's heading frame)
    from the ball (default the task's ready point,
    :data:`~mimo_social.tasks.handover.READY_OFFSET`: 1 cm ahead, 5.5 cm to the right, 4.7 cm
    lower: beside the giver's palm, on its little-finger side, where the giver waits for an open
    hand), the palm facing up and leaning ``lean`` (slopes toward the wrist and toward the thumb)
    so a ball that rolls in settles against the palm's heel and the thumb; fingers pointing
    straight ahead, slightly curled (``cup_deg``: mcp, pip, dip), the thumb at rest; solved by
    damped least squares over shoulder, elbow and wrist (palm position and hand orientation
    together) on a scratch copy of the state
phases:
    ``reach``: PD toward the cup posture via a point ``below`` (m) lower and 3 cm further out (so
    the hand comes up beside the giver's, not through it), then the cup itself; ``cup``: hold the
    cup; ``close`` (once the ball has touched the own hand for ``close_after`` s): the fingers' and
    thumb's flexors get the constant command ``grip`` (a gentle grip, of the motor's strength or of
    full activation: the fingers curl over the ball, up to ~0.3 radii past its centre: the closed
    hand the task's success needs), the arm holds; ``hold`` (once no other hand has touched the
    ball for ``settle`` s): the hand draws back ``draw_back`` (m) toward the body and keeps the
    grip
arm:
    PD control per joint toward the phase's target angles, gains from each joint's own inertia (the
    diagonal of the joint-space mass matrix at reset; natural frequency ``frequency``, damping ratio
    ``damping``) plus the bias-force and passive-spring compensation read from MuJoCo
    (``qfrc_bias``, ``qfrc_spring``); torques become controls as in
    :func:`~mimo_social.partners.base.torque_controls` (spring-damper motors ``u = tau / T_max``;
    muscles: the agonist's activation on the isometric curve)
state:
    ``phase`` (str), ``residual`` (m: the IK's remaining palm distance at the cup),
    ``target_angles`` (rad, per motor)

It needs the right arm's motors (shoulder, elbow, wrist) and the five fingers' in its action (the
handover task's action). Measured success: the handover table (``tasks/handover/__init__.py``)
and ``tests/tasks/test_receive_controller.py``. :class:`CupAndLeave` and :class:`OpenPalm` are
hacks the task must not reward (checks, not solutions).
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...body.joint_groups import RIGHT_SHOULDER_ELBOW, RIGHT_WRIST
from ...core.kinematics import hand_geoms
from ...util.checks import ConfigError, check_number, check_numbers, show
from ...partners.base import (Partner, agent_motors, motor_action, pd_gains,
                               require_prop, torque_controls)
from .task import READY_OFFSET


__all__ = ["ReceiveController", "CupAndLeave", "OpenPalm", "hand_frame", "palm_posture"]

ARM = RIGHT_SHOULDER_ELBOW + RIGHT_WRIST
PHASES = ("reach", "cup", "close", "hold")
FLEXORS = ("mcp", "pip", "dip", "ip")


def _number(name, value, lo, hi):
    return check_number("ReceiveController", name, value, lo, hi)


def _triple(name, value, lo, hi) -> tuple[float, ...]:
    return check_numbers("ReceiveController", name, value, 3, lo, hi,
                         f"three numbers from {lo:g} to {hi:g}")


def hand_frame(normal, fingers) -> np.ndarray:
    """The right hand's orientation (world; columns: the hand body's x, y, z axes) whose palm
    faces ``normal`` (the right palm faces the hand's -y) and whose fingers (+z) point along
    ``fingers`` (made orthogonal to the normal)."""
    n = np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    f = np.asarray(fingers, float)
    f = f - (f @ n) * n
    f = f / np.linalg.norm(f)
    y = -n
    return np.stack([np.cross(y, f), y, f], axis=1)


def palm_posture(world, i: int, palm_goal, frame, start=None, iters: int = 150):
    """Right-arm angles (rad, :data:`ARM` order) that put agent ``i``'s right palm centre at
    ``palm_goal`` (world) with the hand's orientation ``frame`` (3x3, columns the hand's axes):
    damped least squares over position and orientation together (orientation weighted 5 cm per
    rad), on a scratch copy of the state, from ``start`` (default: the current angles).
    Returns (angles, position error m, orientation error rad)."""
    m = world.model
    a = world.agents[i]
    k = [a.joint_names.index(n) for n in ARM]
    qadr, dadr = a.qpos_adr[k], a.dof_adr[k]
    lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
    d = mujoco.MjData(m)
    d.qpos[:] = world.data.qpos
    if start is not None:
        d.qpos[qadr] = start
    site = int(a.palm_sites[0])
    hand = int(m.site_bodyid[site])
    jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    goal = np.asarray(palm_goal, float)
    w_rot = 0.05

    def errors():
        R = d.xmat[hand].reshape(3, 3)
        er = 0.5 * (np.cross(R[:, 0], frame[:, 0]) + np.cross(R[:, 1], frame[:, 1])
                    + np.cross(R[:, 2], frame[:, 2]))
        return goal - d.site_xpos[site], er

    for _ in range(iters):
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        ep, er = errors()
        if np.linalg.norm(ep) < 1e-5 and np.linalg.norm(er) < 1e-4:
            break
        mujoco.mj_jacSite(m, d, jp, None, site)
        mujoco.mj_jacBody(m, d, None, jr, hand)
        J = np.vstack([jp[:, dadr], w_rot * jr[:, dadr]])
        e = np.concatenate([ep, w_rot * er])
        step = J.T @ np.linalg.solve(J @ J.T + 1e-5 * np.eye(6), e)
        d.qpos[qadr] = np.clip(d.qpos[qadr] + np.clip(step, -0.2, 0.2), lo, hi)
    mujoco.mj_kinematics(m, d)
    ep, er = errors()
    return d.qpos[qadr].copy(), float(np.linalg.norm(ep)), float(np.linalg.norm(er))


class ReceiveController(Partner):
    """Hold an open hand out beside the giver's, receive the ball, close the fingers on it (see
    the module table).

    ``offset``: the cup's palm centre from the ball (forward, left, up; m, heading frame);
    ``lean``: the palm's lean (slopes toward the wrist, toward the thumb); ``cup_deg``: the
    fingers' mcp, pip, dip angles while cupping; ``grip``: the flexing command of fingers and
    thumb after the ball arrives, in [0, 1]; ``close_after``, ``settle`` (s) and
    ``draw_back``, ``below`` (m): the phases; ``frequency`` (Hz) and ``damping`` (ratio): the
    arm's PD loop; ``tolerance`` (m) and ``reach_time`` (s): when a waypoint counts as reached;
    ``prop``: the ball's prop name.
    """

    def __init__(self, offset=READY_OFFSET, lean=(0.3, 0.1),
                 cup_deg=(10.0, 10.0, 5.0), grip: float = 0.05, close_after: float = 0.1,
                 settle: float = 0.1, draw_back: float = 0.0, below: float = 0.04,
                 frequency: float = 3.0, damping: float = 1.0, tolerance: float = 0.01,
                 reach_time: float = 1.0, prop: str = "ball"):
        self.offset = _triple("offset", offset, -0.2, 0.2)
        self.lean = check_numbers("ReceiveController", "lean", lean, 2, -1.0, 1.0,
                                  "(toward the wrist, toward the thumb), two slopes within "
                                  "[-1, 1]")
        self.cup_deg = _triple("cup_deg", cup_deg, 0.0, 90.0)
        self.grip = _number("grip", grip, 0.0, 1.0)
        self.close_after = _number("close_after", close_after, 0.0, 5.0)
        self.settle = _number("settle", settle, 0.0, 5.0)
        self.draw_back = _number("draw_back", draw_back, 0.0, 0.1)
        self.below = _number("below", below, 0.0, 0.15)
        self.frequency = _number("frequency", frequency, 0.1, 20.0)
        self.damping = _number("damping", damping, 0.1, 5.0)
        self.tolerance = _number("tolerance", tolerance, 0.001, 0.1)
        self.reach_time = _number("reach_time", reach_time, 0.0, 10.0)
        if not isinstance(prop, str) or not prop:
            raise ConfigError(f"ReceiveController: prop={show(prop)} not allowed; allowed: the "
                              "ball's prop name")
        self.prop = prop

    def __repr__(self):
        return (f"ReceiveController(offset={self.offset}, lean={self.lean}, grip={self.grip}, "
                f"frequency={self.frequency})")

    # -- reset ---------------------------------------------------------------------------------
    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        w = env.world
        m, d = w.model, w.data
        motors = agent_motors("ReceiveController", env, agent,
                              ARM + ("right_index_mcp", "right_thumb_mcp"),
                              "it needs the right arm's and the five fingers' motors in its "
                              "action (the handover task)")
        i, a, names, lo, hi = motors.index, motors.tables, motors.names, motors.lo, motors.hi
        self._i = i
        body = require_prop("ReceiveController", w, self.prop)
        self._ball_body = body
        self._ball_geom = int(np.flatnonzero(m.geom_bodyid == body)[0])
        self._qadr, self._dadr = motors.qpos_adr, motors.dof_adr
        self._arm = np.array([names.index(n) for n in ARM])
        self._flex = np.array([n not in ARM and n.split("_")[-1] in FLEXORS for n in names])
        self._act = env.actuation[i]
        self._site = int(a.palm_sites[0])
        self._own = np.zeros(m.ngeom, bool)
        self._own[hand_geoms(w, i, 0)] = True
        self._others = np.zeros(m.ngeom, bool)
        for j in range(len(w.agents)):
            if j != i:
                self._others[hand_geoms(w, j, 0)] = True
                self._others[hand_geoms(w, j, 1)] = True
        R = d.xmat[a.root_body].reshape(3, 3)
        heading = float(np.arctan2(R[1, 0], R[0, 0]))
        c, s = np.cos(heading), np.sin(heading)
        self._fwd, self._left = np.array([c, s, 0.0]), np.array([-s, c, 0.0])
        up = np.array([0.0, 0.0, 1.0])
        # the palm faces up, leaning toward the wrist (back) and the thumb (the right hand's
        # thumb points right when the palm is up and the fingers point ahead)
        normal = up - self.lean[0] * self._fwd - self.lean[1] * self._left
        self._frame = hand_frame(normal, self._fwd)
        cup = dict(zip(("mcp", "pip", "dip"), self.cup_deg))
        self._cup = np.clip([np.deg2rad(cup.get(n.split("_")[-1], 0.0))
                             if self._flex[k] and "thumb" not in n else
                             np.deg2rad({"right_thumb_swivel": 40.0,
                                         "right_thumb_adduction": -35.0}.get(n, 0.0))
                             for k, n in enumerate(names)], lo, hi)
        self._kp, self._kd = pd_gains(m, d, self._dadr, self.frequency, self.damping)
        self._dt = env.dt
        self.phase = "reach"
        self._t = 0
        self._on = self._free = 0
        out = np.array([0.0, 0.0, -self.below]) - 0.03 * self._left
        self._waypoints = [out, np.zeros(3)]
        self._wp = 0
        self.target_angles = self._cup.copy()
        start = np.clip(np.deg2rad([60.0, 20.0, -60.0, -60.0, -80.0, 0.0, 0.0]),
                        lo[self._arm], hi[self._arm])
        self._aim(env, self._waypoints[0], start)
        self._cup_goal = self._goal.copy()

    def _cup_point(self, d) -> np.ndarray:
        o = self.offset
        return (d.xpos[self._ball_body] + o[0] * self._fwd + o[1] * self._left
                + np.array([0.0, 0.0, o[2]]))

    def _aim(self, env, shift, start):
        """Target the arm posture with the palm centre at the cup point + ``shift`` (world)."""
        self._goal = self._cup_point(env.world.data) + shift
        q, res, _ = palm_posture(env.world, self._i, self._goal, self._frame, start=start)
        self.residual = res
        self.target_angles = self.target_angles.copy()
        self.target_angles[self._arm] = q

    def _ball_contacts(self, d):
        """Whether the ball touches the own right hand, and another agent's hand."""
        n = d.ncon
        if n == 0:
            return False, False
        c = d.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        ob = self._ball_geom
        other = np.where(g1 == ob, g2, np.where(g2 == ob, g1, -1))
        other = other[(other >= 0) & (c.dist[:n] <= 0.0)]
        return bool(self._own[other].any()), bool(self._others[other].any())

    # -- acting --------------------------------------------------------------------------------
    def _advance(self, env):
        d = env.world.data
        self._t += 1
        mine, theirs = self._ball_contacts(d)
        self._on = self._on + 1 if mine else 0
        now = d.qpos[self._qadr[self._arm]]
        if self.phase == "reach":
            near = np.linalg.norm(d.site_xpos[self._site] - self._goal) < self.tolerance
            if near or self._t * self._dt >= self.reach_time or self._on:
                self._wp += 1
                self._t = 0
                if self._wp < len(self._waypoints) and not self._on:
                    self._aim(env, self._waypoints[self._wp], now)
                else:
                    self.phase = "cup"
        if self.phase == "cup" and self._on * self._dt >= self.close_after:
            self.phase = "close"
        if self.phase == "close":
            self._free = self._free + 1 if (mine and not theirs) else 0
            if self._free * self._dt >= self.settle:
                self.phase = "hold"
            if self.phase == "hold" and self.draw_back > 0:
                goal = d.site_xpos[self._site] - self.draw_back * self._fwd
                q, _, _ = palm_posture(env.world, self._i, goal, self._frame, start=now)
                self.target_angles = self.target_angles.copy()
                self.target_angles[self._arm] = q

    def act(self, env, agent, observation):
        self._advance(env)
        d = env.world.data
        q, qd = d.qpos[self._qadr], d.qvel[self._dadr]
        tau = self._kp * (self.target_angles - q) - self._kd * qd
        tau += d.qfrc_bias[self._dadr] - d.qfrc_spring[self._dadr]
        u = torque_controls(self._act, q, tau)
        if self.phase in ("close", "hold"):
            flex = self._flex
            if self._act.name == "muscle":
                n = len(flex)
                u[:n][flex] = 0.0
                u[n:][flex] = self.grip
            else:
                u[flex] = self.grip
        return motor_action(env.action_space(agent), u)


class CupAndLeave(ReceiveController):
    """A hack for the handover's reward (a check, not a solution): holds the open hand out like
    :class:`ReceiveController` (so the giver tips the ball toward it), but draws the hand back
    to its start posture, fingers open, as soon as the ball touches it: the approach is
    rewarded by the shaping, the ball falls."""

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        d = env.world.data
        self._start = d.qpos[self._qadr].copy()
        self.left = False

    def _advance(self, env):
        if self.left:
            return
        super()._advance(env)
        if self.phase in ("close", "hold"):
            self.left = True
            self.phase = "cup"
            self.target_angles = self._start.copy()


class OpenPalm(ReceiveController):
    """A hack for the handover's success (a check, not a solution): holds the open, slightly
    cupped hand out like :class:`ReceiveController` (so the giver tips the ball into it) and
    keeps it so, never closing the fingers on the ball: the ball rests on the palm and the
    thumb. The success needs the fingers closed around the ball, so this does not succeed."""

    def _advance(self, env):
        super()._advance(env)
        if self.phase in ("close", "hold"):
            self.phase = "cup"
