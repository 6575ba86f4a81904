"""The infant's measurements, read from the CSV tables in ``body/data``.

The tables list the midline and the right side only; :func:`load_body` mirrors every
``right_*`` row into a ``left_*`` row across the sagittal (x-z) plane. See
``body/data/README.md`` for the sources and the meaning of each column.

A body of another size or strength (an older child, a caregiver-sized partner) is the same
tables scaled once, here, by :func:`load_body` (``scale``, ``strength``; see :func:`scale_body`
and ``docs/bodies.md``): the builder, the actuation models and the touch skin read the scaled
values and know nothing of the scaling.
"""

from __future__ import annotations

import csv
import functools
from dataclasses import dataclass, replace
from importlib import resources

import numpy as np

__all__ = ["Segment", "GeomSpec", "JointSpec", "SiteSpec", "BodyTables", "load_body",
           "scale_body", "HAND_VERSIONS", "BODY_KINDS", "AGE_RANGE", "SCALE_RANGE",
           "STRENGTH_RANGE", "SCALING_EXPONENTS", "DEFAULT_FRICTION", "subtree", "arm_joints"]

#: ``mitten``: the published v1 body (one-piece fingers, 44 motors); ``five_fingers``: the
#: published v2 body (five articulated fingers per hand, two toes per foot, 88 motors).
HAND_VERSIONS = ("mitten", "five_fingers")

#: Allowed body size factors (every length times ``scale``; 1: the 18-month-old, 77.8 cm) and
#: strength factors (every motor's maximum torque and muscle's maximum force, on top of the size
#: law). Strength stops at 3: at the default physics, bang-bang actions (every motor at -1 or +1,
#: redrawn each step) ran 60k steps without a divergence at 3 and 4 for the smallest body (scale
#: 0.5) and at 6 for scale 1, but diverged every few thousand steps at 5 (scale 0.5) and 7
#: (scale 1), and every ~160 steps at 10 (docs/reliability.md, "Instability").
SCALE_RANGE = (0.5, 2.5)
STRENGTH_RANGE = (0.1, 3.0)

#: The exponent of ``scale`` each kind of table value is multiplied by (geometric similarity,
#: constant density, and dynamic similarity under the same gravity: a body ``s`` times larger
#: moves like the original on a time scale ``sqrt(s)``). ``strength`` multiplies motor torques
#: and muscle forces on top. Angles (joint ranges, spring references, orientations), the sliding
#: friction coefficient and dimensionless ratios (trunk couplings) do not change.
SCALING_EXPONENTS = {
    "length": 1.0,          # segment, geom, site and joint-pivot positions, geom sizes
    "mass": 3.0,            # geom masses (MuJoCo derives inertias, x s^5, from mass and shape)
    "torque": 4.0,          # motor gear (torque limits): m g L
    "stiffness": 4.0,       # joint springs, Nm/rad: a torque per angle
    "damping": 4.5,         # Nm s/rad: a torque per angular speed (speeds scale by s^-0.5)
    "frictionloss": 4.0,    # dry joint friction, Nm
    "armature": 5.0,        # rotor inertia added to a joint, kg m^2
    "muscle_fmax": 4.0,     # the muscle model's fmax acts as a torque (the moment arm is a ratio)
    "muscle_vmax": -0.5,    # the muscle model's vmax is an angular speed: slower by sqrt(s)
    "touch_spacing": 1.0,   # sensor spacing: the same number of points on every part
    "contact_length": 1.0,  # torsional and rolling friction coefficients (metres)
}

#: A geom's contact friction when its table row leaves it empty: sliding, torsional (m), rolling
#: (m), the published model's default.
DEFAULT_FRICTION = (1.0, 0.005, 0.0002)


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
    scale: float = 1.0      # the size factor these tables were scaled by (see scale_body)
    strength: float = 1.0   # the strength factor on top of the size law
    age_months: float | None = None  # the age grown to (body/growth.py); None: the 18-month body
    motor_age_months: float | None = None  # the motors' age when not the body's (load_body)
    body: str = "infant"    # "infant" or "adult" (body/adult.py)

    @property
    def total_mass(self) -> float:
        return float(sum(g.mass for g in self.geoms))

    @property
    def actuated_joints(self) -> tuple[JointSpec, ...]:
        return tuple(j for j in self.joints if j.actuator)

    @property
    def standing_height(self) -> float:
        """Top of the head to the soles (m) with every joint at 0 (standing straight): the
        vertical extent of all geoms, from the segments' positions and orientations."""
        return _vertical_extent(self)


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


def _factor(name: str, value, allowed: tuple[float, float]) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name}={value!r}; allowed: a number from {allowed[0]:g} to "
                         f"{allowed[1]:g}")
    value = float(value)
    if not allowed[0] <= value <= allowed[1]:  # NaN fails too
        raise ValueError(f"{name}={value!r} is out of range; allowed: {allowed[0]:g} to "
                         f"{allowed[1]:g}")
    return value


