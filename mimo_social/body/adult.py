"""The adult caregiver's body: the infant's segments, joints, sites and names, adult-sized.

:func:`adult_tables` turns the 18-month tables of one hand version into a reference adult's
(``body/data/adult_*.csv``, sources in ``body/data/README.md``, "The adult caregiver"):

1. lengths: each segment's factor along its long axis (``axial``) makes its length the published
   fraction of stature (Drillis & Contini 1966, in Winter 2009 Fig. 4.1): the trunk spans hip to
   shoulder height, upper arm, forearm, hand, thigh, foot length; the shank takes the knee
   height less the ankle height as built; the head reaches the stature;
2. masses: each segment group's factor across it (``radial``) gives it its published mass
   fraction (de Leva 1996, female) at the infant's density; the head sphere's radius comes from
   the adult head circumference instead, and the rest of the head-and-neck fraction goes to the
   trunk (the model has no neck);
3. joint ranges from ``adult_ranges.csv`` (AAOS); motor torques from ``adult_torques.csv`` where
   measured, elsewhere the infant's torque times the ratio of adult to infant torque at the
   reference joint of its region (elbow flexion for the head and arms, the knee for the trunk
   and legs: the rule MIMo's authors used to fill their own table); the muscle ``fmax``
   follows each direction's torque, the joint stiffness, damping and friction loss the
   region's ratio; the armature (an inertia) and the eyes' motors keep the volume law of
   :func:`~mimo_social.body.resize.resize_body`.

The result is unscaled (``scale`` 1 means this adult); :func:`~mimo_social.body.tables.load_body`
applies ``scale`` and ``strength`` on top.
"""

from __future__ import annotations

import csv
import functools
import math
from dataclasses import replace
from importlib import resources

from .resize import resize_body
from .tables import BodyTables, GeomSpec, load_body, subtree

__all__ = ["adult_tables", "ANTHROPOMETRY", "MASS_FRACTIONS", "ADULT_RANGES", "ADULT_TORQUES",
           "STATURE", "BODY_MASS", "HEAD_CIRCUMFERENCE", "HEAD_RADIUS", "region_ratios"]


def _rows(name: str) -> list[dict]:
    with resources.files("mimo_social.body").joinpath("data", name).open() as f:
        return list(csv.DictReader(f))


#: quantity -> value (metres, kilograms, or a fraction ``H`` of stature)
ANTHROPOMETRY = {r["quantity"]: float(r["value"]) for r in _rows("adult_anthropometry.csv")}
#: mass group -> (its segments (right side / midline; ``name+``: with its subtree), fraction of
#: body mass (each side))
MASS_FRACTIONS = {r["group"]: (tuple(r["segments"].split()), float(r["fraction"]))
                  for r in _rows("adult_masses.csv")}
#: joint (midline / right side) -> (range_lo, range_hi) in degrees, the body's own signs
ADULT_RANGES = {r["joint"]: (float(r["range_lo"]), float(r["range_hi"]))
                for r in _rows("adult_ranges.csv")}
#: joint -> (torque_neg, torque_pos) in Nm; None: by its region's ratio
ADULT_TORQUES = {r["joint"]: tuple(float(v) if v.strip() else None
                                   for v in (r["torque_neg"], r["torque_pos"]))
                 for r in _rows("adult_torques.csv")}
STATURE = ANTHROPOMETRY["stature"]
BODY_MASS = ANTHROPOMETRY["body_mass"]
HEAD_CIRCUMFERENCE = ANTHROPOMETRY["head_circumference"]
#: the head sphere's radius (m), from the circumference
HEAD_RADIUS = HEAD_CIRCUMFERENCE / (2.0 * math.pi)

_AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
_GEOM_TO_SEGMENT = {"z": "xyz", "x": "zyx", "y": "xzy"}  # as in resize.py


def _half_extent(g: GeomSpec, axis: str) -> float:
    """Half the geom's extent along one axis of its segment."""
    r = g.size[0]
    if g.type == "sphere":
        return r
    if g.type in ("capsule", "cylinder"):
        if g.axis == axis:
            return g.size[1] + (r if g.type == "capsule" else 0.0)
        return r
    return g.size[_GEOM_TO_SEGMENT[g.axis].index(axis)]


def _offsets(tables: BodyTables, root: str) -> dict:
    """Each segment below ``root`` (whose frames keep ``root``'s orientation) -> its origin in
    ``root``'s frame; segments under a rotated frame (the thumb) are left out."""
    seg = {s.name: s for s in tables.segments}
    out = {root: (0.0, 0.0, 0.0)}
    for name in subtree(tables, root)[1:]:
        s = seg[name]
        if s.parent in out and tuple(s.quat) == (1.0, 0.0, 0.0, 0.0):
            p = out[s.parent]
            out[name] = tuple(a + b for a, b in zip(p, s.pos))
    return out


