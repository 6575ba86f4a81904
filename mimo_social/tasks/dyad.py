"""Two agents of any bodies face to face: their tables, held postures, distance and gaze.

The social tasks were tuned for two published 18-month-olds (``body="infant"``,
``age_months=None``, ``scale=1``) in the task's own posture; for such a pair every function here
gives exactly what the tasks used before (same distance, same held angles), but where the two
would start inside each other (the still face's sitting pair: moved from 0.6 to 0.696 m). Any
other pair (an adult caregiver, another age or scale, another posture) is measured in the
compiled world:

- **distance**: the pair meets where the tuned pair meets (the task's meeting point, by
  default where the high five's scripted 18-month-old holds its palm for the other:
  :data:`~mimo_social.partners.hand_offer.REACH_TO` from the learner's right shoulder), seen
  from the body with the lower shoulder and scaled by its arm over the 18-month-old's; the
  other body stands so that its right shoulder is as many of its own (straight) arm lengths
  from that point as in the tuned pair at the task's distance. Two bodies twice the size stand
  twice as far; a kneeling adult stands where its arm meets the infant's. The distance is never
  less than the task's distance times the smaller arm over the 18-month-old's, nor than the two
  bodies' forward depths (plus :data:`CLEARANCE`), so no two bodies start inside each other
  (:func:`pair_distance`). Social touch, where
  one touches the other's body, keeps instead the floor between the two bodies' forward depths
  as it is for two 18-month-olds (:func:`gap_distance`). Either way the pair, placed in its held
  postures on a measuring copy, is then moved apart until no part of one is inside any part of
  the other (:func:`clear_distance`: forward depths alone miss a head over another's legs, or
  feet of other sizes that meet instead of passing side by side).
- **gaze**: where a task holds head and eyes looking "straight ahead at the partner", a pair of
  other bodies holds them at the angles that look at the partner's face (head centre), from
  :class:`~mimo_social.core.kinematics.LookAt` on a measuring copy of the pair.
- **postures**: an agent in another posture than the task's (``posture="kneeling"`` or
  ``"sitting"`` for a caregiver) holds its legs and trunk as that posture's data say
  (:func:`~mimo_social.body.postures.posture_joints`, the adult's own variant), the task's
  other held angles kept.

Measuring an agent builds a one-agent world (about 30 ms), cached per body and posture.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable, Mapping, Sequence

import mujoco
import numpy as np

from ..body.joint_groups import GAZE_JOINTS
from ..body.postures import posture_joints
from ..body.tables import load_body
from ..core.config import AgentConfig
from ..core.kinematics import LookAt
from ..core.task import deepest_overlap
from ..core.world import AgentSetup, World
from ..partners.offer_target import REACH_TO

__all__ = ["CLEARANCE", "ADULT_LEAN_DEG", "LAWS", "Extent", "is_standard", "tables_of",
           "held_angles", "measure", "pair_distance", "gap_distance", "clear_distance",
           "facing_gaze", "DyadPlan", "plan_dyad", "task_plan"]

#: m: the least gap between the two bodies' forward depths when the distance is scaled
CLEARANCE = 0.03
#: deg: how far an adult leans its trunk (lower bend; the upper follows, coupled) toward the
#: infant in the tasks where hands meet: kneeling upright, an adult's right arm reaching down to
#: an 18-month-old's hands crosses its own belly; leaning 15 deg it reaches them over it (measured:
#: the high five with the kneeling adult, seeds 0-3: 4 / 4 in 43-55 steps with the lean, 1 / 4
#: without)
ADULT_LEAN_DEG = 15.0
#: rounds of :func:`facing_gaze` (mirror, kneeling adult: the second round moves the head
#: angles by up to 5 degrees, the third by 0.2, a fourth by 0.01)
GAZE_ROUNDS = 3
#: m: how much farther than the depth found :func:`clear_distance` moves a pair each round;
#: and the rounds it takes at most (one or two suffice: the depth is measured along the contact
#: normal, mostly along the line between the two)
CLEAR_MARGIN = 0.005
CLEAR_ROUNDS = 5
#: words naming the leg joints (hip, knee, ankle, toes)
LEG_WORDS = ("_hip_", "_knee", "_ankle_", "_toes")
#: the distance laws of :func:`plan_dyad`
LAWS = ("reach", "gap")
#: joints whose angle the measurement sets (free in the measuring copy): arm, head and eyes
_ARM_STRAIGHT = ("right_elbow", "right_wrist_rotation", "right_wrist_flexion", "right_wrist_ulnar")


def is_standard(config: AgentConfig, posture: str) -> bool:
    """Whether ``config`` is the body the task was tuned for: the published 18-month-old at
    scale 1 in the task's ``posture``."""
    return (config.body == "infant" and config.age_months is None and config.scale == 1.0
            and config.posture == posture)