#: Body kinds: the infant (of an age, ``body/growth.py``) and the adult (``body/adult.py``).
BODY_KINDS = ("infant", "adult")
#: Infant ages (months) the growth curves cover (``body/growth.py``).
AGE_RANGE = (0.0, 33.0)


def load_body(hands: str = "mitten", scale: float = 1.0, strength: float = 1.0,
              age_months: float | None = None, body: str = "infant",
              motor_age_months: float | None = None) -> BodyTables:
    """The measurement tables of one hand version with the mirrored left side: the infant grown
    to ``age_months`` (0 to 33; None: the published 18-month body; see ``body/growth.py``) or,
    for ``body="adult"``, the adult caregiver (``body/adult.py``); then scaled to a body
    ``scale`` times that size and ``strength`` times its strength (see :func:`scale_body`).
    ``scale=1, strength=1, age_months=None`` gives the published tables unchanged, and so does
    ``age_months=18``, bit for bit.

    ``motor_age_months`` (infants, 0 to 33; None: the body's age): the motors of another age:
    every joint's motor torque (``gear``) and muscle force (``fmax_neg``, ``fmax_pos``) are
    those of the body grown to ``motor_age_months`` (its volume-law strength, what a body of
    that age has); sizes, masses and passive joint parameters stay the body's.

    Cached: the same arguments give the same (immutable) object.
    """
    if hands not in HAND_VERSIONS:
        raise ValueError(f"hands={hands!r} is not a known hand version; allowed: {HAND_VERSIONS}")
    if body not in BODY_KINDS:
        raise ValueError(f"body={body!r} is not a known body; allowed: {BODY_KINDS}")
    if age_months is not None:
        if body != "infant":
            raise ValueError(f"age_months={age_months!r} is for infant bodies; body={body!r} "
                             "takes age_months=None")
        age_months = _factor("age_months", age_months, AGE_RANGE)
    scale = _factor("scale", scale, SCALE_RANGE)
    strength = _factor("strength", strength, STRENGTH_RANGE)
    tables = _load(hands, scale, strength, age_months, body)
    if motor_age_months is None:
        return tables
    if body != "infant":
        raise ValueError(f"motor_age_months={motor_age_months!r} is for infant bodies; "
                         f"body={body!r} takes motor_age_months=None")
    motor = _factor("motor_age_months", motor_age_months, AGE_RANGE)
    if motor == (REFERENCE_AGE if age_months is None else age_months):
        return tables
    return _with_motors(hands, scale, strength, age_months, motor)


#: the age (months) of the published body (``age_months=None``)
REFERENCE_AGE = 18.0


@functools.lru_cache(maxsize=None)
def _with_motors(hands: str, scale: float, strength: float, age_months: float | None,
                 motor_age_months: float) -> BodyTables:
    """The infant's tables at ``age_months`` with every joint's motor torque and muscle force
    from the same body grown to ``motor_age_months``."""
    tables = _load(hands, scale, strength, age_months, "infant")
    motors = _load(hands, scale, strength, motor_age_months, "infant")
    strong = {j.name: j for j in motors.joints}
    joints = tuple(replace(j, gear=strong[j.name].gear, fmax_neg=strong[j.name].fmax_neg,
                           fmax_pos=strong[j.name].fmax_pos) for j in tables.joints)
    return replace(tables, joints=joints, motor_age_months=motors.age_months)


#: The makers of the bodies other than the published infant: ``"grow"`` ->
#: ``grow_body(tables, age_months)`` (body/growth.py) and ``"adult"`` -> ``adult_tables(hands)``
#: (body/adult.py). They build on this module, so it cannot import them (no import cycle):
#: ``body/__init__.py`` wires them in when the package is imported.
MAKERS: dict = {}


def _maker(name: str):
    if name not in MAKERS:
        raise ValueError(f"the {name!r} body maker is not available (body/__init__.py wires it "
                         f"in); available: {sorted(MAKERS)}")
    return MAKERS[name]


@functools.lru_cache(maxsize=None)
def _load(hands: str, scale: float, strength: float, age_months: float | None = None,
          body: str = "infant") -> BodyTables:
    if body == "adult":
        tables = replace(_maker("adult")(hands), body="adult")
    elif age_months is not None:
        tables = _maker("grow")(_published(hands), age_months)
    else:
        tables = _published(hands)
    if scale == 1.0 and strength == 1.0:
        return tables
    return scale_body(tables, scale, strength)


def _cache_clear() -> None:
    """Forget every loaded table (after the CSV files changed, e.g. a muscle calibration)."""
    _load.cache_clear()
    _with_motors.cache_clear()
    _published.cache_clear()
    for maker in MAKERS.values():     # the adult's tables are cached by their maker
        getattr(maker, "cache_clear", lambda: None)()


