"""An infant of another age in the compiled world, without compiling: the new values written in
place into the live ``MjModel`` (the same model and data objects; renderers and index tables
kept). The env's side (which agents change, their motors, senses and skins): core/ages.py.

:func:`regrow_agent` takes agent ``i``'s new :class:`~mimo_social.core.world.AgentSetup` (its
config of other ``age_months`` and / or ``motor_age_months``, and the place and held angles the
task gives it at those ages; hands, body kind, actuation, size, posture, senses, held joints
and motors unchanged: :func:`check_same_model`) and writes, for that agent only:

- from the tables of the new body age (:func:`~mimo_social.body.tables.load_body`): segment
  positions (``body_pos``), geom sizes, positions and contact lengths (torsional and rolling
  friction), the iris and pupil of each eye, site and eye-camera positions, joint pivots, joint
  stiffness, damping, armature and friction loss;
- the held angles: segments a held joint was folded into turned (``body_quat``), joints held
  by an equality at their angle (``eq_data``, the start pose);
- the mass properties from the new geoms (:mod:`mimo_social.body.inertia`, MuJoCo's formulas):
  ``body_mass``, ``body_ipos``, ``body_iquat``, ``body_inertia``;
- the bounds: ``geom_rbound``, ``geom_aabb`` and the bodies' bounding-volume trees
  (``bvh_aabb``, in each body's inertial frame, rebuilt bottom-up from the leaves);
- the motors' torque limits (``actuator_ctrlrange``, ``actuator_forcerange``) from the tables of
  the motor age (the muscle and positional models adapt their motors when next reset);
- the start pose: the root at its place, turned to face its partner, lowered onto the floor
  from its new geometry as a fresh build is (its rest pose's lowest point 2 mm above it);
- then ``mujoco.mj_setConst`` for the derived constants (subtree masses, inverse weights,
  ``actuator_acc0``) and the model statistics (:func:`set_constants`).

:func:`regrow_props` does the same for props a task sizes by its agents. A fresh build at the
new ages gives the same values to rounding (tests/core/test_age_change.py).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import mujoco
import numpy as np

from ..body.builder import (EYE_CAMERA_X, GEOM_FRICTION, IRIS, PUPIL, axis_angle_quat,
                            mouth_position, quat_mul)
from ..body.inertia import (BOX, CAPSULE, CYLINDER, ELLIPSOID, SPHERE, body_inertials,
                            boxes_in_parent, geom_aabb, geom_moments, geom_rbound,
                            quat_matrices)
from ..body.postures import posture_pitch
from ..body.tables import BodyTables, load_body
from .config import ConfigError
from .delays import VESTIBULAR_SENSORS, check_delay_steps, delay_steps

__all__ = ["AgentMaps", "agent_maps", "regrow_agent", "body_tables", "support_below",
           "REST_CLEARANCE", "KEPT", "root_quat", "regrow_props", "set_constants",
           "check_same_model"]

#: a body starts with its lowest point this high above the floor (m), as the world places it
REST_CLEARANCE = 0.002


def body_tables(config) -> BodyTables:
    """The (scaled, grown) tables of an agent config: what its body is built from."""
    return load_body(config.hands, config.scale, config.strength, config.age_months,
                     config.body, config.motor_age_months)


@dataclass
class AgentMaps:
    """Model ids of one agent's table rows (resolved once per world, by name)."""

    segment_body: np.ndarray      # (S,) body id of each table segment
    root: int                     # the root segment's body
    geom: np.ndarray              # (G,) geom id of each table geom
    eyes: list                    # (table geom index, iris id, pupil id) per eye
    joint: np.ndarray             # (J,) joint id of each table joint, -1: folded away
    site: np.ndarray              # (T,) site id of each table site
    head_site: int
    mouth_site: int               # -1: none (a model pickled before it had one)
    head_geom_row: int            # the table row of the head geom
    cameras: list                 # (table geom index of the eye, camera id)
    actuator: np.ndarray          # (J,) actuator id of each table joint, -1: none
    geoms: np.ndarray             # every geom of the agent (iris and pupil too)
    bodies: np.ndarray            # every body of the agent
    bvh: np.ndarray               # the agent's bvh nodes
    bvh_base: np.ndarray          # the first node of each of those nodes' body