def tables_of(config: AgentConfig):
    """The agent's own body tables (its hands, body kind, age, scale and strength)."""
    extra = {}
    if config.body != "infant":
        extra["body"] = config.body
    if config.age_months is not None:
        extra["age_months"] = config.age_months
    return load_body(config.hands, scale=config.scale, strength=config.strength, **extra)


def held_angles(config: AgentConfig, posture: str, angles: Mapping[str, float],
                lean: bool = False) -> dict:
    """The held angles (deg) of a task whose agents are in ``posture``: ``angles`` as they are
    for an agent in that posture; in another posture, the task's leg angles are dropped and
    that posture's joint angles (the body's own variant) replace the others where both name a
    joint. With ``lean``, an adult leans its trunk :data:`ADULT_LEAN_DEG` toward the partner
    (unless its posture's data set the trunk's bend)."""
    if config.posture == posture:
        out = dict(angles)
    else:   # the legs as the other posture has them; the task's other angles kept
        out = {k: v for k, v in angles.items() if not any(p in k for p in LEG_WORDS)}
        out.update(posture_joints(config.posture, config.body))
    own = posture_joints(config.posture, config.body)
    if lean and config.body == "adult" and "lower_trunk_bend" not in own:
        out["lower_trunk_bend"] = ADULT_LEAN_DEG
    return out


@dataclass(frozen=True)
class Extent:
    """One agent measured alone at (0, 0) facing +x in its held posture (m, world frame):
    its right shoulder (the upper arm's origin), its straight right arm (shoulder to palm
    centre), its head centre and its forward depth (the largest x any of its geoms reaches)."""

    shoulder: tuple[float, float, float]
    arm: float
    head: tuple[float, float, float]
    front: float



def _half_extent_x(m, d, geoms) -> np.ndarray:
    """Half extent of each geom along world x (exact for the primitive shapes the body uses;
    the bounding sphere for any other)."""
    R = d.geom_xmat[geoms].reshape(-1, 3, 3)
    rx = R[:, 0, :]       # the world-x row: components of world x in the geom's frame
    size = m.geom_size[geoms]
    t = m.geom_type[geoms]
    G = mujoco.mjtGeom
    out = m.geom_rbound[geoms].copy()
    sph = t == G.mjGEOM_SPHERE
    out[sph] = size[sph, 0]
    cap = t == G.mjGEOM_CAPSULE
    out[cap] = np.abs(rx[cap, 2]) * size[cap, 1] + size[cap, 0]
    cyl = t == G.mjGEOM_CYLINDER
    out[cyl] = (np.abs(rx[cyl, 2]) * size[cyl, 1]
                + size[cyl, 0] * np.sqrt(np.clip(1 - rx[cyl, 2] ** 2, 0, 1)))
    box = t == G.mjGEOM_BOX
    out[box] = np.sum(np.abs(rx[box]) * size[box], axis=1)
    ell = t == G.mjGEOM_ELLIPSOID
    out[ell] = np.sqrt(np.sum((rx[ell] * size[ell]) ** 2, axis=1))
    return out


