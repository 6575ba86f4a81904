"""``HighFiveController``: the scripted solution of the high five (the learner's side).

reads:
    every ``replan_steps`` control steps, from the world: where the partner's right palm centre is
    and where it faces (the other agent's palm site and hand segment); each step: its own right
    arm's joint angles and speeds, and MuJoCo's bias and passive-spring forces on them
target (``palm="partner"``, default):
    palm to palm: first the hand *ready*, raised in front of its own shoulder (``ready``, scaled
    with the arm), until the partner's palm is still (slower than 5 cm/s; at most ``wait_steps``);
    then the own palm facing the partner's palm (its normal against that palm's normal), the
    fingers across the partner's hand to the own left, ``standoff`` (m) off it; then in along the
    partner's palm normal, pressing ``push`` (m) into it. The hands meet where the own finger pads
    (0.55 of the own hand's length from the palm centre) lie on the partner's palm (0.3 of its
    hand from its palm centre toward its fingers), which keeps the own forearm and fingertips off
    the partner's hand edge and wrist; out of reach (a smaller learner), the own fingertips on the
    partner's fingers (:data:`MEET_AT`). Damped least squares on a scratch copy of the state from
    the current posture (:func:`palm_posture`: position, the palm's normal, the fingers'
    direction), and from 3 seeded random postures when that misses by more than ``tolerance``
target (``palm="forward"``, ``"up"``, ``"posture"``: the first versions):
    the arm posture whose right palm centre reaches the partner's palm, pushed ``push`` (m) further
    along its own heading (toward the partner), the wrist as
    :func:`~mimo_social.partners.hand_offer.offer_posture` solves it; the fingertips onto the palm
    where the palm cannot reach (``tolerance``)
fingers:
    straight, the thumb at rest
arm:
    PD control per joint toward the target angles, gains from each joint's own inertia (the diagonal
    of the joint-space mass matrix at reset; natural frequency ``frequency`` 3 Hz, damping ratio
    ``damping`` 1), plus compensation of gravity / Coriolis (``qfrc_bias``) and joint springs
    (``qfrc_spring``); the torques become the agent's controls
    (:func:`~mimo_social.partners.base.torque_controls`: spring-damper motors ``u = tau / T_max``,
    muscles the agonist's activation)
acts:
    only through the agent's action (the expression, if any, neutral); it writes no state and
    changes no model value
state:
    ``phase`` (0 ready, 1 over the partner's palm, 2 in), ``meeting`` (the index of
    :data:`MEET_AT` in use), ``goal`` (world), ``palm_residual`` (m: how far the solved posture
    misses the goal)

The palm it aims at moves while the partner brings its hand out, so the posture is solved
again every ``replan_steps`` steps (50 ms by default). Measured success on ``high_five_v0``'s
``scripted_env()``: see the task's table.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...body.joint_groups import RIGHT_SHOULDER_ELBOW, RIGHT_WRIST
from ...core.kinematics import reach_sites
from ...util.checks import check_int, check_number
from ...partners.base import (Partner, agent_index, motor_action, pd_gains, require_motors,
                               torque_controls)
from ...partners.hand_offer import OPEN_FINGERS_DEG, PALMS, offer_posture
from ...partners.offer_target import REF_ARM, arm_length


__all__ = ["ArmSweep", "BangBang", "HighFiveController", "palm_depth", "palm_posture"]

ARM = RIGHT_SHOULDER_ELBOW + RIGHT_WRIST
WHO = "HighFiveController"
#: the controller's palm goals: ``"partner"`` (default): facing the partner's palm, coming in
#: along its normal; the others as :func:`~mimo_social.partners.hand_offer.offer_posture`'s
CONTROLLER_PALMS = ("partner",) + PALMS


def palm_depth(model, data, site: int) -> float:
    """How deep (m) the palm centre ``site`` lies under its palm's surface: the distance, along
    the palm's normal (the hand segment's -y), from the site out of the segment's geoms."""
    body = int(model.site_bodyid[site])
    normal = -data.xmat[body].reshape(3, 3)[:, 1]
    start = data.site_xpos[site] + 0.2 * normal
    hits = [mujoco.mju_rayGeom(data.geom_xpos[g], data.geom_xmat[g], model.geom_size[g], start,
                               -normal, int(model.geom_type[g]))
            for g in np.flatnonzero(model.geom_bodyid == body)]
    hits = [t for t in hits if t >= 0.0]
    return float(0.2 - min(hits)) if hits else 0.0