_OBJECTS = {"geom": mujoco.mjtObj.mjOBJ_GEOM, "camera": mujoco.mjtObj.mjOBJ_CAMERA,
            "actuator": mujoco.mjtObj.mjOBJ_ACTUATOR, "body": mujoco.mjtObj.mjOBJ_BODY,
            "joint": mujoco.mjtObj.mjOBJ_JOINT, "site": mujoco.mjtObj.mjOBJ_SITE}


def _id(model, kind: str, name: str) -> int:
    """The id of the ``kind`` named ``name``, -1 when there is none."""
    return int(mujoco.mj_name2id(model, _OBJECTS[kind], name))


def agent_maps(world, i: int) -> AgentMaps:
    """The id maps of agent ``i`` of ``world`` (its tables' names resolved in its model)."""
    m, t = world.model, world.tables[i]
    p = f"{world.names[i]}/"
    geoms = np.array([_id(m, "geom", p + g.name) for g in t.geoms], np.intp)
    eyes, cams = [], []
    for k, g in enumerate(t.geoms):
        if g.body.endswith("_eye"):
            eyes.append((k, _id(m, "geom", f"{p}{g.name}_iris"),
                         _id(m, "geom", f"{p}{g.name}_pupil")))
            cams.append((k, _id(m, "camera", p + g.body)))
    acts = np.array([_id(m, "actuator", p + j.actuator) if j.actuator else -1
                     for j in t.joints], np.intp)
    a = world.agents[i]
    bodies = np.asarray(a.body_ids, np.intp)
    has = m.body_bvhnum > 0
    base = np.repeat(m.body_bvhadr[has], m.body_bvhnum[has])
    nodes = np.concatenate([np.arange(m.body_bvhadr[b], m.body_bvhadr[b] + m.body_bvhnum[b])
                            for b in bodies]).astype(np.intp)
    return AgentMaps(
        segment_body=np.array([_id(m, "body", p + s.name) for s in t.segments], np.intp),
        root=int(a.root_body), geom=geoms, eyes=eyes,
        joint=np.array([_id(m, "joint", p + j.name) for j in t.joints], np.intp),
        site=np.array([_id(m, "site", p + s.name) for s in t.sites], np.intp),
        head_site=int(a.head_site), mouth_site=_id(m, "site", p + "mouth"),
        head_geom_row=next(k for k, g in enumerate(t.geoms) if g.name == "head"),
        cameras=cams, actuator=acts, geoms=np.asarray(a.geom_ids, np.intp), bodies=bodies,
        bvh=nodes, bvh_base=base[nodes])


def support_below(model, data, geom_ids) -> float:
    """The lowest world z of the geoms ``geom_ids`` (exact for the primitive shapes)."""
    z = data.geom_xpos[geom_ids, 2]
    rz = data.geom_xmat[geom_ids].reshape(-1, 3, 3)[:, 2, :]
    size = model.geom_size[geom_ids]
    t = model.geom_type[geom_ids]
    low = np.where(t == SPHERE, size[:, 0], 0.0)
    low = np.where(t == CAPSULE, np.abs(rz[:, 2]) * size[:, 1] + size[:, 0], low)
    low = np.where(t == CYLINDER, np.abs(rz[:, 2]) * size[:, 1]
                   + size[:, 0] * np.sqrt(np.clip(1 - rz[:, 2] ** 2, 0, 1)), low)
    low = np.where(t == BOX, np.sum(np.abs(rz) * size, axis=1), low)
    low = np.where(t == ELLIPSOID, np.sqrt(np.sum((rz * size) ** 2, axis=1)), low)
    return float(np.min(z - low))


