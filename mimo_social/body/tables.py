"""The infant's measurements, read from the CSV tables in ``body/data``.

The tables list the midline and the right side only; :func:`load_body` mirrors every
``right_*`` row into a ``left_*`` row across the sagittal (x-z) plane. See
``body/data/README.md`` for the sources and the meaning of each column.
"""

from __future__ import annotations

import csv
import functools
from dataclasses import dataclass, replace
from importlib import resources

import numpy as np

__all__ = ["Segment", "GeomSpec", "JointSpec", "SiteSpec", "BodyTables", "load_body",
           "HAND_VERSIONS", "subtree", "arm_joints"]

#: ``mitten``: the published v1 body (one-piece fingers, 44 motors); ``five_fingers``: the
#: published v2 body (five articulated fingers per hand, two toes per foot, 88 motors).
HAND_VERSIONS = ("mitten", "five_fingers")


@dataclass(frozen=True)
class Segment:
    name: str
    parent: str | None
    pos: tuple[float, float, float]
    quat: tuple[float, float, float, float]


@dataclass(frozen=True)
class GeomSpec:
    body: str
    name: str
    type: str  # sphere | capsule | cylinder | box
    size: tuple[float, ...]
    pos: tuple[float, float, float]
    axis: str  # local axis along which a capsule/cylinder runs: x | y | z
    mass: float
    friction: tuple[float, float, float] | None
    condim: int = 3


@dataclass(frozen=True)
class JointSpec:
    name: str
    body: str
    axis: tuple[float, float, float]
    range_deg: tuple[float, float]
    springref_deg: float
    stiffness: float
    damping: float
    frictionloss: float
    armature: float
    actuator: str | None
    gear: float | None
    force_lo: float | None
    force_hi: float | None
    vmax: float | None
    fmax_neg: float | None
    fmax_pos: float | None
    coupled_to: str | None
    coupling: float | None
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)  # the hinge's pivot in its body

    @property
    def torque_neg(self) -> float:
        """Maximum voluntary torque (Nm, positive number) in the joint's negative direction."""
        return float(self.gear * abs(self.force_lo))

    @property
    def torque_pos(self) -> float:
        """Maximum voluntary torque (Nm) in the joint's positive direction."""
        return float(self.gear * self.force_hi)


@dataclass(frozen=True)
class SiteSpec:
    name: str
    body: str
    pos: tuple[float, float, float]


@dataclass(frozen=True)
class BodyTables:
    hands: str
    segments: tuple[Segment, ...]
    geoms: tuple[GeomSpec, ...]
    joints: tuple[JointSpec, ...]
    touch_spacing: dict
    sites: tuple[SiteSpec, ...] = ()

    @property
    def total_mass(self) -> float:
        return float(sum(g.mass for g in self.geoms))

    @property
    def actuated_joints(self) -> tuple[JointSpec, ...]:
        return tuple(j for j in self.joints if j.actuator)


def _floats(text: str) -> tuple[float, ...]:
    return tuple(float(v) for v in text.split())


def _opt(text: str, cast=float):
    text = text.strip()
    return cast(text) if text else None


def _rows(filename: str) -> list[dict]:
    with resources.files("mimo_social.body").joinpath("data", filename).open() as f:
        return list(csv.DictReader(f))


def _muscle_rows(hands: str) -> dict:
    """The calibrated muscle parameters (``<hands>_muscles.csv``), if shipped."""
    path = resources.files("mimo_social.body").joinpath("data", f"{hands}_muscles.csv")
    if not path.is_file():
        return {}
    return {r["joint"]: (float(r["vmax"]), float(r["fmax_neg"]), float(r["fmax_pos"]))
            for r in _rows(f"{hands}_muscles.csv")}


def _mirror_name(name: str | None) -> str | None:
    if name and name.startswith("right_"):
        return "left_" + name[len("right_"):]
    return name


def _mirror_vec(v):  # a position: reflect y
    return (v[0], -v[1], v[2])


def _mirror_axis(a):  # an axial vector under reflection y -> -y: (-x, y, -z)
    return (-a[0], a[1], -a[2])


def _mirror_quat(q):  # M R M with M = diag(1, -1, 1): (w, x, y, z) -> (w, -x, y, -z)
    return (q[0], -q[1], q[2], -q[3])


def _with_left(rows: list, is_right, mirror) -> tuple:
    return tuple(rows) + tuple(mirror(r) for r in rows if is_right(r))


