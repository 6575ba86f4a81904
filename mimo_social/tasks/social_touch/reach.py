"""Reach geometry of the social touch toucher's right arm: the geom sets of an arm, a partner
and a target part (:class:`ArmGeometry`), arm postures by damped least squares that put the
hand's finger pads into a part (:func:`hand_posture`, :func:`reach_posture`), the sides a hand
may come in from (:data:`SIDES`, :func:`side_normal`, :func:`surface_point`) and the rule that
decides a first touch (:func:`first_touch`, the task's). Used by
:class:`~mimo_social.tasks.social_touch.controller.SocialTouchController` and the task's
reachability tests.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...body.joint_groups import RIGHT_SHOULDER_ELBOW, RIGHT_WRIST
from ...core.kinematics import geoms_collide, hand_geoms

__all__ = ["ARM", "ArmGeometry", "BACK_COS", "SIDES", "TILT_DEG", "TOUCH_CLEARANCE", "first_touch",
           "hand_posture", "reach_posture", "side_normal", "surface_point"]

#: the toucher's arm joints that reach: shoulder, elbow, wrist
ARM = RIGHT_SHOULDER_ELBOW + RIGHT_WRIST
#: the hand touches with the finger pads: the palm's normal tipped this far towards the fingertips
TILT_DEG = 45.0
#: a hand contact whose normal (into the partner) has a component at or below this along the
#: palm's normal is the back of the hand, which does not count (the social touch task's rule)
BACK_COS = -0.5

#: the last step in: the arm may come this close (m) to the target's neighbours
TOUCH_CLEARANCE = 0.004

#: sides of the partner the hand may come in from (x: from the toucher to the partner, y: the
#: toucher's left, z: up), as normals of the partner's surface
SIDES = {"front": (-1.0, 0.0, 0.0), "above": (0.0, 0.0, 1.0), "front_above": (-1.0, 0.0, 1.0),
         "outside_above": (0.0, -1.0, 1.0), "front_outside": (-1.0, -1.0, 0.0),
         "front_outside_above": (-1.0, -1.0, 1.0)}


def _subtree_geoms(m, a, root: int) -> np.ndarray:
    inside = np.zeros(m.nbody, bool)
    inside[root] = True
    for b in sorted(a.body_ids.tolist()):   # MuJoCo numbers a parent before its children
        if b != root and inside[m.body_parentid[b]]:
            inside[b] = True
    return a.geom_ids[inside[m.geom_bodyid[a.geom_ids]]]


class ArmGeometry:
    """Geom sets of one toucher / partner / part: the arm, the hand, the palm, the target and
    the obstacles of each arm geom (pairs MuJoCo collides)."""

    def __init__(self, world, i: int, j: int, part: str):
        m = world.model
        a, b = world.agents[i], world.agents[j]
        try:
            body = m.body(f"{b.name}/{part}").id
        except KeyError:
            raise ValueError(f"SocialTouchController: target {part!r} is no body part of "
                             f"{b.name}") from None
        inside = np.zeros(m.nbody, bool)
        inside[body] = True
        if part.endswith("_hand"):   # a hand includes its fingers (the task's rule)
            for c in sorted(b.body_ids.tolist()):
                if c != body and inside[m.body_parentid[c]]:
                    inside[c] = True
        self.target = np.flatnonzero(inside[m.geom_bodyid])
        if not len(self.target):
            raise ValueError(f"SocialTouchController: {b.name}'s part {part!r} has no geoms")
        self.target_body = body
        self.arm = _subtree_geoms(m, a, m.body(f"{a.name}/right_upper_arm").id)
        self.hand = np.asarray(hand_geoms(world, i, 0), np.intp)
        palm_body = int(m.site_bodyid[a.palm_sites[0]])
        self.palm_body = palm_body
        self.palm = np.flatnonzero(m.geom_bodyid == palm_body)
        in_arm = np.isin(a.geom_ids, self.arm)
        own = a.geom_ids[~in_arm]
        others = np.concatenate([own, b.geom_ids])
        is_target = np.isin(others, self.target)
        self.obstacles = {}
        for g in self.arm.tolist():
            hand = g in set(self.hand.tolist())
            self.obstacles[g] = np.array([o for o, t in zip(others.tolist(), is_target)
                                          if geoms_collide(m, g, o) and not (hand and t)], np.intp)


def hand_posture(world, i: int, j: int, part: str, gap: float, start=None, iters: int = 300,
                 clearance: float = 0.015, tilt_deg: float = TILT_DEG, direction=None,
                 point=None, geometry: ArmGeometry | None = None) -> tuple[np.ndarray, float, float, np.ndarray]:
    """Right-arm joint angles of agent ``i`` (its actuated joints, rad; the fingers straight)
    that put its hand ``gap`` m from agent ``j``'s body part ``part`` (negative: into it), the
    hand's touching direction (the palm's normal tipped ``tilt_deg`` towards the fingertips:
    the finger pads) pointing at the part, every arm geom ``clearance`` from everything else (the
    partner's other parts, the own body; the forearm and upper arm from the target too).
    ``direction``: a fixed approach direction (world, unit) instead of the line between the
    nearest points (moving in along the normal found at a stand-off); ``point`` (world): put
    the centre of the fingertips there instead (``gap`` is then not used), the touching
    direction along ``direction``.

    Damped least squares on a scratch copy of the state (``start``: the first angles, default
    the current ones). Returns the angles, the hand's signed distance to the part (m), the worst
    clearance violation (m, 0 when every geom is clear) and the approach direction (unit).
    """
    m = world.model
    a = world.agents[i]
    geo = geometry if geometry is not None else ArmGeometry(world, i, j, part)
    k = a.actuated_joint_idx
    names = list(a.actuated_names)
    arm = np.array([names.index(n) for n in ARM if n in names])
    qadr, dadr = a.qpos_adr[k], a.dof_adr[k]
    lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
    d = mujoco.MjData(m)
    d.qpos[:] = world.data.qpos
    q = d.qpos[qadr].copy() if start is None else np.array(start, float)
    fingers = np.setdiff1d(np.arange(len(names)), arm)
    q[fingers] = np.clip(0.0, lo[fingers], hi[fingers])
    d.qpos[qadr] = np.clip(q, lo, hi)
    cols = dadr[arm]
    fromto = np.zeros(6)
    jac, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    rb = m.geom_rbound
    tip = int(a.fingertip_sites[0])
    tilt = np.deg2rad(tilt_deg)
    # in the hand's frame: the palm side is -y, the fingers point along +z
    touch_dir = np.array([0.0, -np.cos(tilt), np.sin(tilt)])
    dist = worst = np.inf
    for _ in range(iters):
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        rows, errs = [], []
        dist = np.inf
        for h in geo.hand.tolist():
            for t in geo.target.tolist():
                s = float(mujoco.mj_geomDistance(m, d, h, t, 1.0, fromto))
                if s < dist:
                    dist, p_h, p_t, gt, gh = s, fromto[:3].copy(), fromto[3:].copy(), t, h
        if direction is not None:
            u = np.asarray(direction, float)
        else:
            u = p_t - p_h
            if dist <= 1e-4 or np.linalg.norm(u) < 1e-6:
                u = d.geom_xpos[gt] - p_h
            u = u / max(np.linalg.norm(u), 1e-9)
        if point is None:
            mujoco.mj_jac(m, d, jac, None, p_h, int(m.geom_bodyid[gh]))
            rows.append(jac[:, cols].copy())
            errs.append(u * (dist - gap))
        else:
            mujoco.mj_jacSite(m, d, jac, None, tip)
            rows.append(jac[:, cols].copy())
            errs.append(np.asarray(point, float) - d.site_xpos[tip])
        mujoco.mj_jacBody(m, d, None, jacr, geo.palm_body)
        pointing = d.xmat[geo.palm_body].reshape(3, 3) @ touch_dir
        rows.append(0.05 * jacr[:, cols])
        errs.append(0.05 * np.cross(pointing, u))
        worst = 0.0
        for g, obs in geo.obstacles.items():
            if not len(obs):
                continue
            near = obs[np.linalg.norm(d.geom_xpos[obs] - d.geom_xpos[g], axis=1)
                       < rb[obs] + rb[g] + clearance + 0.02]
            for o in near.tolist():
                s = float(mujoco.mj_geomDistance(m, d, g, o, clearance + 0.02, fromto))
                if s < clearance:
                    p_g, p_o = fromto[:3].copy(), fromto[3:].copy()
                    v = p_g - p_o
                    if s <= 1e-4 or np.linalg.norm(v) < 1e-6:
                        v = p_g - d.geom_xpos[o]
                    v /= max(np.linalg.norm(v), 1e-9)
                    mujoco.mj_jac(m, d, jac, None, p_g, int(m.geom_bodyid[g]))
                    rows.append(jac[:, cols].copy())
                    errs.append(v * (clearance - s))
                    worst = max(worst, clearance - s)
        e = np.concatenate(errs)
        if np.linalg.norm(errs[0]) < 1e-3 and worst < 1e-3 and np.linalg.norm(errs[1]) < 2e-3:
            break
        J = np.vstack(rows)
        step = J.T @ np.linalg.solve(J @ J.T + 1e-4 * np.eye(len(e)), e)
        d.qpos[qadr[arm]] = np.clip(d.qpos[qadr[arm]] + np.clip(step, -0.1, 0.1),
                                    lo[arm], hi[arm])
    return d.qpos[qadr].copy(), float(dist), float(worst), u


def first_touch(m, d, geo: ArmGeometry, arm_mask: np.ndarray, partner_mask: np.ndarray):
    """``None`` while the arm touches nothing of the partner; else whether the first contact
    includes the hand on the target, not with its back (contact normal within 120 deg of the
    palm's normal)."""
    n = d.ncon
    if n == 0:
        return None
    c = d.contact
    g1, g2 = c.geom1[:n], c.geom2[:n]
    hit = ((arm_mask[g1] & partner_mask[g2]) | (arm_mask[g2] & partner_mask[g1])) \
        & (c.dist[:n] <= 0.0)
    if not hit.any():
        return None
    for k in np.flatnonzero(hit).tolist():
        mine, other, sign = (g1[k], g2[k], 1.0) if arm_mask[g1[k]] else (g2[k], g1[k], -1.0)
        if other in geo.target and mine in geo.hand:
            palm = -d.xmat[m.geom_bodyid[mine]].reshape(3, 3)[:, 1]
            if sign * float(c.frame[k, :3] @ palm) > BACK_COS:
                return True
    return False


def side_normal(world, i: int, j: int, side: str) -> np.ndarray:
    """The unit normal of a side (a key of :data:`SIDES`) of agent ``j``, seen from agent ``i``:
    x from ``i`` to ``j`` (level), z up, y to ``i``'s left."""
    d = world.data
    ex = d.xpos[world.agents[j].body_ids[0]] - d.xpos[world.agents[i].body_ids[0]]
    ex[2] = 0.0
    ex /= max(np.linalg.norm(ex), 1e-9)
    ez = np.array([0.0, 0.0, 1.0])
    v = np.asarray(SIDES[side], float) @ np.vstack([ex, np.cross(ez, ex), ez])
    return v / np.linalg.norm(v)


def surface_point(world, geometry: ArmGeometry, n: np.ndarray):
    """Where a ray coming in along ``-n`` through the target part's centre of mass first meets
    the part (None: it misses)."""
    m, d = world.model, world.data
    pnt = d.xipos[geometry.target_body] + 0.3 * n
    vec = -np.asarray(n, float)
    best = np.inf
    for g in geometry.target.tolist():
        t = mujoco.mju_rayGeom(d.geom_xpos[g], d.geom_xmat[g], m.geom_size[g], pnt, vec,
                               int(m.geom_type[g]))
        if 0.0 <= t < best:
            best = t
    return None if not np.isfinite(best) else pnt + best * vec


def reach_posture(world, i: int, j: int, part: str, depth: float = 0.005,
                  clearance: float = 0.0) -> tuple[np.ndarray, float, float]:
    """A right-arm posture of agent ``i`` with its hand (finger pads) ``depth`` into agent
    ``j``'s ``part``, the arm ``clearance`` from everything else (0: touching nothing else):
    :func:`hand_posture` along the line to the part's nearest point and in from each of
    :data:`SIDES`; the best (deepest with the smallest violation). Returns the angles, the hand's
    signed distance to the part (m) and the worst clearance violation (m). The task's reachability
    check."""
    geo = ArmGeometry(world, i, j, part)
    best = None
    kw = {"clearance": clearance, "geometry": geo}
    starts = [hand_posture(world, i, j, part, 0.05, geometry=geo)]
    for side in SIDES:
        n = side_normal(world, i, j, side)
        s = surface_point(world, geo, n)
        if s is not None:
            starts.append(hand_posture(world, i, j, part, 0.0, direction=-n, geometry=geo,
                                       point=s + 0.06 * n))
    for q0, _, _, u in starts:
        q, dist, worst, _ = hand_posture(world, i, j, part, -depth, start=q0, direction=u, **kw)
        score = max(dist + depth, 0.0) + worst
        if best is None or score < best[0]:
            best = (score, q, dist, worst)
    return best[1], best[2], best[3]