def _pad3(v) -> np.ndarray:
    out = np.zeros(3)
    out[:len(v)] = v
    return out


def _write_body(m, maps: AgentMaps, t: BodyTables) -> None:
    """Positions, sizes, frictions, passive joint parameters and motor limits from ``t``."""
    for k, s in enumerate(t.segments):
        if s.parent is not None:
            m.body_pos[maps.segment_body[k]] = s.pos
    for k, g in enumerate(t.geoms):
        gid = maps.geom[k]
        m.geom_size[gid] = _pad3(g.size)
        m.geom_pos[gid] = g.pos
        m.geom_friction[gid] = g.friction or GEOM_FRICTION
    for k, iris, pupil in maps.eyes:
        g = t.geoms[k]
        r, centre = float(g.size[0]), np.asarray(g.pos, float)
        cx, across, depth = IRIS
        m.geom_size[iris] = (across * r, across * r, depth * r)
        m.geom_pos[iris] = centre + (cx * r, 0.0, 0.0)
        cx, radius, half = PUPIL
        m.geom_size[pupil] = (radius * r, half * r, 0.0)
        m.geom_pos[pupil] = centre + (cx * r, 0.0, 0.0)
        m.geom_friction[iris] = m.geom_friction[pupil] = g.friction or GEOM_FRICTION
    for k, c in maps.cameras:
        g = t.geoms[k]
        m.cam_pos[c] = np.asarray(g.pos, float) + (EYE_CAMERA_X * g.size[0], 0.0, 0.0)
    m.site_pos[maps.head_site] = t.geoms[maps.head_geom_row].pos
    if maps.mouth_site >= 0:
        m.site_pos[maps.mouth_site] = mouth_position(t.geoms[maps.head_geom_row])
    for k, s in enumerate(t.sites):
        m.site_pos[maps.site[k]] = s.pos
    for k, j in enumerate(t.joints):
        jid = maps.joint[k]
        if jid < 0:
            continue
        dof = m.jnt_dofadr[jid]
        m.jnt_pos[jid] = j.pos
        m.jnt_stiffness[jid] = j.stiffness
        m.dof_damping[dof] = j.damping
        m.dof_armature[dof] = j.armature
        m.dof_frictionloss[dof] = j.frictionloss
        a = maps.actuator[k]
        if a >= 0:
            m.actuator_ctrlrange[a] = m.actuator_forcerange[a] = (-j.torque_neg, j.torque_pos)


def _write_inertia(m, maps: AgentMaps, t: BodyTables) -> None:
    """Mass properties of the agent's bodies, bounds of its geoms and its bodies' trees."""
    gids = maps.geoms
    mass = np.zeros(m.ngeom)
    mass[maps.geom] = [g.mass for g in t.geoms]
    kind, size = m.geom_type[gids], m.geom_size[gids]
    moments = geom_moments(kind, size, mass[gids])
    local = np.searchsorted(maps.bodies, m.geom_bodyid[gids])
    total, com, iquat, inertia, _ = body_inertials(local, len(maps.bodies), mass[gids],
                                                   m.geom_pos[gids], m.geom_quat[gids], moments)
    # a body of one massive geom: its principal frame is the geom's (as MuJoCo's compiler has)
    heavy = mass[gids] > 0
    one = np.bincount(local[heavy], minlength=len(maps.bodies)) == 1
    for g in np.flatnonzero(heavy & one[local]):
        b = local[g]
        iquat[b], inertia[b] = m.geom_quat[gids[g]], moments[g]
    b = maps.bodies
    m.body_mass[b], m.body_ipos[b], m.body_iquat[b], m.body_inertia[b] = total, com, iquat, inertia
    m.geom_rbound[gids] = geom_rbound(kind, size)
    m.geom_aabb[gids] = geom_aabb(kind, size)
    # bounding-volume trees: leaves are geoms' boxes in their body's inertial frame
    nodes = maps.bvh
    leaf = m.bvh_nodeid[nodes] >= 0
    g = m.bvh_nodeid[nodes[leaf]]
    body = m.geom_bodyid[g]
    R = quat_matrices(m.body_iquat[body])
    pos = np.einsum("nji,nj->ni", R, m.geom_pos[g] - m.body_ipos[body])
    quat = np.empty((len(g), 4))
    conj = m.body_iquat[body] * (1.0, -1.0, -1.0, -1.0)
    for k in range(len(g)):
        mujoco.mju_mulQuat(quat[k], conj[k], m.geom_quat[g[k]])
    m.bvh_aabb[nodes[leaf]] = boxes_in_parent(m.geom_aabb[g], pos, quat)
    for n, base in zip(nodes[~leaf][::-1], maps.bvh_base[~leaf][::-1]):   # children first
        c = m.bvh_child[n] + base
        box = m.bvh_aabb[c]
        lo, hi = (box[:, :3] - box[:, 3:]).min(0), (box[:, :3] + box[:, 3:]).max(0)
        m.bvh_aabb[n, :3], m.bvh_aabb[n, 3:] = (lo + hi) / 2, (hi - lo) / 2


