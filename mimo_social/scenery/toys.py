"""Toys of the play room: free bodies made of primitives, sized for an 18-month-old's hand.

Each toy is a :class:`Toy` (data): its primitives in the toy's frame, its total mass (spread
over the primitives by volume), its friction and contact softness. :func:`add_toy` puts one in
a spec as a free body ``playroom/<toy>`` (geoms ``playroom/<toy>`` or ``playroom/<toy>/<part>``).

Sizes and masses, with where they come from (the infant's own mitten hand is 10 cm long, palm
5.6 cm and fingers 4.6 cm, and 4.2 cm wide: one hand closes round 3-5 cm, two hands hold
8-15 cm):

===========  ==============================  =======  ========  ==============================
toy          shape                           mass     friction  reasoning
===========  ==============================  =======  ========  ==============================
block_*      cube, 4 cm edge                 45 g     0.6       beech, 0.7 g/cm^3 x 64 cm^3
ball_red     sphere, 8 cm                    60 g     0.8       a soft rubber ball, hollow
ball_blue    sphere, 12 cm                   110 g    0.8       a vinyl play ball (two hands)
rattle       handle 2 x 10 cm + 5.6 cm head  50 g     0.7       a plastic rattle, 40-80 g
cup          cylinder cup, 7 cm x 6 cm       25 g     0.5       a stacking cup, 2 mm plastic
teddy        plush bear, 17 cm tall          150 g    1.0       plush toys of this size
===========  ==============================  =======  ========  ==============================

Frictions: wood, rubber, plastic and fabric on a foam mat (sliding coefficients 0.5-1.0);
balls also have a little rolling friction (``condim`` 6) so that they come to rest. The teddy
is soft (a longer ``solref`` time constant and a wider ``solimp``: it gives under a press).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from .meshes import add_box_mesh

__all__ = ["Primitive", "Toy", "TOYS", "add_toy", "rest_height"]

_SHAPES = {"sphere": mujoco.mjtGeom.mjGEOM_SPHERE, "box": mujoco.mjtGeom.mjGEOM_BOX,
           "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE, "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
           "ellipsoid": mujoco.mjtGeom.mjGEOM_ELLIPSOID}


@dataclass(frozen=True)
class Primitive:
    """One shape of a toy: MuJoCo sizes, centre and (for capsules, cylinders) its axis."""

    shape: str
    size: tuple[float, ...]
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    rgba: tuple[float, float, float, float] | None = None
    name: str = ""

    def volume(self) -> float:
        s = self.size
        if self.shape == "sphere":
            return 4 / 3 * np.pi * s[0] ** 3
        if self.shape == "box":
            return 8 * s[0] * s[1] * s[2]
        if self.shape == "capsule":
            return np.pi * s[0] ** 2 * 2 * s[1] + 4 / 3 * np.pi * s[0] ** 3
        if self.shape == "cylinder":
            return np.pi * s[0] ** 2 * 2 * s[1]
        return 4 / 3 * np.pi * s[0] * s[1] * s[2]      # ellipsoid

    def low(self) -> float:
        """The lowest z of the shape in the toy's frame (upright)."""
        s, z = self.size, self.pos[2]
        a = np.abs(np.asarray(self.axis, float)) / np.linalg.norm(self.axis)
        if self.shape == "sphere":
            return z - s[0]
        if self.shape == "box":
            return z - s[2]
        if self.shape == "ellipsoid":
            return z - s[2]
        if self.shape == "capsule":
            return z - s[1] * a[2] - s[0]
        return z - s[1] * a[2] - s[0] * np.sqrt(max(0.0, 1 - a[2] ** 2))


@dataclass(frozen=True)
class Toy:
    """A toy: primitives, total mass (kg), colour, friction (sliding, torsional, rolling),
    ``condim`` and contact softness (``solref``, ``solimp``; None: MuJoCo's defaults)."""

    name: str
    parts: tuple[Primitive, ...]
    mass: float
    rgba: tuple[float, float, float, float]
    friction: tuple[float, float, float] = (0.6, 0.005, 0.0001)
    condim: int = 3
    solref: tuple[float, float] | None = None
    solimp: tuple[float, ...] | None = None
    source: str = ""
    #: drawn as one mesh of its box parts (the colliding parts invisible): one geom for the
    #: eyes to draw instead of many (:mod:`.meshes`)
    one_mesh: bool = False


def _block(name, rgba):
    return Toy(name, (Primitive("box", (0.02, 0.02, 0.02)),), 0.045, rgba, (0.6, 0.005, 0.0001),
               source="beech, 0.7 g/cm^3 x 64 cm^3")


def _cup(name, rgba, r=0.035, h=0.03, wall=0.002, n=10):
    parts = [Primitive("cylinder", (r, wall), (0, 0, -h + wall), name="bottom")]
    side = 2 * r * np.tan(np.pi / n) + 0.001
    for k in range(n):
        a = 2 * np.pi * k / n
        # the walls stand on the bottom disc, clear of what the cup stands on
        parts.append(Primitive("box", (wall, side / 2, h - 1.5 * wall),
                               (r * np.cos(a), r * np.sin(a), 1.5 * wall),
                               axis=(np.cos(a), np.sin(a), 0),
                               name=f"wall_{k}"))
    return Toy(name, tuple(parts), 0.025, rgba, (0.5, 0.005, 0.0001),
               source="a stacking cup, 2 mm plastic", one_mesh=True)


