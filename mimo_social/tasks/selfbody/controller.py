"""``SelfBodyController``: the scripted solution of the self-body task (touch a named primitive).

reads:
    the target primitive (``env.task.target``: a geom name of the agent, e.g. ``"left_shin"``; or
    ``target=`` given to the controller) and the world's state at reset
plan:
    once per reset, on scratch copies of the state: waypoints by damped least squares over the right
    arm's joints (:func:`touch_posture`): the arm raised to the side (:data:`RAISE_DEG`, clear of
    the crossed legs), the palm `lift` (12 cm) above the target, the hand's nearest point `approach`
    (4 cm) from it, then `depth` (1 cm) inside the target primitive (`mj_geomDistance` between every
    hand geom and the target), every right-arm geom pushed out of the other primitives; each plan of
    :data:`VARIANTS` (other lifts and raises, the touching posture alone, plans backwards from
    touching postures found from seeded random starts, with other paces) is run with this
    controller's own PD law on a scratch copy of the world (`mj_step`, the motors' torques) and the
    first that touches within `good_steps` (else the fastest) is kept; the waypoint advances when
    every joint is within `tolerance` (0.1 rad) or after `hold_steps` (80) steps; the IK's random
    restarts are seeded from the target and the start state, so one start gives one plan whatever
    the episode's rng (cloned demonstrations of a start agree; before, 6 of the 28 targets drew
    different plans in different episodes), and a controller keeps its last `MEMO_SIZE` plans
    (the task's start is fixed: planning, about 2 s a target, is done once per target)
arm:
    PD control per joint toward the planned angles, gains from the joint's own inertia (the diagonal
    of the joint-space mass matrix at reset; natural frequency ``frequency`` 3 Hz, damping ratio
    ``damping`` 1), plus gravity / Coriolis and passive-spring compensation (``qfrc_bias``,
    ``qfrc_spring``); the torque becomes the controls ``u = tau / T_max`` (clipped to [-1, 1])
fingers:
    held straight by the same PD (the mitten's finger joint)
state:
    ``target_angles`` (rad, per motor: the current waypoint), ``waypoints``, ``variant`` (the plan
    kept), ``planned_steps`` (steps to the touch on the scratch world; inf: no plan touched, and the
    first is run), ``plan_distance`` (m: the planned hand-target signed distance; negative =
    pressing in)

It acts only through the agent's own motors (no ``qpos`` writes) and reads what it needs from the
world (it imports no task). Measured (seeds 0-19, random targets): 20 of 20 episodes, mean return
330.0 (313.4 on another machine: the plans are chosen by rollouts with contacts, whose floating
point differs between CPUs, so a start can get another plan there; one machine always gives one
plan); the table of :mod:`mimo_social.tasks.selfbody` has the command.
"""

from __future__ import annotations

import zlib

import mujoco
import numpy as np

from ...core.kinematics import geoms_collide, hand_geoms
from ...util.checks import check_int, check_number
from ...partners.base import (Partner, agent_index, check_angles, check_variants, follow_waypoints,
                    motor_action, pd_gains)

__all__ = ["RAISE_DEG", "VARIANTS", "SelfBodyController", "touch_posture"]

#: the first waypoint: the upper arm raised to the side and the elbow bent (deg), so the forearm
#: clears the knee of the crossed legs on its way forward
RAISE_DEG = {"right_shoulder_abduction": 90.0, "right_elbow": -90.0}
#: the plans a controller keeps (start state and target -> plan; the oldest dropped first)
MEMO_SIZE = 256
#: the plans tried at reset, in order (keyword arguments of ``_plan``)
VARIANTS = (({}, {"direct": True}, {"lift": 0.06}, {"raise_deg": {}},
             {"raise_deg": {"right_shoulder_abduction": 120.0, "right_elbow": -100.0}},
             {"lift": 0.2})
            + tuple({"backwards": True, "seed": s, "hold_steps": 50, "tolerance": 0.2}
                    for s in range(1, 9))
            + tuple({"backwards": True, "seed": s, "approach": 0.07, "lift": 0.08}
                    for s in range(1, 9)))


def _geom_distance(m, d, g1: int, g2: int, fromto: np.ndarray, cap: float = 1.0) -> float:
    return float(mujoco.mj_geomDistance(m, d, int(g1), int(g2), cap, fromto))