def _write_frozen(world, i: int, maps: AgentMaps, t: BodyTables, held) -> None:
    """Held joints at their (new) angles ``held`` (joint -> rad, the same joints as built): a
    joint folded into its segment's orientation turns the segment (``body_quat``), one held by
    an equality gets the angle in ``eq_data`` and in the start pose."""
    m = world.model
    held = dict(held)
    for j in t.joints:   # a held driver holds its coupled follower (as the builder does)
        if j.coupled_to in held and j.name not in held:
            held[j.name] = held[j.coupled_to] * j.coupling
    row = {j.name: k for k, j in enumerate(t.joints)}
    for k, seg in enumerate(t.segments):
        if seg.parent is None:
            continue
        quat = np.array(seg.quat, float)
        for j in t.joints:
            if j.body != seg.name:
                continue
            if j.name not in held or maps.joint[row[j.name]] >= 0:
                break
            quat = quat_mul(quat, axis_angle_quat(j.axis, held[j.name]))
        m.body_quat[maps.segment_body[k]] = quat / np.linalg.norm(quat)   # as compiled
    a = world.agents[i]
    for name, angle in held.items():
        jid = maps.joint[row[name]]
        if jid < 0:
            continue
        eq = np.flatnonzero((m.eq_type == mujoco.mjtEq.mjEQ_JOINT) & (m.eq_obj1id == jid)
                            & (m.eq_obj2id == -1))
        m.eq_data[eq, 0] = angle
        world.set_initial_qpos(a.qpos_adr[a.joint_names.index(name)], angle)


def _place(world, i: int, maps: AgentMaps, setup, quat, scratch) -> None:
    """The agent's start pose: its root at ``setup.position`` turned by ``quat``, lowered onto
    the floor from its (new) geometry in its rest pose."""
    m = world.model
    a = world.agents[i]
    root = maps.root
    free = a.free_qpos
    q = world.initial_qpos
    if free >= 0:
        q[free:free + 2] = setup.position
        q[free + 3:free + 7] = quat
    else:
        m.body_pos[root, :2] = setup.position
        m.body_quat[root] = quat
    scratch.qpos[:] = q
    mujoco.mj_kinematics(m, scratch)
    low = support_below(m, scratch, maps.geoms)
    if free >= 0:
        q[free + 2] += REST_CLEARANCE - low
        world.set_initial_root(i, q[free:free + 3], quat)
        for target in (m.qpos0, m.qpos_spring):
            target[free:free + 7] = q[free:free + 7]
        m.body_pos[root], m.body_quat[root] = q[free:free + 3], quat
    else:
        m.body_pos[root, 2] += REST_CLEARANCE - low