def _measuring_config(config: AgentConfig) -> AgentConfig:
    return AgentConfig(hands=config.hands, body=config.body, age_months=config.age_months,
                       scale=config.scale, posture=config.posture, proprioception=None,
                       vestibular=None, touch=None, vision=None, expressions=False)


def _frozen_key(frozen: Mapping[str, float]) -> tuple:
    return tuple(sorted((k, round(float(v), 9)) for k, v in frozen.items()))


def measure(config: AgentConfig, frozen: Mapping[str, float]) -> Extent:
    """The :class:`Extent` of ``config`` holding ``frozen`` (joint -> rad); cached."""
    c = config
    return _measure(c.hands, c.body, c.age_months, c.scale, c.posture, _frozen_key(frozen))


@lru_cache(maxsize=64)
def _measure(hands, body, age_months, scale, posture, frozen_key) -> Extent:
    cfg = _measuring_config(AgentConfig(hands=hands, body=body, age_months=age_months,
                                        scale=scale, posture=posture))
    frozen = {k: v for k, v in frozen_key if k not in _ARM_STRAIGHT and "shoulder" not in k}
    w = World([AgentSetup(cfg, (0.0, 0.0), (1.0, 0.0), frozen, base="fixed")])
    m, d = w.model, w.data
    a = w.agents[0]
    front = float(np.max(d.geom_xpos[a.geom_ids, 0] + _half_extent_x(m, d, a.geom_ids)))
    head = tuple(float(x) for x in d.site_xpos[a.head_site])
    shoulder = tuple(float(x) for x in d.xpos[m.body(f"{w.names[0]}/right_upper_arm").id])
    for k, n in enumerate(a.joint_names):   # the right arm straight: elbow and wrist at 0
        if n in _ARM_STRAIGHT:
            d.qpos[a.qpos_adr[k]] = np.clip(0.0, *a.joint_range[k])
    mujoco.mj_kinematics(m, d)
    arm = float(np.linalg.norm(d.site_xpos[a.palm_sites[0]] - np.array(shoulder)))
    return Extent(shoulder, arm, head, front)


def pair_distance(distance: float, extents: Sequence[Extent], standard: Extent,
                  meet=REACH_TO) -> float:
    """Hip-to-hip distance of a pair with ``extents`` (agent 0 at the origin facing agent 1) in
    a task whose two ``standard`` bodies stand ``distance`` apart (see the module docstring).

    ``meet`` (m: forward, left, up from agent 0's right shoulder) is where the two meet in the
    standard pair; seen from each agent's own right shoulder that point is its own meeting
    point. The pair meets at the meeting point of the body with the lower shoulder, scaled by
    its arm over the standard arm; the other stands so that its right shoulder is as many of its
    arm lengths from there as in the standard pair. At least ``distance`` times the smaller arm
    over the standard arm, and the two forward depths plus :data:`CLEARANCE`, apart."""
    flip = np.array([-1.0, -1.0, 1.0])        # a body facing -x: its own x and y turned round

    def shoulders(e0: Extent, e1: Extent, dist: float) -> tuple[np.ndarray, np.ndarray]:
        return np.array(e0.shoulder), np.array([dist, 0.0, 0.0]) + flip * e1.shoulder

    std = shoulders(standard, standard, distance)
    point = std[0] + np.asarray(meet, float)
    own = (point - std[0], flip * (point - std[1]))               # in each one's own frame
    ratio = [np.linalg.norm(point - sh) / standard.arm for sh in std]
    small = 0 if extents[0].shoulder[2] <= extents[1].shoulder[2] else 1
    big = 1 - small
    # the smaller at the origin facing +x (the pair turned round if it is agent 1)
    here = np.array(extents[small].shoulder) + own[small] * extents[small].arm / standard.arm
    sh = flip * extents[big].shoulder        # the bigger's shoulder, its hip at (0, 0)
    across = (ratio[big] * extents[big].arm) ** 2 - (sh[1] - here[1]) ** 2 \
        - (sh[2] - here[2]) ** 2
    dist = here[0] - sh[0] + float(np.sqrt(max(across, 0.0)))
    # never nearer than the standard pair scaled to the smaller arm (a taller body reaching
    # down would otherwise crowd the smaller one), nor than the forward depths allow
    floor = distance * min(e.arm for e in extents) / standard.arm
    return float(max(dist, floor, sum(e.front for e in extents) + CLEARANCE))


