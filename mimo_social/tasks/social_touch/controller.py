"""``SocialTouchController``: the scripted toucher of the social touch task (touch a named part of
the partner with the palm, touching nothing else first), and two hack policies that game it.

reads:
    the target part (``env.task.target``: a body part name of the partner, e.g. ``"left_hand"``; or
    ``target=`` given to the controller) and the world's state at reset
plan:
    once per reset, on scratch copies of the state: postures by damped least squares over the right
    arm's shoulder, elbow and wrist (:func:`hand_posture`, the fingers straight): the palm's face
    ``standoff`` (5 cm) off the target's nearest surface and facing it, then ``depth`` (1 cm) into
    it; every geom of the arm kept ``clearance`` (1.5 cm) from the partner's other parts (the
    forearm and upper arm from the target too) and from the toucher's own body; each plan of
    :data:`VARIANTS` (the arm first raised ``lift`` above the target or not, other stand-offs, IK
    from seeded random starts) is run with this controller's own PD law on a scratch copy of the
    world (``mj_step``, the motors' torques) and the first whose first contact with the partner is
    the palm side of the hand on the target within ``good_steps`` is kept (else the fastest that
    does; else the first)
blind plan (``twins`` K > 0):
    the toucher senses its own body (the distance too: its eyes verge on the partner's face) and
    the instruction, not the partner's arms, which the task draws each episode; this plan reads
    only what it senses. K twin worlds are made from the episode's: everything kept but the
    partner's arms, drawn again (``env.task.draw_unseen``) from generators seeded
    ``(twin_seed, k)`` (the same K draws every episode, so the plan is a function of what the
    toucher senses at the start and the target: a demonstration a clone can follow); one plan
    is made per twin as above, each plan is rolled out on every twin, and the one that touches
    the target first on the most twins (ties: the fewest steps) is played. ``twin_start="mean"``:
    the twins hold the toucher's arm at its mean start, not the episode's: one plan per target
    and distance whatever the start, the PD law bringing the arm onto it
arm:
    PD control per joint toward the current waypoint, gains from each joint's own inertia (the
    diagonal of the joint-space mass matrix at reset; natural frequency ``frequency`` 3 Hz, damping
    ratio ``damping`` 1), plus gravity / Coriolis and passive-spring compensation (``qfrc_bias``,
    ``qfrc_spring``); ``u = tau / T_max`` clipped to [-1, 1]; the waypoint advances when every joint
    is within ``tolerance`` (0.1 rad) or after ``hold_steps`` (60)
    With positional actuation (``per_agent=[{"actuation": "positional"}, ...]``) the action is
    the waypoint itself, plus the gravity / Coriolis torque over the servo's stiffness, as the
    target angle (the servo tracks it); the waypoints advance alike
fingers:
    held straight by the same PD (positional: targeted straight)
state:
    ``target_part``, ``waypoints``, ``variant`` (the plan kept), ``planned_steps`` (steps to the
    touch on the scratch world; inf: no plan touched the target first; blind: the mean over the
    twins it touched first), ``twin_hits`` (blind: on how many twins the kept plan touches the
    target first)

Hack policies (they ignore the instruction; each scores less than the controller, see
tests/partners/test_touch_controller.py): :class:`NearestPartToucher` touches, palm first, the
listed target part nearest to its hand at reset, whatever the target; :class:`ArmSweep` swings
the arm, elbow bent, in front of the partner from its side to the midline and down.

It acts only through the agent's own motors (no ``qpos`` writes) and reads what it needs from the
world and ``env.task`` (it imports no task).
"""

from __future__ import annotations

from collections.abc import Mapping

import mujoco
import numpy as np

from ...core.kinematics import hand_geoms
from .reach import (ARM, BACK_COS, SIDES, TILT_DEG, TOUCH_CLEARANCE, ArmGeometry, first_touch,
                    hand_posture, reach_posture, side_normal, surface_point)
from ...util.checks import check_choice, check_int, check_number
from ...partners.base import (Partner, agent_index, check_variants, follow_waypoints, motor_action,
                    pd_gains, require_motors, servo_waypoints)

__all__ = [
    "BACK_COS",
    "SIDES",
    "VARIANTS",
    "ArmSweep",
    "NearestPartToucher",
    "SocialTouchController",
    "first_touch",
    "hand_posture",
    "reach_posture",
    "side_normal",
    "surface_point",
]