#: what an age change keeps of an agent's config (the model's topology and the body's kind)
KEPT = ("hands", "body", "actuation", "scale", "strength", "expressions", "posture",
        "proprioception", "vestibular", "touch", "vision")


def root_quat(setup) -> np.ndarray:
    """The root's orientation of ``setup``: facing its ``facing`` point, pitched as its
    posture wants (as the world builds it)."""
    d = np.asarray(setup.facing, float) - np.asarray(setup.position, float)
    yaw = float(np.arctan2(d[1], d[0])) if np.linalg.norm(d) > 1e-9 else 0.0
    pitch = posture_pitch(setup.config.posture, setup.config.body)
    return quat_mul(axis_angle_quat((0, 0, 1), yaw),
                    axis_angle_quat((0, 1, 0), np.deg2rad(pitch)))


def check_same_model(world, i: int, setup, dt: float) -> None:
    """A ConfigError unless agent ``i`` of ``world`` can take ``setup`` in place: the same held
    joints, motors, base and :data:`KEPT` settings (other ages, place and held angles), its
    delays within the limits."""
    old = world.agent_setups[i]
    same = replace(setup, config=old.config, position=old.position, facing=old.facing,
                   frozen=old.frozen if set(setup.frozen) == set(old.frozen) else None)
    if same != old or any(getattr(setup.config, k) != getattr(old.config, k) for k in KEPT):
        raise ConfigError(f"agent {world.names[i]}: this change needs another model (held "
                          f"joints, motors, base or one of {list(KEPT)}); an age change at reset "
                          "changes only the ages, the place and held angles")
    check_delay_steps(world.names[i], setup.config, dt)


def regrow_agent(world, i: int, setup, dt: float) -> BodyTables:
    """Write agent ``i``'s body at the ages of ``setup.config``, placed as ``setup`` says (its
    position, facing and held joint angles), into ``world``'s compiled model (module
    docstring); returns the new tables. A ConfigError when the change needs another model (other
    held joints, motors, base, senses or body) or a vestibular delay beyond what the model's
    sensor history holds."""
    check_same_model(world, i, setup, dt)
    config = setup.config
    quat = root_quat(setup)
    m = world.model
    maps = world.regrow_maps(i)
    t = body_tables(config)
    if config.vestibular:
        k = delay_steps(config, dt)["vestibular"]
        _vestibular_delay(world, i, k, dt, VESTIBULAR_SENSORS)
    size_before = _mean_box(m)
    _write_body(m, maps, t)
    _write_frozen(world, i, maps, t, setup.frozen)
    _write_inertia(m, maps, t)
    scratch = world.scratch_data()
    _place(world, i, maps, setup, quat, scratch)
    set_constants(world, scratch)
    _write_statistics(m, size_before)
    return t


def regrow_props(world, props) -> None:
    """The task's props as ``props`` says (the same props, each of another size, place, mass or
    colour: a task may size its props by the agents' sizes), written into ``world``'s compiled
    model in place; a ConfigError for any other change."""
    m = world.model
    size_before = _mean_box(m)
    resized = []
    for old, new in zip(world.props, props):
        if new == old:
            continue
        if replace(new, size=old.size, pos=old.pos, mass=old.mass, rgba=old.rgba) != old:
            raise ConfigError(f"prop {new.name}: this change needs another model (its shape, "
                              "welds or whether it is fixed); an age change at reset changes "
                              "only a prop's size, place, mass and colour")
        b = world.prop_bodies[new.name]
        resized.append(b)
        g = int(m.body_geomadr[b])
        size = _pad3(new.size)
        kind = m.geom_type[g:g + 1]
        m.geom_size[g], m.geom_rgba[g] = size, new.rgba
        m.geom_rbound[g] = geom_rbound(kind, size[None])[0]
        m.geom_aabb[g] = geom_aabb(kind, size[None])[0]
        # one geom at the body's origin: its frame is the principal frame
        m.body_mass[b], m.body_inertia[b] = new.mass, geom_moments(kind, size[None], [new.mass])[0]
        m.body_ipos[b], m.body_iquat[b] = m.geom_pos[g], m.geom_quat[g]
        m.bvh_aabb[m.body_bvhadr[b]] = m.geom_aabb[g]
        m.body_pos[b] = new.pos
        if not new.fixed:
            q = world.prop_qpos[new.name]
            m.qpos0[q:q + 3] = m.qpos_spring[q:q + 3] = new.pos
            for k in range(3):
                world.set_initial_qpos(q + k, new.pos[k])
    set_constants(world, world.scratch_data(), resized)
    _write_statistics(m, size_before)


