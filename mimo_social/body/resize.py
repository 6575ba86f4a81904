"""Resize a body part by part: per segment, one factor along it and one across it.

:func:`resize_body` turns one body's tables into another's with other proportions (an infant of
another age, see :mod:`~mimo_social.body.growth`; an adult from the 18-month tables). Each
segment gets two factors, ``(radial, axial)``: every length along the segment's long axis (its
local z, or the axis named by an optional third entry, e.g. ``"x"`` for a foot, which runs
forward) is multiplied by ``axial``, every length across it by ``radial``. What the laws give:

- positions: a child segment's position in its parent's frame, and a geom's, site's or joint
  pivot's position in its own segment's frame, component by component with that frame's
  factors (``axial`` on the long axis, ``radial`` on the other two);
- geom sizes by shape: a sphere's radius ``radial``; a capsule's or cylinder's radius
  ``radial`` and its half-length ``axial`` when it runs along the segment's long axis, else
  ``radial``; a box's or ellipsoid's half-sizes component by component like positions;
- masses at constant density: each geom's mass times (new volume / old volume); MuJoCo derives
  the inertias from the masses and shapes;
- the torsional and rolling contact friction coefficients (lengths) times ``radial``;
- touch spacing times the segment's mean length factor ``(radial^2 axial)^(1/3)``, so every
  part keeps about the same number of touch points;
- joints (the volume law, after MIMo v2, which scales actuation strength with the volume of the
  body part moved): a joint on segment S moves S and everything distal to it (S's subtree);
  with ``v`` = (the subtree's geom volume now) / (its volume before), the motor torque (gear),
  the muscle ``fmax``, the joint stiffness, damping and friction loss are multiplied by ``v``
  and the armature, an inertia, by ``v * axial(S)^2``; muscle ``vmax`` (an angular speed),
  joint ranges and spring reference angles are unchanged. ``torque_factors`` (joint -> factor)
  replaces ``v`` for the joints it names.

A factor of exactly 1 multiplies by 1.0, so ``resize_body(t, {})`` and all-one factors return
every value bit for bit. A ``left_*`` segment missing from ``factors`` takes its ``right_*``
twin's factors (the tables are mirrored, and left and right stay symmetric); segments not
named (and without a named twin) keep their size.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Mapping

from .tables import DEFAULT_FRICTION, BodyTables, GeomSpec, subtree

__all__ = ["resize_body", "geom_volume"]

_AXES = "xyz"
# The segment axis each of a geom's local axes lies along, by the geom's `axis` column (the
# builder turns a geom's local z onto that axis: "x" by +90 degrees about y, "y" by -90 about x).
_GEOM_TO_SEGMENT = {"z": "xyz", "x": "zyx", "y": "xzy"}


def geom_volume(g: GeomSpec) -> float:
    """The geom's volume (m^3) from its shape and sizes."""
    s = g.size
    if g.type == "sphere":
        return 4.0 / 3.0 * math.pi * s[0] ** 3
    if g.type == "capsule":
        return math.pi * s[0] ** 2 * 2.0 * s[1] + 4.0 / 3.0 * math.pi * s[0] ** 3
    if g.type == "cylinder":
        return math.pi * s[0] ** 2 * 2.0 * s[1]
    if g.type == "box":
        return 8.0 * s[0] * s[1] * s[2]
    if g.type == "ellipsoid":
        return 4.0 / 3.0 * math.pi * s[0] * s[1] * s[2]
    raise ValueError(f"geom {g.name}: unknown shape {g.type!r}")


class _Frame:
    """The factors of one segment's frame."""

    def __init__(self, name: str, value):
        if not isinstance(value, (tuple, list)) or len(value) not in (2, 3):
            raise ValueError(f"resize_body: factors[{name!r}]={value!r}; allowed: (radial, "
                             "axial) or (radial, axial, long axis 'x'|'y'|'z')")
        radial, axial = (float(v) for v in value[:2])
        long = value[2] if len(value) == 3 else "z"
        if long not in _AXES:
            raise ValueError(f"resize_body: factors[{name!r}] long axis {long!r}; allowed: "
                             "'x', 'y', 'z'")
        for what, v in (("radial", radial), ("axial", axial)):
            if not (v > 0 and math.isfinite(v)):
                raise ValueError(f"resize_body: factors[{name!r}] {what}={v!r}; allowed: a "
                                 "positive finite number")
        self.radial, self.axial, self.long = radial, axial, long

    def along(self, axis: str) -> float:
        return self.axial if axis == self.long else self.radial

    def vec(self, v) -> tuple[float, ...]:
        return tuple(float(c) * self.along(a) for c, a in zip(v, _AXES))

    @property
    def mean(self) -> float:
        if self.radial == self.axial:
            return self.radial
        return (self.radial * self.radial * self.axial) ** (1.0 / 3.0)