def gap_distance(distance: float, extents: Sequence[Extent], standard: Extent) -> float:
    """Hip-to-hip distance that leaves the same floor between the two bodies' forward depths as
    two ``standard`` bodies have at ``distance`` (for tasks with things on the floor between
    them, or where one reaches the other's body)."""
    return float(distance - 2.0 * standard.front + sum(e.front for e in extents))


def clear_distance(configs: Sequence[AgentConfig], frozen: Sequence[Mapping[str, float]],
                   distance: float, slack: float = 0.0) -> float:
    """``distance``, or more: what a pair face to face in its held postures (``frozen``) needs
    for no part of one to be inside any part of the other when placed ``distance - slack``
    apart (``slack``: how much closer a task may draw them at reset), measured on a copy of
    the pair (:func:`~mimo_social.core.task.deepest_overlap`)."""
    bodies = tuple((c.hands, c.body, c.age_months, c.scale, c.posture) for c in configs)
    return _clear(bodies, tuple(_frozen_key(f) for f in frozen), round(float(distance), 9),
                  round(float(slack), 9))


@lru_cache(maxsize=64)
def _clear(bodies, frozen_keys, distance, slack) -> float:
    for _ in range(CLEAR_ROUNDS):
        d = distance - slack
        w = World([AgentSetup(_measuring_config(AgentConfig(hands=h, body=b, age_months=a,
                                                            scale=sc, posture=p)),
                              (0.0, 0.0) if i == 0 else (d, 0.0),
                              (d, 0.0) if i == 0 else (0.0, 0.0), dict(f), base="fixed")
                   for i, ((h, b, a, sc, p), f) in enumerate(zip(bodies, frozen_keys))])
        found = deepest_overlap(w, w.data, 0.0)
        if found is None:
            break
        distance += found[0] + CLEAR_MARGIN
    return float(distance)


def facing_gaze(setups: Sequence[AgentSetup], which: Sequence[int]) -> list[dict]:
    """For agents ``which`` of a pair, the head and eye angles (joint -> rad) that look at the
    other's face (head centre), measured on a copy of the pair with those joints free; a few
    rounds, each with the other's head turned as the last round found (a turned head moves its
    centre). Cached per pair (bodies, places, held angles): an age change at reset back to an
    age seen before compiles no measuring copy."""
    key = tuple((_measuring_config(s.config), tuple(float(x) for x in s.position),
                 tuple(float(x) for x in s.facing),
                 _frozen_key({k: v for k, v in s.frozen.items() if k not in GAZE_JOINTS}))
                for s in setups)
    return [dict(g) for g in _gaze(key, tuple(int(i) for i in which))]


@lru_cache(maxsize=64)
def _gaze(key: tuple, which: tuple) -> tuple:
    free = [AgentSetup(config, position, facing, dict(frozen), base="fixed")
            for config, position, facing, frozen in key]
    w = World(free)
    m = w.model
    looks = {i: LookAt(w, i) for i in which}
    pose = w.data.qpos.copy()
    scratch = mujoco.MjData(m)
    for _ in range(GAZE_ROUNDS):
        angles = {}
        for i, look in looks.items():
            scratch.qpos[:] = pose
            angles[i] = look(m, scratch, "site", int(w.agents[1 - i].head_site))
        for i, q in angles.items():
            pose[looks[i].qpos] = q
    out = []
    for i in range(len(key)):
        if i not in looks:
            out.append({})
            continue
        names = [w.agents[i].joint_names[k] for k in looks[i].joints]
        out.append({n: float(v) for n, v in zip(names, pose[looks[i].qpos])})
    return tuple(out)