def palm_posture(model, data, qpos_adr, dof_adr, lo, hi, site: int, goal, normal,
                 along: float = 0.0, fingers=None, iters: int = 100,
                 weight: float = 0.1) -> float:
    """Damped least squares over the joints at ``qpos_adr``/``dof_adr`` (limits lo, hi): the
    point ``along`` (m) from the palm centre ``site`` toward the fingertips (the hand segment's
    +z) to ``goal`` (world), the palm's normal (the segment's -y) along ``normal`` (unit,
    world) and, half as important, the fingers along ``fingers`` (unit, world; None: free);
    ``weight`` (m per rad) trades the orientation against the position. ``data.qpos`` is
    changed in place. Returns the point's remaining distance (m)."""
    body = int(model.site_bodyid[site])
    jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    goal, normal = np.asarray(goal, float), np.asarray(normal, float)
    for _ in range(iters):
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        R = data.xmat[body].reshape(3, 3)
        point = data.site_xpos[site] + along * R[:, 2]
        e_p = goal - point
        e_r = np.cross(-R[:, 1], normal)
        if fingers is not None:
            e_r = e_r + 0.5 * np.cross(R[:, 2], fingers)
        if np.linalg.norm(e_p) < 1e-4 and np.linalg.norm(e_r) < 1e-3:
            break
        mujoco.mj_jac(model, data, jp, jr, point, body)
        J = np.vstack([jp[:, dof_adr], weight * jr[:, dof_adr]])
        e = np.concatenate([e_p, weight * e_r])
        step = J.T @ np.linalg.solve(J @ J.T + 1e-4 * np.eye(6), e)
        data.qpos[qpos_adr] = np.clip(data.qpos[qpos_adr] + np.clip(step, -0.1, 0.1), lo, hi)
    mujoco.mj_kinematics(model, data)
    R = data.xmat[body].reshape(3, 3)
    return float(np.linalg.norm(goal - data.site_xpos[site] - along * R[:, 2]))


#: where the hands meet, on each hand a fraction of its length (palm centre to fingertips) from
#: the palm centre toward the fingertips: (own, partner's): the own finger pads on the partner's
#: palm, the own forearm clear of the partner's hand; where that is out of reach (a smaller
#: learner), the own fingertips' pads on the partner's fingers
MEET_AT = ((0.55, 0.3), (0.9, 0.6))
#: the hand waits ready here, (forward, left, up) m from its right shoulder in its heading frame
#: (an 18-month-old's; scaled with the arm), until the partner's palm is still
READY = (0.105, 0.0, 0.05)
#: m/s: the partner's palm is still when slower than this
STILL_SPEED = 0.05
#: IK starts tried when the warm start does not reach (seeded by the controller's reset rng)
RESTARTS = 3