def touch_posture(world, i: int, target_geom: int, depth: float = 0.01, iters: int = 300,
                  restarts: int = 6, rng: np.random.Generator | None = None,
                  clearance: float = 0.003, start=None, point=None) -> tuple[np.ndarray, float]:
    """Right-arm joint angles of agent ``i`` (its actuated joints, rad) that put its right hand
    ``depth`` m inside the geom ``target_geom``, the rest of the arm clear of other primitives.

    Damped least squares on a scratch copy of the state: each iteration moves the hand point
    nearest to the target (``mj_geomDistance`` over the hand's geoms) along the line to the
    target's nearest point, and every right-arm geom that comes within ``clearance`` of another
    primitive of the body (not the target) out along the line between them. Restarts from random
    arm postures (``rng``) while the hand stays short of the target. Returns the angles and the
    planned hand-target signed distance (m)."""
    m = world.model
    a = world.agents[i]
    k = a.actuated_joint_idx
    qadr, dadr = a.qpos_adr[k], a.dof_adr[k]
    lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
    hand = [int(g) for g in hand_geoms(world, i, 0)]
    arm_root = int(m.jnt_bodyid[m.dof_jntid[dadr[0]]])   # the shoulder's body
    arm = [int(g) for g in a.geom_ids if _below(m, int(m.geom_bodyid[g]), arm_root)]
    others = [int(g) for g in a.geom_ids if int(g) not in arm and int(g) != int(target_geom)]
    # pairs MuJoCo would not collide (parent-child bodies) are no obstacles
    others_of = {g: [o for o in others if geoms_collide(m, g, o)] for g in arm}
    d = mujoco.MjData(m)
    d.qpos[:] = world.data.qpos
    start = d.qpos[qadr].copy() if start is None else np.asarray(start, float)
    rng = rng if rng is not None else np.random.default_rng(0)
    palm = int(a.palm_sites[0])
    fromto = np.zeros(6)
    jac = np.zeros((3, m.nv))
    best_q, best = start.copy(), np.inf

    def solve(q0):
        d.qpos[qadr] = q0
        dist = np.inf
        for _ in range(iters):
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            rows, errs = [], []
            if point is None:
                dist, pt_h, pt_t = np.inf, None, None
                for h in hand:
                    s = _geom_distance(m, d, h, target_geom, fromto)
                    if s < dist:
                        dist, pt_h, pt_t, hb = s, fromto[:3].copy(), fromto[3:].copy(), h
                n = _direction(pt_h, pt_t, d.geom_xpos[target_geom], dist)
                mujoco.mj_jac(m, d, jac, None, pt_h, int(m.geom_bodyid[hb]))
                rows.append(jac[:, dadr].copy())
                errs.append(n * (dist + depth))
            else:   # the palm centre to a point
                v = np.asarray(point) - d.site_xpos[palm]
                dist = float(np.linalg.norm(v))
                mujoco.mj_jacSite(m, d, jac, None, palm)
                rows.append(jac[:, dadr].copy())
                errs.append(v)
            worst = 0.0
            for g in arm:
                for o in others_of[g]:
                    s = _geom_distance(m, d, g, o, fromto, clearance + 0.02)
                    if s < clearance:
                        p_g, p_o = fromto[:3].copy(), fromto[3:].copy()
                        away = -_direction(p_g, p_o, d.geom_xpos[o], s)
                        mujoco.mj_jac(m, d, jac, None, p_g, int(m.geom_bodyid[g]))
                        rows.append(jac[:, dadr].copy())
                        errs.append(away * (clearance - s))
                        worst = max(worst, clearance - s)
            if abs(dist + (depth if point is None else 0.0)) < 1e-3 and worst < 1e-3:
                break
            J = np.vstack(rows)
            e = np.concatenate(errs)
            step = J.T @ np.linalg.solve(J @ J.T + 1e-4 * np.eye(len(e)), e)
            d.qpos[qadr] = np.clip(d.qpos[qadr] + np.clip(step, -0.1, 0.1), lo, hi)
        return d.qpos[qadr].copy(), dist

    for r in range(restarts + 1):
        q0 = start if r == 0 else rng.uniform(lo, hi)
        q, dist = solve(q0)
        if dist < best:
            best_q, best = q, dist
        if (point is None and best <= -0.5 * depth) or (point is not None and best < 0.01):
            break
    return best_q, float(best)


def _below(m, body: int, root: int) -> bool:
    while body > 0:
        if body == root:
            return True
        body = int(m.body_parentid[body])
    return False


def _direction(p_from, p_to, centre_to, dist) -> np.ndarray:
    """Unit vector from the first geom's nearest point toward the second geom (its nearest
    point; its centre when the two overlap or touch, where the nearest points say little)."""
    v = p_to - p_from
    if dist <= 1e-4 or np.linalg.norm(v) < 1e-6:
        v = centre_to - p_from
    n = np.linalg.norm(v)
    return v / n if n > 1e-9 else np.zeros(3)