_ONE = _Frame("", (1.0, 1.0))


def _geom_size(g: GeomSpec, f: _Frame) -> tuple[float, ...]:
    if g.type == "sphere":
        return (g.size[0] * f.radial,) + tuple(g.size[1:])
    if g.type in ("capsule", "cylinder"):
        return (g.size[0] * f.radial, g.size[1] * f.along(g.axis)) + tuple(g.size[2:])
    seg_axes = _GEOM_TO_SEGMENT[g.axis]
    return tuple(float(c) * f.along(a) for c, a in zip(g.size, seg_axes))


def resize_body(tables: BodyTables, factors: Mapping[str, tuple],
                torque_factors: Mapping[str, float] | None = None) -> BodyTables:
    """The tables with each segment resized by its ``(radial, axial)`` factors (see the module
    docstring for every law). ``factors``: segment name -> ``(radial, axial)`` or
    ``(radial, axial, long_axis)``; ``torque_factors``: joint name -> factor on its torque,
    muscle force and passive parameters instead of the volume law."""
    names = {s.name for s in tables.segments}
    unknown = sorted(set(factors) - names)
    if unknown:
        raise ValueError(f"resize_body: unknown segments {unknown}; known: {sorted(names)}")
    joint_names = {j.name for j in tables.joints}
    unknown = sorted(set(torque_factors or {}) - joint_names)
    if unknown:
        raise ValueError(f"resize_body: torque_factors for unknown joints {unknown}")
    frames = {}
    for s in tables.segments:
        key = s.name
        if key not in factors and key.startswith("left_"):
            key = "right_" + key[len("left_"):]
        frames[s.name] = _Frame(key, factors[key]) if key in factors else _ONE

    segments = tuple(
        s if s.parent is None else replace(s, pos=frames[s.parent].vec(s.pos))
        for s in tables.segments)

    geoms = []
    for g in tables.geoms:
        f = frames[g.body]
        new = replace(g, size=_geom_size(g, f), pos=f.vec(g.pos))
        fr = g.friction
        if fr is not None or f.radial != 1.0:
            fr = fr or DEFAULT_FRICTION
            fr = (fr[0], fr[1] * f.radial, fr[2] * f.radial)
        ratio = geom_volume(new) / geom_volume(g)
        geoms.append(replace(new, mass=g.mass * ratio, friction=fr))
    geoms = tuple(geoms)

    old_vol = _segment_volumes(tables.geoms)
    new_vol = _segment_volumes(geoms)
    subtree_ratio = {}
    for s in tables.segments:
        parts = subtree(tables, s.name)
        before = sum(old_vol.get(p, 0.0) for p in parts)
        after = sum(new_vol.get(p, 0.0) for p in parts)
        subtree_ratio[s.name] = after / before if before > 0 else 1.0

    def opt(v, k):
        return None if v is None else v * k

    joints = []
    for j in tables.joints:
        f = frames[j.body]
        v = float((torque_factors or {}).get(j.name, subtree_ratio[j.body]))
        joints.append(replace(
            j, pos=f.vec(j.pos), stiffness=j.stiffness * v, damping=j.damping * v,
            frictionloss=j.frictionloss * v, armature=j.armature * (v * f.axial * f.axial),
            gear=opt(j.gear, v), fmax_neg=opt(j.fmax_neg, v), fmax_pos=opt(j.fmax_pos, v)))
    sites = tuple(replace(t, pos=frames[t.body].vec(t.pos)) for t in tables.sites)
    spacing = {b: v * frames[b].mean if b in frames else v
               for b, v in tables.touch_spacing.items()}
    return replace(tables, segments=segments, geoms=geoms, joints=tuple(joints),
                   touch_spacing=spacing, sites=sites)


def _segment_volumes(geoms) -> dict:
    out: dict = {}
    for g in geoms:
        out[g.body] = out.get(g.body, 0.0) + geom_volume(g)
    return out