#: where a blind plan's twins start the toucher's arm (see the module table)
TWIN_STARTS = ("episode", "mean")
#: the arm raised to the side, elbow bent (deg): a first waypoint that keeps the hand clear of
#: the partner's knees on its way in
RAISE_DEG = {"right_shoulder_abduction": 90.0, "right_elbow": -90.0}
#: the plans tried at reset, in order (keyword arguments of ``_plan``)
VARIANTS = (({}, {"side": "front_above"}, {"side": "above"}, {"side": "front"},
             {"side": "front_outside_above"}, {"side": "outside_above"},
             {"side": "front_outside"}, {"lift": 0.10}, {"side": "above", "lift": 0.08},
             {"side": "front_above", "lift": 0.08}, {"standoff": 0.03})
            + tuple(dict(v, raise_arm=True) for v in (
                {}, {"side": "front_outside"}, {"side": "outside_above"},
                {"side": "front_outside_above"}, {"side": "above"}, {"side": "front_above"},
                {"side": "front_outside", "lift": 0.08}))
            + tuple(dict(v, tilt_deg=t) for t in (60.0, 30.0) for v in (
                {}, {"side": "above"}, {"side": "front_above"}, {"side": "front"},
                {"side": "front_outside"}))
            + tuple({"seed": s} for s in range(1, 5))
            + tuple({"side": "front_above", "seed": s} for s in range(5, 9)))


class _Twin:
    """A twin of the episode's world for a blind plan: the episode's model, its own data, the
    agents' index tables."""

    def __init__(self, model, data, agents):
        self.model, self.data, self.agents = model, data, agents