class SelfBodyController(Partner):
    """Touch the self-body task's target primitive with the right hand (see the module table).

    ``target``: a primitive (geom) name of the agent, or ``None`` to read the task's current
    target at each reset (``env.task.target``); ``depth``: how far inside the target's surface
    the hand is aimed (m); ``frequency`` (Hz) and ``damping`` (ratio): the PD loop;
    ``restarts``: random starts of the IK when a plan falls short; ``lift``, ``approach``,
    ``raise_deg``: the waypoints (m above the target, m from it, the raised arm in degrees);
    ``tolerance`` (rad) and ``hold_steps``: when a waypoint gives way to the next; ``variants``:
    the plans tried at reset (default :data:`VARIANTS`); ``good_steps``: the first plan that
    touches within this many steps on the scratch world is taken without trying the rest.
    """

    def __init__(self, target: str | None = None, depth: float = 0.01, frequency: float = 3.0,
                 damping: float = 1.0, restarts: int = 6, lift: float = 0.12,
                 approach: float = 0.04, tolerance: float = 0.1, hold_steps: int = 80,
                 raise_deg: dict | None = None, variants=None, good_steps: int = 250):
        if target is not None and (not isinstance(target, str) or not target):
            raise ValueError(f"SelfBodyController: target={target!r}; allowed: None or a "
                             "primitive (geom) name of the agent")
        self.target = target
        self.depth = check_number("SelfBodyController", "depth", depth, 0.0, 0.05)
        self.frequency = check_number("SelfBodyController", "frequency", frequency, 0.1, 20.0)
        self.damping = check_number("SelfBodyController", "damping", damping, 0.1, 5.0)
        self.restarts = int(check_number("SelfBodyController", "restarts", restarts, 0, 50))
        self.variants = check_variants("SelfBodyController", variants, self._plan, VARIANTS,
                                       ("hold_steps", "tolerance"))
        self.good_steps = check_int("SelfBodyController", "good_steps", good_steps, 1, 100000)
        self.raise_deg = check_angles("SelfBodyController", "raise_deg",
                                      RAISE_DEG if raise_deg is None else raise_deg)
        self.lift = check_number("SelfBodyController", "lift", lift, 0.0, 0.3)
        self.approach = check_number("SelfBodyController", "approach", approach, 0.0, 0.2)
        self.tolerance = check_number("SelfBodyController", "tolerance", tolerance, 0.01, 1.0)
        self.hold_steps = int(check_number("SelfBodyController", "hold_steps", hold_steps, 1,
                                           10000))
        self._memo_model, self._memo = None, {}

    def __getstate__(self):
        state = dict(self.__dict__)
        state["_memo_model"], state["_memo"] = None, {}     # plans again (the same) after a copy
        return state

    def __repr__(self):
        return f"SelfBodyController(target={self.target!r}, depth={self.depth})"

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        w = env.world
        m, d = w.model, w.data
        i = agent_index(env, agent)
        a = w.agents[i]
        name = self.target if self.target is not None else getattr(env.task, "target", None)
        if name is None:
            raise ValueError("SelfBodyController: no target: give target= or use it on an env "
                             "whose task names one (env.task.target)")
        try:
            geom = m.geom(f"{a.name}/{name}").id
        except KeyError:
            raise ValueError(f"SelfBodyController: target {name!r} is no primitive of {agent}; "
                             f"primitives: {[m.geom(int(g)).name[len(a.name) + 1:] for g in a.geom_ids]}"
                             ) from None
        k = a.actuated_joint_idx
        self._qadr, self._dadr = a.qpos_adr[k], a.dof_adr[k]
        self._geom = geom
        self._hand = np.zeros(m.ngeom, bool)
        self._hand[hand_geoms(w, i, 0)] = True
        self._kp, self._kd = pd_gains(m, d, self._dadr, self.frequency, self.damping)
        act = env.actuation[i]
        if act.name == "muscle":
            raise ValueError("SelfBodyController drives spring-damper motors (the task's "
                             "actuation); got muscles")
        self._act = act
        self._tneg, self._tpos = act.torque_neg, act.torque_pos
        # the plan is a function of the target and the start state: its random IK restarts are
        # seeded from them, so a start gives one plan whatever the episode's rng (demonstrations
        # of a start agree) and a start met again reuses it (the memo: planning is the cost)
        key = (name, d.qpos.tobytes(), d.qvel.tobytes(), d.act.tobytes())
        if self._memo_model is not m:
            self._memo_model, self._memo = m, {}
        if key not in self._memo:
            if len(self._memo) >= MEMO_SIZE:
                del self._memo[next(iter(self._memo))]
            self._memo[key] = self._best_plan(w, i, a, k, geom, env.max_steps,
                                              np.random.default_rng(zlib.crc32(b"".join(key[1:])
                                                                              + name.encode())))
        steps, (waypoints, distance, pace), variant = self._memo[key]
        self.planned_steps, self.plan_distance, self.variant = steps, distance, variant
        self.waypoints = [q.copy() for q in waypoints]
        self._pace = pace
        self._wp = 0
        self._in_wp = 0
        self.target_angles = self.waypoints[0]

    def _best_plan(self, w, i, a, k, geom, max_steps, rng):
        """Each variant planned and tried on a scratch copy of the world: (steps to the touch,
        (waypoints, planned distance, pace), variant) of the first to touch within
        ``good_steps``, else of the fastest."""
        best = None
        for variant in self.variants:
            pace = {"hold_steps": variant.get("hold_steps", self.hold_steps),
                    "tolerance": variant.get("tolerance", self.tolerance)}
            self._pace = pace
            plan = self._plan(w, i, a, k, geom, rng, **{n: v for n, v in variant.items()
                                                        if n not in pace}) + (pace,)
            steps = self._rollout(w, plan[0], max_steps)
            if best is None or steps < best[0]:
                best = (steps, plan, variant)
            if steps <= self.good_steps:
                break
        return best

    def _plan(self, w, i, a, k, geom, rng, raise_deg=None, lift=None, direct=False,
              backwards=False, seed=None, approach=None):
        """Waypoints: the arm raised to the side (clear of the crossed legs), the palm ``lift``
        above the target, the hand ``approach`` from it, the hand ``depth`` inside it; planned
        from the first, or, when that falls short, backwards from a touching posture found from
        other starts. ``direct``: the touching posture only."""
        d = w.data
        lift = self.lift if lift is None else lift
        approach = self.approach if approach is None else approach
        names = list(a.actuated_names)
        q0 = d.qpos[self._qadr].copy()
        for n, deg in (self.raise_deg if raise_deg is None else raise_deg).items():
            if n in names:
                q0[names.index(n)] = np.deg2rad(deg)
        q0 = np.clip(q0, a.joint_range[k, 0], a.joint_range[k, 1])
        if seed is not None:
            rng = np.random.default_rng(seed)
        first = None if seed is None else rng.uniform(a.joint_range[k, 0], a.joint_range[k, 1])
        if direct:
            q3, dist = touch_posture(w, i, geom, self.depth, restarts=self.restarts, rng=rng,
                                     start=first)
            return [q3], dist
        above = d.geom_xpos[geom] + np.array([0.0, 0.0, lift])
        q1, _ = touch_posture(w, i, geom, restarts=0, point=above, start=q0)
        q2, _ = touch_posture(w, i, geom, -approach, restarts=0, start=q1)
        q3, dist = touch_posture(w, i, geom, self.depth, restarts=0, start=q2)
        if backwards or dist > -0.5 * self.depth:
            q, dq = touch_posture(w, i, geom, self.depth, restarts=self.restarts, rng=rng,
                                  start=first)
            if backwards or dq < dist:
                q3, dist = q, dq
                q2, _ = touch_posture(w, i, geom, -approach, restarts=0, start=q3)
                q1, _ = touch_posture(w, i, geom, restarts=0, point=above, start=q2)
        return [q0, q1, q2, q3], dist

    def _rollout(self, w, waypoints, max_steps) -> float:
        """Steps until the hand presses on the target when this plan runs on a scratch copy of
        the world (inf: never within ``max_steps``)."""
        m = w.model
        d = mujoco.MjData(m)
        d.qpos[:], d.qvel[:] = w.data.qpos, w.data.qvel
        d.act[:] = w.data.act
        mujoco.mj_forward(m, d)
        state = [0, 0, waypoints[0]]
        f = np.zeros(6)
        for step in range(1, max_steps + 1):
            u = self._control(d, waypoints, state)
            d.ctrl[self._act.actuator_ids] = self._act.torque(u)
            mujoco.mj_step(m, d)
            for c in range(d.ncon):
                con = d.contact[c]
                g1, g2 = con.geom1, con.geom2
                if (g1 == self._geom and self._hand[g2]) or (g2 == self._geom and self._hand[g1]):
                    mujoco.mj_contactForce(m, d, c, f)
                    if con.dist <= 0.0 and f[0] > 0.0:
                        return float(step)
        return float("inf")

    def _control(self, d, waypoints, state) -> np.ndarray:
        """The controls of one step (PD + compensation toward the current waypoint); ``state``
        [waypoint, steps in it, target angles] is advanced in place."""
        return follow_waypoints(d, waypoints, state, self._pace["hold_steps"],
                                self._pace["tolerance"], self._qadr, self._dadr, self._kp, self._kd,
                                self._tneg, self._tpos)

    def act(self, env, agent, observation):
        state = [self._wp, self._in_wp, self.target_angles]
        u = self._control(env.world.data, self.waypoints, state)
        self._wp, self._in_wp, self.target_angles = state
        return motor_action(env.action_space(agent), u)