load_body.cache_clear = _cache_clear


def scale_body(tables: BodyTables, scale: float, strength: float = 1.0) -> BodyTables:
    """The tables of a body ``scale`` times as large and ``strength`` times as strong.

    Every value is multiplied by ``scale ** SCALING_EXPONENTS[kind]`` (and motor torques and
    muscle forces by ``strength``): lengths and positions ``s``, masses ``s^3`` (inertias follow
    as ``s^5``: MuJoCo computes them from the scaled masses and shapes), motor torque limits
    ``s^4 strength``, joint stiffness ``s^4``, damping ``s^4.5``, friction loss ``s^4``,
    armature ``s^5``, muscle ``fmax`` ``s^4 strength`` and ``vmax`` ``s^-0.5``, touch spacing
    ``s``, torsional and rolling friction ``s``. Angles and ratios are kept. Applied to the
    published tables (``tables.scale == 1``) or again to scaled ones (factors multiply).
    """
    s, k = float(scale), float(strength)
    if not (s > 0 and k > 0 and np.isfinite(s) and np.isfinite(k)):
        raise ValueError(f"scale_body: scale={scale!r}, strength={strength!r}; both must be "
                         "positive numbers")
    e = SCALING_EXPONENTS

    def f(kind):
        return s ** e[kind]

    def vec(v):
        return tuple(float(c) * f("length") for c in v)

    def opt(v, factor):
        return None if v is None else float(v) * factor

    def friction(fr):
        fr = fr or DEFAULT_FRICTION
        return (float(fr[0]), fr[1] * f("contact_length"), fr[2] * f("contact_length"))

    segments = tuple(replace(seg, pos=vec(seg.pos)) for seg in tables.segments)
    geoms = tuple(replace(g, size=vec(g.size), pos=vec(g.pos), mass=g.mass * f("mass"),
                          friction=friction(g.friction)) for g in tables.geoms)
    joints = tuple(replace(
        j, pos=vec(j.pos), stiffness=j.stiffness * f("stiffness"),
        damping=j.damping * f("damping"), frictionloss=j.frictionloss * f("frictionloss"),
        armature=j.armature * f("armature"), gear=opt(j.gear, f("torque") * k),
        vmax=opt(j.vmax, f("muscle_vmax")), fmax_neg=opt(j.fmax_neg, f("muscle_fmax") * k),
        fmax_pos=opt(j.fmax_pos, f("muscle_fmax") * k)) for j in tables.joints)
    sites = tuple(replace(t, pos=vec(t.pos)) for t in tables.sites)
    spacing = {b: v * f("touch_spacing") for b, v in tables.touch_spacing.items()}
    return replace(tables, segments=segments, geoms=geoms, joints=joints,
                   touch_spacing=spacing, sites=sites, scale=tables.scale * s,
                   strength=tables.strength * k)


@functools.lru_cache(maxsize=None)
def _published(hands: str) -> BodyTables:
    """Read the measurement tables of one hand version and add the mirrored left side."""
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


def _quat_rotate(q, v) -> np.ndarray:
    w, u = q[0], np.asarray(q[1:], float)
    v = np.asarray(v, float)
    return v + 2.0 * np.cross(u, np.cross(u, v) + w * v)


def _quat_mul(a, b) -> tuple:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw)


_GEOM_AXIS = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


def _vertical_extent(tables: BodyTables) -> float:
    """Highest minus lowest point of every geom with the segments at their table pose."""
    frames = {}
    for seg in tables.segments:  # tree order
        if seg.parent is None:
            frames[seg.name] = (np.asarray(seg.pos, float), tuple(seg.quat))
        else:
            p, q = frames[seg.parent]
            frames[seg.name] = (p + _quat_rotate(q, seg.pos), _quat_mul(q, seg.quat))
    lo, hi = np.inf, -np.inf
    for g in tables.geoms:
        p, q = frames[g.body]
        centre = (p + _quat_rotate(q, g.pos))[2]
        ez = np.array([_quat_rotate(q, e)[2] for e in np.eye(3)])  # segment axes' z parts
        if g.type == "sphere":
            half = g.size[0]
        elif g.type in ("capsule", "cylinder"):
            c = abs(float(np.dot(ez, _GEOM_AXIS[g.axis])))
            across = g.size[0] * np.sqrt(max(0.0, 1.0 - c * c))
            half = g.size[1] * c + (g.size[0] if g.type == "capsule" else across)
        else:  # box, ellipsoid (its bounding box); sizes on the segment's axes (axis "z")
            half = float(np.dot(np.abs(ez), g.size[:3]))
        lo, hi = min(lo, centre - half), max(hi, centre + half)
    return float(hi - lo)


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