class SocialTouchController(Partner):
    """Touch the social touch task's target part of the partner with the palm, coming in along
    the part's normal, clear of the partner's other parts (see the module table).

    ``target``: a body part name of the partner, or ``None`` to read the task's target at each
    reset (``env.task.target``); ``standoff`` (m): the palm's gap to the part before moving in;
    ``depth`` (m): how far into the part the hand is aimed; ``tilt_deg``: the touching
    direction, the palm's normal tipped this far towards the fingertips (the finger pads); ``lift``
    (m): where variants raise the palm above the part first; ``frequency`` (Hz) and ``damping``
    (ratio): the PD loop; ``tolerance`` (rad) and ``hold_steps``: when a waypoint gives way to the
    next; ``variants``: the plans tried at reset (default :data:`VARIANTS`); ``good_steps``: the
    first plan that touches the target first within this many steps on the scratch world is kept;
    ``twins`` (0: the plan sees the partner): plan without seeing the partner, on that many twin
    worlds; ``twin_seed``: their draws; ``twin_start``: ``"episode"`` (the twins' toucher starts
    as in the episode) or ``"mean"`` (at its mean start) (see the module table, "blind plan").
    """

    who = "SocialTouchController"

    def __init__(self, target: str | None = None, standoff: float = 0.05, depth: float = 0.03,
                 lift: float = 0.10, frequency: float = 3.0, damping: float = 1.0,
                 tolerance: float = 0.1, hold_steps: int = 60, variants=None,
                 good_steps: int = 250, tilt_deg: float = TILT_DEG, twins: int = 0,
                 twin_seed: int = 0, twin_start: str = "episode"):
        if target is not None and (not isinstance(target, str) or not target):
            raise ValueError(f"{self.who}: target={target!r}; allowed: None or a body part "
                             "name of the partner")
        self.target = target
        self.standoff = check_number(self.who, "standoff", standoff, 0.0, 0.2)
        self.depth = check_number(self.who, "depth", depth, 0.0, 0.05)
        self.lift = check_number(self.who, "lift", lift, 0.0, 0.3)
        self.frequency = check_number(self.who, "frequency", frequency, 0.1, 20.0)
        self.damping = check_number(self.who, "damping", damping, 0.1, 5.0)
        self.tolerance = check_number(self.who, "tolerance", tolerance, 0.01, 1.0)
        self.hold_steps = int(check_number(self.who, "hold_steps", hold_steps, 1, 10000))
        self.variants = check_variants(self.who, variants, self._plan, VARIANTS)
        self.good_steps = int(check_number(self.who, "good_steps", good_steps, 1, 100000))
        self.tilt_deg = check_number(self.who, "tilt_deg", tilt_deg, 0.0, 90.0)
        self.twins = check_int(self.who, "twins", twins, 0, 100)
        self.twin_seed = check_int(self.who, "twin_seed", twin_seed, 0, 2**31 - 1)
        self.twin_start = check_choice(self.who, "twin_start", twin_start, TWIN_STARTS)
        self.twin_hits: int | None = None

    def __repr__(self):
        twins = (f", twins={self.twins}, twin_seed={self.twin_seed}, twin_start="
                 f"{self.twin_start!r}" if self.twins else "")
        return f"{type(self).__name__}(target={self.target!r}{twins})"

    # -- set-up shared with the hacks ------------------------------------------------------------
    def bind(self, env, agent):
        """Take ``agent`` of ``env`` as the toucher: its right arm's motors, joint ranges and PD
        gains, the partner; checks that the env is a dyad and the actuation is not muscles."""
        w = env.world
        m, d = w.model, w.data
        i = agent_index(env, agent)
        if len(env.possible_agents) != 2:
            raise ValueError(f"{self.who}: needs a dyad (the toucher and the touched infant); "
                             f"agents: {env.possible_agents}")
        a = w.agents[i]
        require_motors(self.who, agent, a, ARM,
                       "it needs the right arm's motors (shoulder, elbow, wrist) in its action")
        act = env.actuation[i]
        if act.name not in ("spring_damper", "positional"):
            raise ValueError(f"{self.who}: {agent} has actuation={act.name!r}; allowed: "
                             "'spring_damper' (the task's) or 'positional'")
        self._servo = act.name == "positional"
        if self._servo:
            self._servo_kp = act.gains(m)[0]
        self._i, self._j, self._a = i, 1 - i, a
        k = a.actuated_joint_idx
        self._qadr, self._dadr = a.qpos_adr[k], a.dof_adr[k]
        self._lo, self._hi = a.joint_range[k, 0], a.joint_range[k, 1]
        self._kp, self._kd = pd_gains(m, d, self._dadr, self.frequency, self.damping)
        self._act = act
        self._tneg, self._tpos = act.torque_neg, act.torque_pos
        self._arm_mask = np.zeros(m.ngeom, bool)
        self._partner_mask = np.zeros(m.ngeom, bool)
        self._partner_mask[w.agents[self._j].geom_ids] = True
        tip = d.site_xpos[a.fingertip_sites[0]]
        hand = hand_geoms(w, i, 0)
        nearest = int(hand[np.argmin(np.linalg.norm(d.geom_xpos[hand] - tip, axis=1))])
        round_ = m.geom_type[nearest] in (mujoco.mjtGeom.mjGEOM_SPHERE,
                                          mujoco.mjtGeom.mjGEOM_CAPSULE,
                                          mujoco.mjtGeom.mjGEOM_CYLINDER)
        self._tip_radius = float(m.geom_size[nearest, 0]) if round_ else 0.01

    def _part(self, env) -> str:
        name = self.target if self.target is not None else getattr(env.task, "target", None)
        if name is None:
            raise ValueError(f"{self.who}: no target: give target= or use it on an env whose "
                             "task names one (env.task.target)")
        return str(name)

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        self.bind(env, agent)
        self.target_part = self._part(env)
        w = env.world
        # geom sets of the model only: the blind plan's twins, which share it, use them too
        self._geo = ArmGeometry(w, self._i, self._j, self.target_part)
        self._arm_mask[:] = False
        self._arm_mask[self._geo.arm] = True
        self.twin_hits = None
        best = self._blind_plan(env) if self.twins else self._best_plan(w, env)
        self.planned_steps, _, self.variant = best
        self.follow(best[1])

    def _best_plan(self, w, env) -> tuple[float, list, dict]:
        """(steps to the touch, waypoints, variant) of the first variant that touches the target
        first within ``good_steps`` on ``w`` (else the fastest that does; else the first)."""
        best = None
        for variant in self.variants:
            plan = self._plan(w, **variant)
            if not plan:
                continue
            steps = self._rollout(w, plan, env.max_steps, env.frame_skip)
            if best is None or steps < best[0]:
                best = (steps, plan, variant)
            if steps <= self.good_steps:
                break
        if best is None:
            raise ValueError(f"{self.who}: no plan for {self.target_part!r}")
        return best

    def _blind_plan(self, env) -> tuple[float, list, dict]:
        """The plan kept without seeing the partner (module table, "blind plan")."""
        draw = getattr(env.task, "draw_unseen", None)
        if not callable(draw):
            raise ValueError(f"{self.who}: twins={self.twins} needs a task that draws what the "
                             f"toucher does not sense (env.task.draw_unseen); "
                             f"{type(env.task).__name__} has none: allowed twins=0")
        w = env.world
        m = w.model
        twins = []
        for k in range(self.twins):
            d = mujoco.MjData(m)
            d.qpos[:], d.qvel[:], d.act[:], d.ctrl[:] = w.data.qpos, w.data.qvel, w.data.act, \
                w.data.ctrl
            draw(m, d, np.random.default_rng([self.twin_seed, k]),
                 own_mean=self.twin_start == "mean")
            mujoco.mj_forward(m, d)
            twins.append(_Twin(m, d, w.agents))
        found = [self._best_plan(t, env) for t in twins]
        steps = np.array([[self._rollout(t, plan, env.max_steps, env.frame_skip) for t in twins]
                          for _, plan, _ in found])
        hits = np.isfinite(steps).sum(axis=1)
        mean = np.array([row[np.isfinite(row)].mean() if h else np.inf
                         for row, h in zip(steps, hits)])
        kept = int(np.lexsort((mean, -hits))[0])
        self.twin_hits = int(hits[kept])
        return float(mean[kept]), found[kept][1], found[kept][2]

    def follow(self, waypoints: list[np.ndarray]) -> None:
        """Drive the arm through ``waypoints`` (motor angles, rad) from the first one on."""
        self.waypoints = waypoints
        self._wp, self._in_wp = 0, 0
        self.target_angles = self.waypoints[0]

    def posture(self, angles_deg: Mapping[str, float]) -> np.ndarray:
        """Motor angles (rad): each joint at 0 (clipped to its range), but those named in
        ``angles_deg`` (joint name -> degrees), clipped to the joints' ranges."""
        names = list(self._a.actuated_names)
        q = np.clip(np.zeros(len(names)), self._lo, self._hi)
        for name, deg in angles_deg.items():
            q[names.index(name)] = np.deg2rad(deg)
        return np.clip(q, self._lo, self._hi)

    def _plan(self, w, lift: float | None = None, standoff: float | None = None,
              seed: int | None = None, side: str | None = None,
              raise_arm: bool = False, tilt_deg: float | None = None) -> list[np.ndarray]:
        """Waypoints: (the hand ``lift`` above its stand-off,) the hand ``standoff`` off the
        part facing it, then 40 % of that, then ``depth`` into it, moving in along one line.
        ``tilt_deg``: another touching direction. ``raise_arm``: first the arm raised to the side
        (:data:`RAISE_DEG`). ``side`` (a key of :data:`SIDES`): come in along that side's normal to
        the point of the part's surface hit by a ray from that side through its centre; else along
        the line between the hand and the part's nearest point; the IK starts from the current
        posture or from a seeded random one."""
        standoff = self.standoff if standoff is None else standoff
        start = None
        if seed is not None:
            start = np.random.default_rng(seed).uniform(self._lo, self._hi)
        args = (w, self._i, self._j, self.target_part)
        kw = {"geometry": self._geo,
              "tilt_deg": self.tilt_deg if tilt_deg is None else tilt_deg}
        if side is None:
            pre, _, _, u = hand_posture(*args, standoff, start=start, **kw)
            near, _, _, _ = hand_posture(*args, 0.4 * standoff, start=pre, direction=u,
                                         clearance=TOUCH_CLEARANCE, **kw)
            touch, _, _, _ = hand_posture(*args, -self.depth, start=near, direction=u,
                                          clearance=TOUCH_CLEARANCE, **kw)
            up = None
            if lift:
                up, _, _, _ = hand_posture(*args, lift, start=pre, **kw)
        else:
            n = side_normal(w, self._i, self._j, side)
            surface = surface_point(w, self._geo, n)
            if surface is None:
                return []
            u = -n
            r = self._tip_radius

            def at(gap, q0, clearance=0.015):
                return hand_posture(*args, 0.0, start=q0, direction=u, clearance=clearance,
                                    point=surface + n * (r + gap), **kw)[0]
            pre = at(standoff, start)
            near = at(0.4 * standoff, pre, TOUCH_CLEARANCE)
            touch = at(-self.depth, near, TOUCH_CLEARANCE)
            up = None
            if lift:
                up = hand_posture(*args, 0.0, start=pre, direction=u,
                                  point=surface + n * (r + standoff) + [0.0, 0.0, lift], **kw)[0]
        plan = ([up] if up is not None else []) + [pre, near, touch]
        if raise_arm:
            names = list(self._a.actuated_names)
            q = w.data.qpos[self._qadr].copy()
            for name, deg in RAISE_DEG.items():
                if name in names:
                    q[names.index(name)] = np.deg2rad(deg)
            plan.insert(0, np.clip(q, self._lo, self._hi))
        return plan

    def _rollout(self, w, waypoints, max_steps: int, frame_skip: int) -> float:
        """Control steps until the first contact with the partner, when it is the palm on the
        target, running this plan on a scratch copy of the world (inf: never, or another part
        first)."""
        m = w.model
        d = mujoco.MjData(m)
        d.qpos[:], d.qvel[:], d.act[:], d.ctrl[:] = w.data.qpos, w.data.qvel, w.data.act, \
            w.data.ctrl
        mujoco.mj_forward(m, d)
        state = [0, 0, waypoints[0]]
        for step in range(1, max_steps + 1):
            u = self._control(d, waypoints, state)
            d.ctrl[self._act.actuator_ids] = (self._act.targets(u) if self._servo
                                              else self._act.torque(u))
            for _ in range(frame_skip):
                mujoco.mj_step(m, d)
            mujoco.mj_kinematics(m, d)
            hit = first_touch(m, d, self._geo, self._arm_mask, self._partner_mask)
            if hit is not None:
                return float(step) if hit else float("inf")
        return float("inf")

    def _control(self, d, waypoints, state) -> np.ndarray:
        """The controls of one step (PD + compensation toward the current waypoint); ``state``
        [waypoint, steps in it, target angles] is advanced in place."""
        if self._servo:
            return servo_waypoints(d, waypoints, state, self.hold_steps, self.tolerance,
                                   self._qadr, self._dadr, self._servo_kp, self._lo, self._hi)
        return follow_waypoints(d, waypoints, state, self.hold_steps, self.tolerance, self._qadr,
                                self._dadr, self._kp, self._kd, self._tneg, self._tpos)

    def act(self, env, agent, observation):
        state = [self._wp, self._in_wp, self.target_angles]
        u = self._control(env.world.data, self.waypoints, state)
        self._wp, self._in_wp, self.target_angles = state
        return motor_action(env.action_space(agent), u)