def _teddy(name, rgba):
    dark = (0.35, 0.22, 0.14, 1.0)
    parts = (Primitive("ellipsoid", (0.042, 0.036, 0.05), (0, 0, 0.05), name="body"),
             Primitive("sphere", (0.038,), (0, 0, 0.125), name="head"),
             Primitive("sphere", (0.014,), (0, 0.03, 0.155), name="ear_left"),
             Primitive("sphere", (0.014,), (0, -0.03, 0.155), name="ear_right"),
             Primitive("sphere", (0.014,), (0.033, 0, 0.118), rgba=(0.93, 0.80, 0.62, 1),
                       name="snout"),
             Primitive("sphere", (0.006,), (0.046, 0, 0.122), rgba=dark, name="nose"),
             Primitive("capsule", (0.014, 0.02), (0.01, 0.045, 0.07), axis=(0.3, 0.3, -1),
                       name="arm_left"),
             Primitive("capsule", (0.014, 0.02), (0.01, -0.045, 0.07), axis=(0.3, -0.3, -1),
                       name="arm_right"),
             Primitive("sphere", (0.02,), (0.03, 0.03, 0.02), name="leg_left"),
             Primitive("sphere", (0.02,), (0.03, -0.03, 0.02), name="leg_right"))
    return Toy(name, parts, 0.15, rgba, (1.0, 0.01, 0.0005), solref=(0.04, 1.0),
               solimp=(0.7, 0.9, 0.01), source="plush toys of this size weigh 100-200 g")


#: every toy of the room, by name
TOYS: dict[str, Toy] = {t.name: t for t in (
    _block("block_red", (0.88, 0.25, 0.22, 1)),
    _block("block_yellow", (0.98, 0.80, 0.22, 1)),
    _block("block_blue", (0.25, 0.45, 0.88, 1)),
    _block("block_green", (0.30, 0.72, 0.35, 1)),
    Toy("ball_red", (Primitive("sphere", (0.04,)),), 0.06, (0.92, 0.22, 0.25, 1),
        (0.8, 0.005, 0.0005), condim=6, source="a soft rubber ball, hollow"),
    Toy("ball_blue", (Primitive("sphere", (0.06,)),), 0.11, (0.25, 0.55, 0.95, 1),
        (0.8, 0.005, 0.0005), condim=6, source="a vinyl play ball"),
    Toy("rattle", (Primitive("capsule", (0.01, 0.04), (-0.045, 0, 0), axis=(1, 0, 0),
                             name="handle"),
                   Primitive("sphere", (0.028,), (0.03, 0, 0), rgba=(0.98, 0.80, 0.25, 1),
                             name="head")),
        0.05, (0.55, 0.35, 0.85, 1), (0.7, 0.005, 0.0002), source="plastic rattles, 40-80 g"),
    _cup("cup", (0.20, 0.72, 0.70, 1)),
    _teddy("teddy", (0.72, 0.52, 0.32, 1)),
)}


def rest_height(toy: Toy) -> float:
    """How far above a surface the toy's origin is when it rests upright on it."""
    return -min(p.low() for p in toy.parts)


def add_toy(spec: mujoco.MjSpec, toy: Toy, pos, yaw_deg: float = 0.0,
            sleep: bool = False) -> str:
    """Add ``toy`` as a free body ``playroom/<toy>`` resting with its origin at ``pos`` (the
    surface height plus :func:`rest_height`); with ``sleep`` MuJoCo may put it to sleep while
    it rests (``mjENBL_SLEEP`` on). Returns the body name."""
    name = f"playroom/{toy.name}"
    yaw = np.deg2rad(yaw_deg)
    body = spec.worldbody.add_body(name=name, pos=list(pos),
                                   quat=[np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)])
    body.add_freejoint(name=name)
    if sleep:
        body.sleep = mujoco.mjtSleepPolicy.mjSLEEP_ALLOWED
    density = toy.mass / sum(p.volume() for p in toy.parts)
    for k, p in enumerate(toy.parts):
        g = body.add_geom(name=name if len(toy.parts) == 1 else f"{name}/{p.name or k}",
                          type=_SHAPES[p.shape], pos=list(p.pos), density=density,
                          rgba=list(p.rgba or toy.rgba), friction=list(toy.friction),
                          condim=toy.condim)
        size = np.zeros(3)
        size[:len(p.size)] = p.size
        g.size = size
        if p.shape in ("capsule", "cylinder", "box") and tuple(p.axis) != (0.0, 0.0, 1.0):
            q = np.zeros(4)
            if p.shape == "box":   # a box turned about z to face along its axis
                a = np.arctan2(p.axis[1], p.axis[0])
                q[:] = (np.cos(a / 2), 0, 0, np.sin(a / 2))
            else:
                mujoco.mju_quatZ2Vec(q, np.asarray(p.axis, float))
            g.quat = q
        if toy.solref is not None:
            g.solref = list(toy.solref)
        if toy.solimp is not None:
            imp = np.array([0.9, 0.95, 0.001, 0.5, 2.0])
            imp[:len(toy.solimp)] = toy.solimp
            g.solimp = imp
        if toy.one_mesh:
            g.group = 3
    if toy.one_mesh:
        boxes = []
        for p in toy.parts:
            a = np.arctan2(p.axis[1], p.axis[0]) if p.shape == "box" else 0.0
            R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
            half = p.size if p.shape == "box" else (0.85 * p.size[0], 0.85 * p.size[0], p.size[1])
            boxes.append((np.asarray(p.pos, float), R, np.asarray(half, float)))
        add_box_mesh(spec, f"{name}/look", boxes, rgba=toy.rgba, body=body)
    return name