@dataclass(frozen=True)
class DyadPlan:
    """Where a pair stands and what it holds: the distance (m) and, per agent, extra held
    angles (joint -> rad) that replace the task's."""

    distance: float
    gaze: tuple[dict, dict]
    standard: bool = False    # the pair the task was tuned for (nothing changed)


def plan_dyad(configs: Sequence[AgentConfig], posture: str, distance: float,
              frozen_of: Callable[[int, AgentConfig], Mapping[str, float]],
              look: Sequence[int] = (0, 1), meet=REACH_TO, law: str = "reach",
              slack: float = 0.0) -> DyadPlan:
    """The placement of a pair in a task tuned for two standard bodies in ``posture`` at
    ``distance``: for a standard pair exactly that (no extra angles); else the scaled distance
    (:func:`pair_distance`) and, for agents ``look`` (whose head and eyes the task holds), the
    angles that look at the partner's face. Either distance is moved out until the pair is
    clear of each other even ``slack`` closer (:func:`clear_distance`). ``law``: ``"reach"``
    (:func:`pair_distance`, where ``meet`` is the meeting point) or ``"gap"``
    (:func:`gap_distance`). ``frozen_of(i, config)``: the task's held angles (joint -> rad) of
    agent ``i`` with that config."""
    frozen = [frozen_of(i, c) for i, c in enumerate(configs)]
    if all(is_standard(c, posture) for c in configs):
        # as tuned, unless the two would start inside each other (the still face's two sitting
        # infants at 0.6 m: feet 3.6 cm in each other)
        return DyadPlan(clear_distance(configs, frozen, distance, slack), ({}, {}), True)
    ref = AgentConfig(hands=configs[0].hands, posture=posture)
    standard = measure(ref, frozen_of(0, ref))
    extents = [measure(c, f) for c, f in zip(configs, frozen)]
    if law not in LAWS:
        raise ValueError(f"plan_dyad: law={law!r}; allowed: {list(LAWS)}")
    dist = pair_distance(distance, extents, standard, meet) if law == "reach" \
        else gap_distance(distance, extents, standard)
    dist = clear_distance(configs, frozen, dist, slack)
    if not look:
        return DyadPlan(dist, ({}, {}))
    setups = [AgentSetup(c, (0.0, 0.0) if i == 0 else (dist, 0.0),
                         (dist, 0.0) if i == 0 else (0.0, 0.0), f, base="fixed")
              for i, (c, f) in enumerate(zip(configs, frozen))]
    gaze = facing_gaze(setups, look)
    return DyadPlan(dist, (gaze[0], gaze[1]))


def task_plan(task, posture: str, distance: float,
              frozen_of: Callable[[int, AgentConfig], Mapping[str, float]],
              look: Sequence[int] = (0, 1), meet=REACH_TO, law: str = "reach",
              slack: float = 0.0) -> DyadPlan:
    """:func:`plan_dyad` for a two-agent task's current ``task.configs`` (set by the env before
    it calls ``setup``), computed once per env; without two configs (a task's ``setup`` called
    alone), the standard plan."""
    configs = tuple(getattr(task, "configs", ()) or ())
    if len(configs) != 2:
        return DyadPlan(float(distance), ({}, {}), True)
    cached = _PLANS.get(task)
    if cached is not None and cached[0] is task.configs:
        return cached[1]
    plan = plan_dyad(configs, posture, distance, frozen_of, look, meet, law, slack)
    _PLANS[task] = (task.configs, plan)
    return plan


#: each task object's last plan, with the configs it was made for (forgotten with the task)
_PLANS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