class NearestPartToucher(SocialTouchController):
    """Hack policy: ignores the instruction and touches, palm first, the task's listed target
    part (``env.task.targets``) whose centre is nearest its palm at reset."""

    who = "NearestPartToucher"

    def _part(self, env) -> str:
        w = env.world
        m, d = w.model, w.data
        b = w.agents[self._j]
        parts = list(getattr(env.task, "targets", ()) or [])
        if not parts:
            raise ValueError(f"{self.who}: the task lists no target parts (env.task.targets)")
        palm = d.site_xpos[self._a.palm_sites[0]]
        far = [np.linalg.norm(d.xipos[m.body(f"{b.name}/{p}").id] - palm) for p in parts]
        return parts[int(np.argmin(far))]


class ArmSweep(Partner):
    """Hack policy: swings the right arm, elbow bent, forward and across in front of the
    partner (shoulder horizontal from 0 to 90 deg at ``abduction_deg``), then lowers it: it
    touches whatever part is in the way, the instruction unread. PD control as the controller's
    (``frequency`` Hz)."""

    #: (shoulder horizontal, shoulder abduction, elbow) in deg along the sweep
    PATH = ((0.0, 80.0, -40.0), (45.0, 80.0, -40.0), (90.0, 80.0, -40.0), (90.0, 40.0, -20.0),
            (90.0, 10.0, 0.0))

    def __init__(self, frequency: float = 3.0, hold_steps: int = 60):
        self.frequency = check_number("ArmSweep", "frequency", frequency, 0.1, 20.0)
        self.hold_steps = int(check_number("ArmSweep", "hold_steps", hold_steps, 1, 10000))

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        helper = SocialTouchController(frequency=self.frequency, hold_steps=self.hold_steps)
        helper.who = "ArmSweep"
        helper.bind(env, agent)
        helper.follow([helper.posture({"right_shoulder_horizontal": h,
                                       "right_shoulder_abduction": ab, "right_elbow": el})
                       for h, ab, el in self.PATH])
        self._helper = helper

    def act(self, env, agent, observation):
        return self._helper.act(env, agent, observation)