#: the per-body and per-dof constants of ``mj_setConst`` kept for bodies no age change wrote
_KEPT_BODY = ("body_invweight0",)
_KEPT_DOF = ("dof_invweight0", "dof_M0", "dof_length")


def set_constants(world, scratch, also=()) -> None:
    """``mujoco.mj_setConst`` for the bodies written (every agent's, and the bodies ``also``:
    props just resized); the other bodies and their dofs keep their constants as they were: a
    task that changes a prop at reset (a ball's size and mass) leaves them as a fresh build
    has them."""
    m = world.model
    written = world.body_agent >= 0
    written[np.asarray(also, np.intp)] = True
    other = np.flatnonzero(~written)
    dofs = np.flatnonzero(~written[m.dof_bodyid])
    kept = [(k, other, getattr(m, k)[other].copy()) for k in _KEPT_BODY] + [
        (k, dofs, getattr(m, k)[dofs].copy()) for k in _KEPT_DOF]
    mujoco.mj_setConst(m, scratch)
    for k, rows, values in kept:
        getattr(m, k)[rows] = values


def _mean_box(m) -> float:
    """The mean edge of the bodies' equivalent inertia boxes (a measure of their size)."""
    mass, inertia = m.body_mass[1:], m.body_inertia[1:]
    heavy = mass > mujoco.mjMINVAL
    I, mass = inertia[heavy], mass[heavy, None]
    sq = 6.0 * (I.sum(axis=1, keepdims=True) - 2.0 * I) / mass
    return float(np.sqrt(np.maximum(sq, 0.0)).mean()) if len(I) else 0.0


def _write_statistics(m, size_before: float) -> None:
    """The model statistics that depend on the bodies: ``meaninertia`` (the mean diagonal of
    the joint-space inertia at ``qpos0``, which scales the solver's tolerance), ``meanmass``
    (as the compiler computes them) and ``meansize`` (for drawing only: scaled with the mean
    inertia-box edge of the bodies, within a few percent of a fresh build's)."""
    if m.nv:
        m.stat.meaninertia = float(m.dof_M0.mean())
    if m.nbody > 1:
        m.stat.meanmass = float(m.body_mass[1:].mean())
    after = _mean_box(m)
    if size_before > 0 and after > 0:
        m.stat.meansize = m.stat.meansize * after / size_before


def _vestibular_delay(world, i: int, k: int, dt: float, sensors) -> None:
    m = world.model
    ts = m.opt.timestep
    for name in sensors:
        s = m.sensor(f"{world.names[i]}/{name}").id
        held = int(m.sensor_history[s, 0])
        need = k * int(round(dt / ts)) + 2 if k else 0
        if need > held:
            raise ConfigError(
                f"agent {world.names[i]}: a vestibular delay of {k} control steps needs a "
                f"history of {need} samples; the compiled model holds {held}; allowed: a "
                f"vestibular delay of at most {max(0, (held - 2) * ts / dt):g} steps without a "
                "rebuild (build the env with the longer delay)")
        m.sensor_delay[s] = k * dt - 0.5 * ts if k else 0.0