def _extent(tables: BodyTables, root: str, axis: str) -> tuple[float, float]:
    """(lowest, highest) coordinate along ``axis`` of the geoms of ``root``'s subtree in its
    frame (zero pose)."""
    k = _AXIS_INDEX[axis]
    where = _offsets(tables, root)
    lo, hi = math.inf, -math.inf
    for g in tables.geoms:
        if g.body in where:
            c = where[g.body][k] + g.pos[k]
            h = _half_extent(g, axis)
            lo, hi = min(lo, c - h), max(hi, c + h)
    return lo, hi


def _seg(tables: BodyTables, name: str):
    return next(s for s in tables.segments if s.name == name)


def _joint(tables: BodyTables, name: str):
    return next(j for j in tables.joints if j.name == name)


def _lengths(t: BodyTables) -> dict:
    """The hand (wrist pivot to fingertip), the foot (heel to toe tip) and the ankle height
    (ankle to sole) of these tables, in metres."""
    pivot = _joint(t, "right_wrist_flexion").pos[2]  # the wrist's pivot in the hand's frame
    lo_x, hi_x = _extent(t, "right_foot", "x")
    return {"hand": _extent(t, "right_hand", "z")[1] - pivot, "foot_length": hi_x - lo_x,
            "ankle_height": -_extent(t, "right_foot", "z")[0]}


def _axial_factors(t: BodyTables, built: dict, axial: dict | None = None) -> dict:
    """Segment -> axial factor from the stature fractions (see the module docstring). The hand
    and foot lengths and the ankle height mix lengths along and across their segments, so
    their factors are corrected from the lengths ``built`` with the previous ``axial``."""
    H, a = STATURE, ANTHROPOMETRY
    z = {n: _seg(t, n).pos[2] for n in ("lower_body", "upper_body", "head", "right_upper_arm",
                                        "right_lower_arm", "right_hand", "right_upper_leg",
                                        "right_lower_leg", "right_foot")}
    trunk = (z["lower_body"] + z["upper_body"] + z["right_upper_arm"] - z["right_upper_leg"])
    f = {"trunk": (a["shoulder_height"] - a["hip_height"]) * H / trunk}
    f["right_upper_arm"] = a["upper_arm"] * H / z["right_lower_arm"]
    if axial is None:
        infant = _lengths(t)
        f["right_hand"] = a["hand"] * H / infant["hand"]
        f["right_foot"] = a["foot_length"] * H / infant["foot_length"]
    else:
        f["right_hand"] = axial["right_hand"] * a["hand"] * H / built["hand"]
        f["right_foot"] = axial["right_foot"] * a["foot_length"] * H / built["foot_length"]
    pivot = _joint(t, "right_wrist_flexion").pos[2]
    f["right_lower_arm"] = (a["forearm"] * H - pivot * f["right_hand"]) / z["right_hand"]
    f["right_upper_leg"] = a["thigh"] * H / -z["right_lower_leg"]
    f["right_lower_leg"] = (a["knee_height"] * H - built["ankle_height"]) / -z["right_foot"]
    head = next(g for g in t.geoms if g.name == "head")
    hip_joint = a["hip_height"] * H
    neck = hip_joint + (z["lower_body"] + z["upper_body"] + z["head"]
                        - _seg(t, "right_upper_leg").pos[2]) * f["trunk"]
    f["head"] = (H - HEAD_RADIUS - neck) / head.pos[2]
    return f


def _groups(t: BodyTables) -> dict:
    """Mass group -> the segments (right side / midline) it resizes together."""
    out = {}
    for group, (segments, _) in MASS_FRACTIONS.items():
        names = []
        for s in segments:  # "name+": the segment and every segment below it
            names += subtree(t, s[:-1]) if s.endswith("+") else [s]
        out[group] = [n for n in names if n != "right_eye"]
    return out


def _factors(t: BodyTables, radial: dict, axial: dict) -> dict:
    """Segment -> (radial, axial[, long axis]) for the given group radials and axials."""
    groups = _groups(t)
    eye = ANTHROPOMETRY["eye_radius"] / next(g for g in t.geoms if g.name == "right_eye").size[0]
    out = {"right_eye": (eye, eye)}
    head_g = next(g for g in t.geoms if g.name == "head")
    out["head"] = (HEAD_RADIUS / head_g.size[0], axial["head"])
    for group, names in groups.items():
        if group == "head":
            continue
        for n in names:
            if group == "trunk":
                out[n] = (radial[group], axial["trunk"])
            elif group == "foot":
                out[n] = (radial[group], axial["right_foot"], "x")
            else:
                top = names[0]
                out[n] = (radial[group], axial[top])
    return out


def _group_masses(tables: BodyTables, groups: dict) -> dict:
    mass = {}
    for g in tables.geoms:
        mass[g.body] = mass.get(g.body, 0.0) + g.mass
    return {k: sum(mass.get(n, 0.0) for n in names) for k, names in groups.items()}


