"""Build one infant as a ``mujoco.MjSpec`` from the measurement tables.

Names in the returned spec are UNPREFIXED (``hip``, ``right_elbow`` ...); the world attaches each
infant with a prefix per agent (``infant_0/``). Angles are radians everywhere
(``spec.compiler.degree = False``).

Joints a task wants held still are *frozen*: when a frozen joint comes before every free joint
of its segment, its rotation is folded into the segment's orientation and the joint disappears
from the model (no degree of freedom, no cost); otherwise it is held by an equality constraint.
Motors of frozen joints are not built.

A larger or stronger body (``scale``, ``strength``), an infant of another age
(``age_months``) or the adult (``body``) is built from the tables of
:func:`~mimo_social.body.tables.load_body`; nothing here depends on the size.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from importlib import resources
from typing import Mapping

import mujoco
import numpy as np

from .tables import DEFAULT_FRICTION, BodyTables, load_body, subtree

__all__ = ["InfantBuild", "build_infant", "axis_angle_quat", "quat_mul"]

# Contact and joint-limit solver settings of the published model's defaults.
GEOM_SOLIMP = (0.95, 0.99, 0.001, 0.5, 1.0)
GEOM_SOLREF = (0.005, 1.0)
GEOM_FRICTION = DEFAULT_FRICTION  # sliding, torsional (m), rolling (m)
LIMIT_SOLIMP = (0.98, 0.99, 0.001, 0.5, 1.0)
LIMIT_SOLREF = (0.02, 1.0)

SKIN_RGBA = (0.94, 0.78, 0.67, 1.0)
SCLERA_RGBA = (0.97, 0.96, 0.93, 1.0)
IRIS_RGBA = (0.36, 0.24, 0.13, 1.0)
PUPIL_RGBA = (0.04, 0.03, 0.03, 1.0)
# The visible eyeball (in eye radii r, along the eye's +x, its line of sight): the eye sphere is
# the white sclera; the iris is a lens-shaped ellipsoid (centre 0.85 r, semi-axes 0.5 r across,
# 0.19 r deep) whose front bulges out of the sphere as a disc of radius ~0.48 r (a human iris:
# ~12 of ~24 mm); the pupil a thin disc of radius 0.22 r just on the iris's front. Both are
# visual only (no contact, no mass, no touch). The eye camera sits just in front of the pupil
# (EYE_CAMERA_X r), so an eye never sees its own eyeball, iris or pupil.
IRIS = (0.85, 0.5, 0.19)          # centre x, radius across, half depth (eye radii)
PUPIL = (1.035, 0.22, 0.012)      # centre x, radius, half thickness (eye radii)
EYE_CAMERA_X = 1.06
DEFAULT_CLOTHES_RGBA = (0.35, 0.55, 0.85, 1.0)
# Segments shown in skin colour (and every segment of the hands below them); the rest wear the
# agent's clothes colour.
SKIN_SEGMENTS = {"head", "right_hand", "left_hand", "right_fingers", "left_fingers",
                 "right_lower_arm", "left_lower_arm"}
EYE_FOVY_DEG = 60.0


def axis_angle_quat(axis, angle: float) -> np.ndarray:
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    return np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis])


def quat_mul(a, b) -> np.ndarray:
    out = np.empty(4)
    mujoco.mju_mulQuat(out, np.asarray(a, float), np.asarray(b, float))
    return out


_AXIS_QUATS = {  # rotate a primitive's local z onto the named axis of its segment
    "z": (1.0, 0.0, 0.0, 0.0),
    "x": tuple(axis_angle_quat((0, 1, 0), np.pi / 2)),
    "y": tuple(axis_angle_quat((1, 0, 0), -np.pi / 2)),
}


@dataclass
class InfantBuild:
    """The spec of one infant and what the builder decided (unprefixed names)."""

    spec: mujoco.MjSpec
    tables: BodyTables
    joints: list[str]            # hinge joints present in the model, in model order
    actuated: list[str]          # joints with a motor, in actuator order
    actuators: list[str]         # motor names, same order as `actuated`
    frozen: dict[str, float]     # joint -> held angle (rad)
    locked: list[str] = field(default_factory=list)  # frozen joints held by an equality


def _excludes(hands: str) -> list[tuple[str, str]]:
    with resources.files("mimo_social.body").joinpath("data").joinpath(
            f"{hands}_excludes.csv").open() as f:
        rows = [(r["body_a"], r["body_b"]) for r in csv.DictReader(f)]
    mirror = [(a.replace("right_", "left_"), b.replace("right_", "left_")) for a, b in rows]
    return sorted(set(rows + mirror))


def build_infant(
    hands: str = "mitten",
    frozen: Mapping[str, float] | None = None,
    base: str = "free",
    clothes_rgba=DEFAULT_CLOTHES_RGBA,
    scale: float = 1.0,
    strength: float = 1.0,
    age_months: float | None = None,
    body: str = "infant",
    motor_age_months: float | None = None,
) -> InfantBuild:
    """Build one infant.

    Args:
        hands: hand version: ``"mitten"`` (44 motors) or ``"five_fingers"`` (88 motors).
        frozen: joint name -> angle (rad) to hold the joint at. Frozen trunk joints drag their
            coupled partner along (at the coupling ratio) unless it is named too.
        base: ``"free"`` (a free joint at the hip: the infant can walk, fall, be pushed) or
            ``"fixed"`` (the hip is fixed to the world at its placement).
        clothes_rgba: colour of the clothed segments, so infants can be told apart.
        scale: body size factor, 0.5 to 2.5 (every length times ``scale``; masses, inertias,
            torques, passive joint parameters, muscles and touch spacing follow the scaling laws
            of :func:`~mimo_social.body.tables.scale_body`).
        strength: factor on every motor's maximum torque and muscle's maximum force, 0.1 to 3
            (:data:`~mimo_social.body.tables.STRENGTH_RANGE`).
        age_months: the infant's age, 0 to 33 months (segments from growth curves, see
            :mod:`~mimo_social.body.growth`); None: the published 18-month body.
        body: ``"infant"`` or ``"adult"`` (the adult caregiver's tables, ``body/adult.py``).
        motor_age_months: the motors' age (torques, muscle forces: those of the body grown to
            it), 0 to 33 months; None: the body's age.
    """
    tables = load_body(hands, scale, strength, age_months, body, motor_age_months)
    if base not in ("free", "fixed"):
        raise ValueError(f"base={base!r}; allowed: 'free', 'fixed'")
    by_name = {j.name: j for j in tables.joints}
    frozen = dict(frozen or {})
    unknown = sorted(set(frozen) - set(by_name))
    if unknown:
        raise ValueError(f"cannot freeze unknown joints {unknown}; known joints: {sorted(by_name)}")
    for j in tables.joints:  # a frozen driver joint freezes its coupled follower
        if j.coupled_to in frozen and j.name not in frozen:
            frozen[j.name] = frozen[j.coupled_to] * j.coupling
    for name, angle in frozen.items():
        lo, hi = np.deg2rad(by_name[name].range_deg)
        if not lo - 1e-9 <= angle <= hi + 1e-9:
            raise ValueError(
                f"frozen angle {angle:.3f} rad for {name} is outside its range [{lo:.3f}, {hi:.3f}] rad")

    spec = mujoco.MjSpec()
    spec.modelname = "mimo"
    spec.compiler.degree = False
    spec.compiler.autolimits = True

    joints_of: dict[str, list] = {}
    for j in tables.joints:
        joints_of.setdefault(j.body, []).append(j)

    skin = set(SKIN_SEGMENTS)
    for side in ("right", "left"):
        skin.update(subtree(tables, f"{side}_hand"))
    bodies = {}
    present, locked = [], []
    for seg in tables.segments:
        parent = spec.worldbody if seg.parent is None else bodies[seg.parent]
        quat = np.array(seg.quat, float)
        seg_joints = joints_of.get(seg.name, [])
        folding = True
        to_build = []
        for j in seg_joints:  # fold a leading run of frozen joints into the segment orientation
            if folding and j.name in frozen:
                quat = quat_mul(quat, axis_angle_quat(j.axis, frozen[j.name]))
            else:
                folding = False
                to_build.append(j)
        body = parent.add_body(name=seg.name, pos=seg.pos, quat=quat)
        bodies[seg.name] = body
        if seg.parent is None and base == "free":
            body.add_freejoint(name="root")
        for j in to_build:
            lo, hi = np.deg2rad(j.range_deg)
            body.add_joint(
                name=j.name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=j.axis, range=[lo, hi],
                limited=mujoco.mjtLimited.mjLIMITED_TRUE,
                springref=np.deg2rad(j.springref_deg), stiffness=[j.stiffness, 0.0, 0.0],
                damping=[j.damping, 0.0, 0.0], frictionloss=j.frictionloss,
                armature=j.armature, solimp_limit=LIMIT_SOLIMP, solref_limit=LIMIT_SOLREF,
                pos=j.pos,
            )
            present.append(j.name)
            if j.name in frozen:
                locked.append(j.name)
        _add_geoms(body, seg.name, tables, clothes_rgba, skin)

    _add_sites_cameras_sensors(spec, bodies, tables)

    for a, b in _excludes(hands):
        spec.add_exclude(bodyname1=a, bodyname2=b)
    # MuJoCo skips parent-child contacts, except when the parent is welded to the world (a fixed
    # hip with a frozen trunk): then the shoulders would hold the upper arms and the neck the
    # head. Excluding every parent-child pair keeps the rule in every case.
    for seg in tables.segments:
        if seg.parent is not None:
            spec.add_exclude(bodyname1=seg.parent, bodyname2=seg.name)

    for j in tables.joints:  # trunk coupling, when both joints are free to move
        if j.coupled_to and j.name in present and j.coupled_to in present \
                and j.name not in frozen:
            spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=j.name, name2=j.coupled_to,
                              data=np.r_[0.0, j.coupling, np.zeros(10)])
    for name in locked:  # frozen joints that could not be folded away
        spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=name,
                          data=np.r_[frozen[name], np.zeros(11)])

    actuated, actuators = [], []
    for j in tables.joints:
        if j.actuator and j.name in present and j.name not in frozen:
            spec.add_actuator(
                name=j.actuator, target=j.name, trntype=mujoco.mjtTrn.mjTRN_JOINT,
                gear=[1, 0, 0, 0, 0, 0], ctrlrange=[-j.torque_neg, j.torque_pos],
                forcerange=[-j.torque_neg, j.torque_pos],
                ctrllimited=mujoco.mjtLimited.mjLIMITED_TRUE,
                forcelimited=mujoco.mjtLimited.mjLIMITED_TRUE,
            )
            actuated.append(j.name)
            actuators.append(j.actuator)
    return InfantBuild(spec, tables, present, actuated, actuators, frozen, locked)


def _add_geoms(body, segment: str, tables: BodyTables, clothes_rgba, skin) -> None:
    rgba = SKIN_RGBA if segment in skin else clothes_rgba
    eye = segment.endswith("_eye")
    if eye:  # the eye sphere is the white of the eye; the iris and pupil are added below
        rgba = SCLERA_RGBA
    for g in tables.geoms:
        if g.body != segment:
            continue
        gtype = {"sphere": mujoco.mjtGeom.mjGEOM_SPHERE, "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
                 "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER, "box": mujoco.mjtGeom.mjGEOM_BOX,
                 "ellipsoid": mujoco.mjtGeom.mjGEOM_ELLIPSOID}[g.type]
        size = np.zeros(3)
        size[: len(g.size)] = g.size
        body.add_geom(
            name=g.name, type=gtype, size=size, pos=g.pos, quat=_AXIS_QUATS[g.axis],
            mass=g.mass, friction=g.friction or GEOM_FRICTION, condim=g.condim,
            solimp=GEOM_SOLIMP, solref=GEOM_SOLREF, rgba=rgba, group=0,
        )
        if eye:
            _add_iris_pupil(body, g.name, float(g.size[0]), np.asarray(g.pos, float),
                            g.friction or GEOM_FRICTION)


def _add_iris_pupil(body, eye: str, r: float, centre: np.ndarray, friction) -> None:
    """The iris and pupil of eye sphere ``eye`` (radius ``r``): visual only, they turn with the
    eye's joints. No contact (contype = conaffinity = 0), no mass: the body's mass and
    inertia are those of the tables (the friction, unused, is the eye's, so it scales alike)."""
    x = centre  # in the eye's frame, whose +x is the line of sight
    visual = dict(contype=0, conaffinity=0, mass=0.0, density=0.0, group=0,
                  quat=_AXIS_QUATS["x"], friction=friction)
    cx, across, depth = IRIS
    body.add_geom(name=f"{eye}_iris", type=mujoco.mjtGeom.mjGEOM_ELLIPSOID,
                  size=[across * r, across * r, depth * r], pos=x + [cx * r, 0.0, 0.0],
                  rgba=IRIS_RGBA, **visual)
    cx, radius, half = PUPIL
    body.add_geom(name=f"{eye}_pupil", type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                  size=[radius * r, half * r, 0.0], pos=x + [cx * r, 0.0, 0.0],
                  rgba=PUPIL_RGBA, **visual)


def mouth_position(head_geom) -> np.ndarray:
    """The mouth site in the head's body frame: the head sphere's front (its centre + r x)."""
    return np.asarray(head_geom.pos, float) + (float(head_geom.size[0]), 0.0, 0.0)


def _add_sites_cameras_sensors(spec, bodies, tables: BodyTables) -> None:
    head_geom = next(g for g in tables.geoms if g.name == "head")
    bodies["head"].add_site(name="head_centre", pos=head_geom.pos, size=[0.005, 0, 0])
    # the mouth: on the face's front, where a voice comes from (senses/audition.py)
    bodies["head"].add_site(name="mouth", pos=mouth_position(head_geom), size=[0.005, 0, 0])
    for site in tables.sites:  # palm centres and fingertips, the same names in every hand version
        bodies[site.body].add_site(name=site.name, pos=site.pos, size=[0.005, 0, 0])
    for side in ("right", "left"):
        # Eye camera: MuJoCo cameras look along their local -z with +y up; the eye looks
        # along its local +x with +z up.
        # It sits on the line of sight just in front of the pupil (the eye sphere's centre + its
        # radius x EYE_CAMERA_X), so the own eyeball, iris and pupil are behind it.
        g = next(g for g in tables.geoms if g.body == f"{side}_eye")
        bodies[f"{side}_eye"].add_camera(
            name=f"{side}_eye", pos=np.asarray(g.pos, float) + [EYE_CAMERA_X * g.size[0], 0, 0],
            fovy=EYE_FOVY_DEG,
            quat=quat_mul(axis_angle_quat((0, 0, 1), -np.pi / 2),
                          axis_angle_quat((1, 0, 0), np.pi / 2)),
        )
    spec.add_sensor(name="vestibular_gyro", type=mujoco.mjtSensor.mjSENS_GYRO,
                    objtype=mujoco.mjtObj.mjOBJ_SITE, objname="head_centre")
    spec.add_sensor(name="vestibular_accel", type=mujoco.mjtSensor.mjSENS_ACCELEROMETER,
                    objtype=mujoco.mjtObj.mjOBJ_SITE, objname="head_centre")