class HighFiveController(Partner):
    """Bring the right palm onto the partner's right palm (see the module table).

    ``palm``: the wrist's goal: ``"partner"`` (default): the own palm facing the partner's palm,
    coming in along its normal from ``standoff`` (m) off it, then pressing ``push`` (m) into it;
    ``"forward"``, ``"up"`` or ``"posture"`` (the first versions: as in
    :func:`~mimo_social.partners.hand_offer.offer_posture`, the palm centre aimed ``push`` beyond
    the partner's palm centre along the own heading); ``replan_steps``: control steps between two
    solutions of the posture; ``frequency`` (Hz) and ``damping`` (ratio): the PD loop;
    ``partner``: the other agent's name (default: the first other agent); ``tolerance`` (m): a
    solved posture missing its goal by more than this is solved again from other starts
    (``"partner"``) or gives way to the fingertips (the first versions); ``ready``: (forward,
    left, up) m from the right shoulder where the hand waits (``"partner"``); ``wait_steps``: the
    most control steps it waits there for the partner's palm to be still."""

    def __init__(self, push: float = 0.02, palm: str = "partner", replan_steps: int = 5,
                 frequency: float = 3.0, damping: float = 1.0, partner: str | None = None,
                 tolerance: float = 0.02, standoff: float = 0.04,
                 ready: tuple[float, float, float] = READY, wait_steps: int = 150):
        self.push = check_number(WHO, "push", push, -0.1, 0.1)
        self.tolerance = check_number(WHO, "tolerance", tolerance, 0.0, 1.0)
        self.standoff = check_number(WHO, "standoff", standoff, 0.0, 0.2)
        if not isinstance(ready, (tuple, list)) or len(ready) != 3:
            raise ValueError(f"{WHO}: ready={ready!r}; allowed: (forward, left, up) in m")
        self.ready = tuple(check_number(WHO, f"ready[{k}]", v, -0.3, 0.3)
                           for k, v in enumerate(ready))
        self.wait_steps = check_int(WHO, "wait_steps", wait_steps, 0, 100000)
        if not isinstance(palm, str) or palm not in CONTROLLER_PALMS:
            raise ValueError(f"{WHO}: palm={palm!r}; allowed: {list(CONTROLLER_PALMS)}")
        self.palm = palm
        self.replan_steps = check_int(WHO, "replan_steps", replan_steps, 1, 1000)
        self.frequency = check_number(WHO, "frequency", frequency, 0.1, 20.0)
        self.damping = check_number(WHO, "damping", damping, 0.1, 5.0)
        if partner is not None and not isinstance(partner, str):
            raise ValueError(f"{WHO}: partner={partner!r}; allowed: None or an agent's name")
        self.partner = partner

    def __repr__(self):
        return (f"HighFiveController(push={self.push}, palm={self.palm!r}, "
                f"replan_steps={self.replan_steps}, standoff={self.standoff})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        w = env.world
        m, d = w.model, w.data
        i = agent_index(env, agent)
        names = list(env.possible_agents)
        if self.partner is None:
            others = [k for k in range(len(names)) if k != i]
            if not others:
                raise ValueError(f"{WHO}: {agent} has no partner in this env")
            j = others[0]
        elif self.partner in names and self.partner != agent:
            j = names.index(self.partner)
        else:
            raise ValueError(f"{WHO}: partner={self.partner!r} for {agent}; allowed: "
                             f"{[n for n in names if n != agent]}")
        a = w.agents[i]
        require_motors(WHO, agent, a, ARM,
                       "it needs the right arm's motors (shoulder, elbow, wrist) in its action")
        self._i = i
        self._partner_palm = int(w.agents[j].palm_sites[0])
        self._partner_hand = int(m.site_bodyid[self._partner_palm])
        self._palm = int(a.palm_sites[0])
        self._hand = int(m.site_bodyid[self._palm])
        self._depths = palm_depth(m, d, self._palm) + palm_depth(m, d, self._partner_palm)
        self.phase = 0
        self.meeting = 0
        self._partner_was = d.site_xpos[self._partner_palm].copy()
        self._tips = int(a.fingertip_sites[0])
        self._scratch = mujoco.MjData(m)
        jk = a.actuated_joint_idx
        self._qadr, self._dadr = a.qpos_adr[jk], a.dof_adr[jk]
        self._lo, self._hi = a.joint_range[jk, 0], a.joint_range[jk, 1]
        motor_names = list(a.actuated_names)
        self._arm = np.array([motor_names.index(n) for n in ARM])
        fingers = np.deg2rad([OPEN_FINGERS_DEG.get(n, 0.0) for n in motor_names])
        self.target_angles = np.clip(fingers, self._lo, self._hi)
        self.target_angles[self._arm] = d.qpos[self._qadr[self._arm]]
        # each hand's length (palm centre to fingertips), the fingers as they are held: straight
        scratch = self._scratch
        scratch.qpos[:] = d.qpos
        fingers = np.setdiff1d(np.arange(len(motor_names)), self._arm)
        scratch.qpos[self._qadr[fingers]] = self.target_angles[fingers]
        mujoco.mj_kinematics(m, scratch)
        self._lengths = [float(np.linalg.norm(scratch.site_xpos[t] - scratch.site_xpos[p]))
                         for t, p in ((self._tips, self._palm),
                                      (int(w.agents[j].fingertip_sites[0]), self._partner_palm))]
        shoulder_dof = a.dof_adr[a.joint_names.index(ARM[0])]
        self._shoulder = int(m.jnt_bodyid[m.dof_jntid[shoulder_dof]])
        R = d.xmat[a.root_body].reshape(3, 3)
        heading = np.arctan2(R[1, 0], R[0, 0])
        self._c, self._s = float(np.cos(heading)), float(np.sin(heading))
        self._kp, self._kd = pd_gains(m, d, self._dadr, self.frequency, self.damping)
        self._ready = np.array(self.ready) * arm_length(w, i) / REF_ARM
        self._act = env.actuation[i]
        self._steps = 0
        self._plan(env)

    def _plan(self, env) -> None:
        """Solve the arm posture for the partner's palm where it is now."""
        if self.palm == "partner":
            self._plan_palms(env)
            return
        d = env.world.data
        c, s = self._c, self._s
        goal = d.site_xpos[self._partner_palm] + self.push * np.array([c, s, 0.0])
        rel = goal - d.xpos[self._shoulder]
        target = (c * rel[0] + s * rel[1], -s * rel[0] + c * rel[1], rel[2])
        arm = offer_posture(env.world, self._i, target=target, palm=self.palm)
        lo, hi = self._lo[self._arm], self._hi[self._arm]
        q = np.clip([arm[n] for n in ARM], lo, hi)
        scratch = self._scratch
        m = env.world.model
        scratch.qpos[:] = d.qpos
        scratch.qpos[self._qadr[self._arm]] = q
        mujoco.mj_kinematics(m, scratch)
        self.palm_residual = float(np.linalg.norm(scratch.site_xpos[self._palm] - goal))
        self.fingertips = self.palm_residual > self.tolerance
        if self.fingertips:   # out of reach with the palm forward: the fingertips onto the palm
            reach_sites(m, scratch, self._qadr[self._arm], self._dadr[self._arm], lo, hi,
                        self._tips, goal, iters=60)
            q = scratch.qpos[self._qadr[self._arm]].copy()
        self.goal = goal
        self.target_angles[self._arm] = q

    def _plan_palms(self, env) -> None:
        """Ready in front of the own shoulder until the partner's palm is still; then the own
        palm facing the partner's, ``standoff`` off it along its normal; then (once there,
        within half the stand-off) pressed ``push`` into it, the hands meeting at
        :data:`MEET_AT`. IK from the current posture, and from :data:`RESTARTS` seeded random
        postures (and the next meeting point) when that misses by more than ``tolerance``."""
        m, d = env.world.model, env.world.data
        R = d.xmat[self._partner_hand].reshape(3, 3)
        normal = -R[:, 1]
        gap = self._depths - self.push + (self.standoff if self.phase < 2 else 0.0)
        partner = d.site_xpos[self._partner_palm].copy()
        still = np.linalg.norm(partner - self._partner_was) \
            < STILL_SPEED * self.replan_steps * env.dt
        self._partner_was = partner
        goal = partner + gap * normal
        if self.phase == 0:   # ready: the hand raised in front of the own shoulder
            c, s = self._c, self._s
            f, left, up = self._ready
            goal = d.xpos[self._shoulder] + np.array([c * f - s * left, s * f + c * left, up])
        k, dof = self._qadr[self._arm], self._dadr[self._arm]
        lo, hi = self._lo[self._arm], self._hi[self._arm]
        # the fingers across the partner's hand, to the own left (in the partner's palm plane;
        # up when that palm faces sideways), clear of the partner's wrist
        fingers = None
        for ahead in (np.array([-self._s, self._c, 0.0]), np.array([0.0, 0.0, 1.0])):
            v = ahead - (ahead @ normal) * normal
            if np.linalg.norm(v) > 0.5:
                fingers = v / np.linalg.norm(v)
                break
        scratch = self._scratch
        best = None
        for t in range(len(MEET_AT) * (1 + RESTARTS)):
            meet, r = (self.meeting, 0) if t == 0 else divmod(t, 1 + RESTARTS)
            if t and best[0] < self.tolerance:
                break
            own = MEET_AT[meet][0] * self._lengths[0]
            at = goal + MEET_AT[meet][1] * self._lengths[1] * R[:, 2] if self.phase else goal
            scratch.qpos[:] = d.qpos
            if r:   # a seeded random start
                scratch.qpos[k] = self.rng.uniform(lo, hi)
            err = palm_posture(m, scratch, k, dof, lo, hi, self._palm, at, -normal, own,
                               fingers)
            if best is None or err < best[0] - 1e-3:
                best = (err, scratch.qpos[k].copy(), at, own, meet)
        self.palm_residual, q, self.goal, own, self.meeting = best
        here = d.site_xpos[self._palm] + own * d.xmat[self._hand].reshape(3, 3)[:, 2]
        there = np.linalg.norm(here - self.goal) < 0.5 * self.standoff + 1e-3
        if self.phase == 0 and ((there and still) or self._steps >= self.wait_steps):
            self.phase = 1   # the partner's hand is still: over to it
        elif self.phase == 1 and there:
            self.phase = 2   # and in
        self.fingertips = False
        self.target_angles[self._arm] = q

    def _replan_due(self) -> bool:
        return self._steps % self.replan_steps == 0

    def act(self, env, agent, observation):
        if self._steps and self._replan_due():
            self._plan(env)
        self._steps += 1
        d = env.world.data
        q, qd = d.qpos[self._qadr], d.qvel[self._dadr]
        tau = self._kp * (self.target_angles - q) - self._kd * qd
        tau += d.qfrc_bias[self._dadr] - d.qfrc_spring[self._dadr]
        u = torque_controls(self._act, q, tau).astype(np.float32)
        return motor_action(env.action_space(agent), u)


class ArmSweep(HighFiveController):
    """A hack policy (for baselines): sweeps the right arm back and forth in front of the body
    without looking for the partner's hand, hoping to hit it. The shoulder's horizontal joint
    follows a sine over the middle ``amplitude`` (0.8) of its range at ``sweep_hz`` (1 Hz), the
    shoulder's abduction a sine of half that frequency; the elbow and wrist stay at the middle of
    their ranges; the same PD loop as :class:`HighFiveController` drives the motors."""

    def __init__(self, sweep_hz: float = 1.0, amplitude: float = 0.8, **kwargs):
        super().__init__(**kwargs)
        self.sweep_hz = check_number("ArmSweep", "sweep_hz", sweep_hz, 0.01, 10.0)
        self.amplitude = check_number("ArmSweep", "amplitude", amplitude, 0.0, 1.0)

    def __repr__(self):
        return f"ArmSweep(sweep_hz={self.sweep_hz}, amplitude={self.amplitude})"

    def _plan(self, env) -> None:
        k = self._arm
        lo, hi = self._lo[k], self._hi[k]
        mid, half = 0.5 * (lo + hi), 0.5 * self.amplitude * (hi - lo)
        t = self._steps * env.dt * 2 * np.pi * self.sweep_hz
        q = mid.copy()
        q[0] += half[0] * np.sin(t)          # shoulder horizontal: across the front
        q[1] += half[1] * np.sin(0.5 * t)    # shoulder abduction: up and down, slower
        self.goal = None
        self.target_angles[k] = q

    def _replan_due(self) -> bool:
        return True   # a new target every step


class BangBang(Partner):
    """A flailing policy (for baselines): every motor command at one of its bounds (the action
    space's low or high), each one's side drawn uniformly at random from the reset's generator
    every ``hold`` control steps (1: every step); the face neutral. It does not look for the
    partner: what it scores is what flailing earns."""

    def __init__(self, hold: int = 1):
        self.hold = check_int("BangBang", "hold", hold, 1, 100000)

    def __repr__(self):
        return f"BangBang(hold={self.hold})"

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        space = env.action_space(agent)
        box = space["motors"] if hasattr(space, "spaces") else space
        self._lo, self._hi = box.low, box.high
        self._steps = 0
        self._u = self._lo.copy()

    def act(self, env, agent, observation):
        if self._steps % self.hold == 0:
            self._u = np.where(self.rng.random(self._lo.shape) < 0.5, self._lo, self._hi)
        self._steps += 1
        return motor_action(env.action_space(agent), self._u)