def _fit_factors(t: BodyTables) -> tuple[dict, dict]:
    """Each group's radial factor (its mass the published fraction of the body mass, at the
    infant's density) and each segment's axial factor (its length the published fraction of
    stature), by fixed-point iteration: mass grows as radial^2 to radial^3 (the step uses
    ^2.5), the hand and foot lengths and the ankle height mix radial and axial lengths."""
    groups = _groups(t)
    limbs = [k for k in groups if k not in ("head", "trunk")]
    radial = {k: 1.5 for k in groups if k != "head"}
    built = _lengths(t)
    built["ankle_height"] *= radial["foot"]
    axial = _axial_factors(t, built)
    for _ in range(_ITERATIONS):
        resized = resize_body(t, _factors(t, radial, axial))
        masses = _group_masses(resized, groups)
        head = masses["head"] + 2 * sum(g.mass for g in resized.geoms if g.body == "right_eye")
        target = {k: MASS_FRACTIONS[k][1] * BODY_MASS for k in limbs}
        target["trunk"] = ((MASS_FRACTIONS["trunk"][1] + MASS_FRACTIONS["head"][1]) * BODY_MASS
                           - head)
        radial = {k: r * (target[k] / masses[k]) ** 0.4 for k, r in radial.items()}
        axial = _axial_factors(t, _lengths(resized), axial)
    return radial, axial


#: fixed-point steps of :func:`_fit_factors` (masses and lengths then agree to ~1e-9)
_ITERATIONS = 30


def _region(t: BodyTables, joint) -> str | None:
    """``arm`` (head, neck, arms, hands), ``leg`` (trunk, legs, feet) or None (the eyes)."""
    if joint.body.endswith("_eye"):
        return None
    arms = set(subtree(t, "right_upper_arm")) | set(subtree(t, "left_upper_arm")) | {"head"}
    return "arm" if joint.body in arms else "leg"


def region_ratios(t: BodyTables) -> dict:
    """Adult / infant torque at each region's reference joint: ``arm``: elbow flexion;
    ``leg``: the knee (geometric mean of flexion and extension)."""
    elbow, knee = _joint(t, "right_elbow"), _joint(t, "right_knee")
    kn, kp = ADULT_TORQUES["right_knee"]
    return {"arm": ADULT_TORQUES["right_elbow"][0] / elbow.torque_neg,
            "leg": math.sqrt(kn / knee.torque_neg * kp / knee.torque_pos)}


def _mirror(name: str) -> str:
    return "right_" + name[len("left_"):] if name.startswith("left_") else name


def _adult_joint(j, infant_j, ratio: float):
    """The joint with the adult's range and torques (muscle fmax in proportion)."""
    if _mirror(j.name) in ADULT_RANGES:
        lo, hi = ADULT_RANGES[_mirror(j.name)]
        j = replace(j, range_deg=(lo, hi), springref_deg=min(max(j.springref_deg, lo), hi))
    if j.gear is None or ratio is None:
        return j
    want = ADULT_TORQUES.get(_mirror(j.name), (None, None))
    neg = want[0] if want[0] is not None else infant_j.torque_neg * ratio
    pos = want[1] if want[1] is not None else infant_j.torque_pos * ratio
    gear = max(neg, pos)
    k_neg, k_pos = neg / j.torque_neg, pos / j.torque_pos
    return replace(j, gear=gear, force_lo=-neg / gear, force_hi=pos / gear,
                   fmax_neg=None if j.fmax_neg is None else j.fmax_neg * k_neg,
                   fmax_pos=None if j.fmax_pos is None else j.fmax_pos * k_pos)


@functools.lru_cache(maxsize=None)
def adult_tables(hands: str = "mitten") -> BodyTables:
    """The reference adult's tables (``body="adult"``) for one hand version, unscaled: the
    infant's segments, joints, sites and names with adult lengths, masses, ranges and torques
    (see the module docstring; ``docs/bodies.md``, "The adult caregiver body")."""
    infant = load_body(hands)
    radial, axial = _fit_factors(infant)
    ratios = region_ratios(infant)
    region = {j.name: _region(infant, j) for j in infant.joints}
    torque_factors = {n: ratios[r] for n, r in region.items() if r is not None}
    factors = _factors(infant, radial, axial)
    resized = resize_body(infant, factors, torque_factors)
    # the armature is an inertia: it follows the mass and length moved (the volume law), not
    # the strength
    armature = {j.name: j.armature for j in resize_body(infant, factors).joints}
    before = {j.name: j for j in infant.joints}
    joints = tuple(_adult_joint(replace(j, armature=armature[j.name]), before[j.name],
                                ratios.get(region[j.name])) for j in resized.joints)
    return replace(resized, joints=joints, body="adult")