@functools.lru_cache(maxsize=None)
def load_body(hands: str = "mitten") -> BodyTables:
    """Read the measurement tables of one hand version and add the mirrored left side."""
    if hands not in HAND_VERSIONS:
        raise ValueError(f"hands={hands!r} is not a known hand version; allowed: {HAND_VERSIONS}")
    segs = [
        Segment(r["body"], r["parent"] or None, _floats(r["pos"]), _floats(r["quat"]))
        for r in _rows(f"{hands}_segments.csv")
    ]
    geoms = [
        GeomSpec(
            r["body"], r["geom"], r["type"], _floats(r["size"]), _floats(r["pos"]), r["axis"],
            float(r["mass"]), _floats(r["friction"]) if r["friction"].strip() else None,
            int(r.get("condim") or 3),
        )
        for r in _rows(f"{hands}_geoms.csv")
    ]
    joints = [
        JointSpec(
            r["joint"], r["body"], _floats(r["axis"]),
            (float(r["range_lo"]), float(r["range_hi"])),
            _opt(r["springref"]) or 0.0, float(r["stiffness"]), float(r["damping"]),
            _opt(r["frictionloss"]) or 0.0, float(r["armature"]),
            r["actuator"] or None, _opt(r["gear"]), _opt(r["force_lo"]), _opt(r["force_hi"]),
            _opt(r["vmax"]), _opt(r["fmax_neg"]), _opt(r["fmax_pos"]),
            r["coupled_to"] or None, _opt(r["coupling"]),
            _floats(r["pos"]) if (r.get("pos") or "").strip() else (0.0, 0.0, 0.0),
        )
        for r in _rows(f"{hands}_joints.csv")
    ]
    sites = [SiteSpec(r["site"], r["body"], _floats(r["pos"])) for r in _rows(f"{hands}_sites.csv")]
    muscles = _muscle_rows(hands)
    joints = [replace(j, vmax=muscles[j.name][0], fmax_neg=muscles[j.name][1],
                      fmax_pos=muscles[j.name][2]) if j.name in muscles else j for j in joints]
    spacing = {r["body"]: float(r["spacing"]) for r in _rows("touch_spacing.csv")}

    def right(name):
        return name.startswith("right_")

    segments = _with_left(
        segs, lambda s: right(s.name),
        lambda s: replace(s, name=_mirror_name(s.name), parent=_mirror_name(s.parent),
                          pos=_mirror_vec(s.pos), quat=_mirror_quat(s.quat)),
    )
    geoms_all = _with_left(
        geoms, lambda g: right(g.body),
        lambda g: replace(g, body=_mirror_name(g.body), name=_mirror_name(g.name),
                          pos=_mirror_vec(g.pos)),
    )
    joints_all = _with_left(
        joints, lambda j: right(j.name),
        lambda j: replace(j, name=_mirror_name(j.name), body=_mirror_name(j.body),
                          axis=_mirror_axis(j.axis), actuator=_mirror_name(j.actuator),
                          pos=_mirror_vec(j.pos)),
    )
    sites_all = _with_left(
        sites, lambda t: right(t.name),
        lambda t: replace(t, name=_mirror_name(t.name), body=_mirror_name(t.body),
                          pos=_mirror_vec(t.pos)),
    )
    spacing.update({_mirror_name(k): v for k, v in list(spacing.items()) if right(k)})
    # Depth-first tree order (a parent before its children, a limb's segments together).
    children: dict = {}
    for s in segments:
        children.setdefault(s.parent, []).append(s)
    order, stack = [], list(reversed(children.get(None, [])))
    while stack:
        s = stack.pop()
        order.append(s)
        stack.extend(reversed(children.get(s.name, [])))
    if len(order) != len(segments):
        raise ValueError("body table: a segment's parent is missing")
    return BodyTables(hands, tuple(order), geoms_all, joints_all, spacing, sites_all)


def joint_limits_rad(tables: BodyTables) -> np.ndarray:
    return np.deg2rad(np.array([j.range_deg for j in tables.joints]))


def subtree(tables: BodyTables, root: str) -> list[str]:
    """The segment ``root`` and every segment below it, in tree order."""
    inside = {root}
    out = []
    for seg in tables.segments:  # tree order: a parent comes before its children
        if seg.name == root or seg.parent in inside:
            inside.add(seg.name)
            out.append(seg.name)
    return out


def arm_joints(tables: BodyTables, side: str = "right") -> tuple[str, ...]:
    """The joints of one arm, shoulder to fingertips, in table order (8 for the mitten body:
    shoulder 3, elbow, wrist 3, fingers; 29 for the five-fingered one: 7 + 22 finger joints)."""
    bodies = set(subtree(tables, f"{side}_upper_arm"))
    return tuple(j.name for j in tables.joints if j.body in bodies)
