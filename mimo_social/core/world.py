"""Compose N infants and a scene into one MuJoCo model, with integer index tables per agent.

Each infant is built by :func:`mimo_social.body.builder.build_infant` with unprefixed names and
attached with ``MjSpec.attach`` under its agent's name as prefix (``infant_<i>/``, an adult
``caregiver_<i>/``: :mod:`mimo_social.util.names`). After compiling, every name an
agent needs is resolved to integer ids and address arrays (:class:`AgentIndex`); no string
lookups or MuJoCo accessor views are kept, so a world pickles: its MjData travels whole, with its
model (every model field a task wrote, every quantity of the last step), and the index tables
are rebuilt from the recipe; a copy continues exactly as the original.

Agents may differ in body: hands, actuation, senses, and size and strength (``scale``,
``strength`` of :class:`~mimo_social.core.config.AgentConfig`). Each infant is built from its
own scaled tables (:attr:`World.tables`) and lowered onto the floor from its own geometry.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import mujoco
import numpy as np

from ..body.builder import axis_angle_quat, build_infant, quat_mul
from ..body.postures import posture_joints, posture_pitch
from ..expressions.switch import FaceTextures
from ..scenery import SCENES, add_playroom, clear_toys
from ..senses import SENSES
from ..util.checks import check_choice
from ..util.names import agent_names
from .config import AgentConfig, PhysicsConfig
from .delays import check_delay_steps, delay_sensors, fill_sensor_history
from .regrow import agent_maps, regrow_agent, regrow_props
from .scene_parts import Prop, add_floor, add_lights, add_prop

__all__ = ["AgentSetup", "Prop", "AgentIndex", "World", "CLOTHES_PALETTE"]

CLOTHES_PALETTE = (
    (0.35, 0.55, 0.85, 1.0), (0.90, 0.45, 0.40, 1.0), (0.45, 0.75, 0.45, 1.0),
    (0.85, 0.70, 0.30, 1.0), (0.65, 0.45, 0.80, 1.0), (0.30, 0.75, 0.75, 1.0),
    (0.85, 0.50, 0.70, 1.0), (0.55, 0.55, 0.55, 1.0),
)


@dataclass(frozen=True)
class AgentSetup:
    """How the task wants one agent built and placed."""

    config: AgentConfig
    position: tuple[float, float] = (0.0, 0.0)
    facing: tuple[float, float] = (1.0, 0.0)
    frozen: dict = field(default_factory=dict)       # joint -> angle (rad), held still
    base: str = "free"                               # "free" or "fixed"
    actuated: tuple[str, ...] | None = None          # motor joints in the action; None: all
    gaze_joints: tuple[str, ...] = ()                # joints the task points at a target


@dataclass
class AgentIndex:
    """Integer index tables of one agent in the compiled world."""

    name: str
    joint_names: list[str]          # unprefixed hinge joints, model order
    qpos_adr: np.ndarray
    dof_adr: np.ndarray
    joint_range: np.ndarray         # (n, 2) rad
    actuated_names: list[str]       # joints of the motors in the action, action order
    actuator_ids: np.ndarray
    actuated_joint_idx: np.ndarray  # index into joint_names of each actuated joint
    gaze_idx: np.ndarray            # index into joint_names of joints the task sets
    body_ids: np.ndarray
    geom_ids: np.ndarray
    root_body: int
    free_qpos: int                  # -1 for a fixed base
    free_dof: int
    head_geom: int
    head_material: int
    head_site: int
    palm_sites: np.ndarray          # right, left
    fingertip_sites: np.ndarray     # right, left
    eye_cameras: np.ndarray         # right, left
    gyro_adr: int
    accel_adr: int
    initial_qpos: np.ndarray = None  # this agent's part of qpos at reset (full-length mask below)


def _support_below(model, data, geom_ids: np.ndarray) -> np.ndarray:
    """Lowest world z of each geom (exact for the primitive shapes the body uses)."""
    z = data.geom_xpos[geom_ids, 2]
    R = data.geom_xmat[geom_ids].reshape(-1, 3, 3)
    size = model.geom_size[geom_ids]
    t = model.geom_type[geom_ids]
    rz = R[:, 2, :]  # the world-z row: components of world z in the geom's frame
    low = np.empty(len(geom_ids))
    G = mujoco.mjtGeom
    sph = t == G.mjGEOM_SPHERE
    low[sph] = z[sph] - size[sph, 0]
    cap = t == G.mjGEOM_CAPSULE
    low[cap] = z[cap] - np.abs(rz[cap, 2]) * size[cap, 1] - size[cap, 0]
    cyl = t == G.mjGEOM_CYLINDER
    low[cyl] = (z[cyl] - np.abs(rz[cyl, 2]) * size[cyl, 1]
                - size[cyl, 0] * np.sqrt(np.clip(1 - rz[cyl, 2] ** 2, 0, 1)))
    box = t == G.mjGEOM_BOX
    low[box] = z[box] - np.sum(np.abs(rz[box]) * size[box], axis=1)
    ell = t == G.mjGEOM_ELLIPSOID
    low[ell] = z[ell] - np.sqrt(np.sum((rz[ell] * size[ell]) ** 2, axis=1))
    return low


def _yaw_quat(position, facing) -> np.ndarray:
    d = np.asarray(facing, float) - np.asarray(position, float)
    yaw = float(np.arctan2(d[1], d[0])) if np.linalg.norm(d) > 1e-9 else 0.0
    return axis_angle_quat((0, 0, 1), yaw)


class World:
    """N infants, a floor, lights and props, compiled into one model.

    ``scene``: ``"floor"`` (the bare checkered floor) or ``"playroom"`` (the play room of
    :mod:`mimo_social.scenery`, centred on the agents' places; its toys, free bodies
    ``playroom/<toy>``, are in :attr:`room`; with ``floor=False`` no scene at all)."""

    #: the play room's toys may sleep while they rest (MuJoCo's ``mjENBL_SLEEP``, in the room
    #: only; agents and a task's props never sleep). Off: it saves ~17 % of the room's physics
    #: but changes the agents' own trajectories too (the reach controller then misses with seed
    #: 0); without it agents move exactly as on the floor until they touch the room
    #: (docs/playroom.md)
    ROOM_SLEEP = False
    #: MjData counters of the awake part that MuJoCo 4.0.0's pickling of MjData leaves out (a
    #: copy with sleeping trees then fails in ``mj_sleep``): they travel with the world
    _SLEEP_COUNTERS = ("nbody_awake", "ntree_awake", "nv_awake")

    def __init__(self, agents: Sequence[AgentSetup], props: Sequence[Prop] = (),
                 physics: PhysicsConfig = PhysicsConfig(), floor: bool = True,
                 scene: str = "floor"):
        if not 1 <= len(agents) <= 8:
            raise ValueError(f"a world holds 1 to 8 infants, got {len(agents)}")
        self.scene = check_choice("env", "scene", scene, SCENES)
        self._recipe = (tuple(agents), tuple(props), physics, floor, scene)
        self.agent_setups = tuple(agents)
        self.props = tuple(props)
        self.physics = physics
        # infants infant_<i>, adults caregiver_<i>, each kind counted in world order
        self.names = agent_names([s.config.body for s in agents])
        self._build()

    # -- pickling: the recipe rebuilds the index tables; MjData (with its model) travels whole --
    def __getstate__(self):
        # MjData pickles with its model: every model field a task changed (a ball's size and
        # mass, weld and contact settings) and every quantity of the last step (qfrc_bias,
        # contacts, the solver's warm start) travel, so a copy continues exactly.
        state = {"recipe": self._recipe, "data": self.data, "bad_count": self._bad_count,
                 "regrown": dict(self.regrown), "props": self.regrown_props}
        if self.model.opt.enableflags & mujoco.mjtEnableBit.mjENBL_SLEEP:
            state["awake"] = {k: getattr(self.data, k) for k in self._SLEEP_COUNTERS}
        return state

    def __setstate__(self, state):
        self.__init__(*state["recipe"])   # the index tables, faces and spec of the recipe
        for i, setup in state.get("regrown", {}).items():   # ages changed since (regrow)
            self.regrow(i, setup)
        if state.get("props") is not None:
            self.regrow_props(state["props"])
        self.data = state["data"]
        for k, v in state.get("awake", {}).items():
            setattr(self.data, k, v)
        self.model = self.data.model
        self._bad_count = state["bad_count"]

    # -- building ------------------------------------------------------------------------------
    def _build(self):
        agents, props, physics, floor, scene = self._recipe
        spec = mujoco.MjSpec()
        spec.modelname = "mimo_social"
        spec.compiler.degree = False
        self.set_physics_options(spec, physics)
        self.faces = FaceTextures()
        self.faces.add_to(spec)
        self.room = None
        if floor and scene == "playroom":
            xy = np.array([s.position for s in agents], float)
            centre = (xy.min(axis=0) + xy.max(axis=0)) / 2
            self.room = add_playroom(spec, centre, sleep=self.ROOM_SLEEP)
            # the near plane of the cameras as on the floor (2 cm: a tenth of znear x extent)
            spec.stat.extent = 2.0
            if self.ROOM_SLEEP:
                spec.option.enableflags |= mujoco.mjtEnableBit.mjENBL_SLEEP
        else:
            if floor:
                add_floor(spec)
            add_lights(spec)
        builds = []
        for i, setup in enumerate(agents):
            cfg = setup.config
            rgba = cfg.clothes_rgba or CLOTHES_PALETTE[i % len(CLOTHES_PALETTE)]
            build = build_infant(cfg.hands, setup.frozen, setup.base, rgba,
                                 scale=cfg.scale, strength=cfg.strength,
                                 age_months=cfg.age_months, body=cfg.body,
                                 motor_age_months=cfg.motor_age_months)
            unknown = sorted(set(setup.actuated or ()) - set(build.actuated))
            if unknown:
                raise ValueError(f"{self.names[i]}: cannot actuate {unknown}: not motor joints "
                                 f"of this body (frozen or unknown)")
            pose_q, root_quat, height = self._rest_pose(build, cfg.posture, setup)
            frame = spec.worldbody.add_frame(
                pos=[setup.position[0], setup.position[1], height], quat=root_quat)
            prefix = f"{self.names[i]}/"
            spec.attach(build.spec, prefix=prefix, frame=frame)
            # every channel within MAX_DELAY_STEPS (the env's rings too), else a ConfigError
            k = check_delay_steps(self.names[i], cfg,
                                  physics.timestep * physics.frame_skip)["vestibular"]
            if k and cfg.vestibular:    # MuJoCo's own sensor delay (core/delays.py)
                delay_sensors(spec, prefix, k, physics.timestep, physics.frame_skip)
            mat = spec.add_material(name=f"{prefix}face")
            self.faces.bind_material(mat)
            spec.geom(f"{prefix}head").material = f"{prefix}face"
            builds.append((build, pose_q))
        for entry in SENSES.values():    # what a sense adds to the model (hearing's sensors)
            if entry.add_to_spec is not None:
                entry.add_to_spec(spec, self.names, [s.config for s in agents])
        for p in props:
            body = add_prop(spec, p)
            if self.room is not None and self.ROOM_SLEEP and not p.fixed:
                body.sleep = mujoco.mjtSleepPolicy.mjSLEEP_NEVER   # tasks move their props
        self.spec = spec
        self.regrown: dict[int, AgentSetup] = {}   # agent -> its setup after an age change
        self.regrown_props = None                   # the props after an age change
        self._regrow_maps: dict[int, object] = {}
        self._scratch = None
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        self.delayed_sensors = np.flatnonzero(self.model.sensor_delay > 0)
        self._index(builds)
        self._initial_qpos = self.model.qpos0.copy()
        for a, (build, pose_q) in zip(self.agents, builds):
            for k, name in enumerate(a.joint_names):
                self._initial_qpos[a.qpos_adr[k]] = pose_q.get(name, self._initial_qpos[a.qpos_adr[k]])
        self.toys_moved = []
        if self.room is not None:   # toys where an agent or a task's prop starts: spare places
            self.data.qpos[:] = self._initial_qpos
            mujoco.mj_kinematics(self.model, self.data)
            others = np.flatnonzero((self.geom_agent >= 0) | np.isin(
                self.model.geom_bodyid, list(self.prop_bodies.values())))
            self.toys_moved = clear_toys(self.model, self.data, self.room, others,
                                         self._initial_qpos)
        self.reset()
        self.hold_welds()

    @staticmethod
    def set_physics_options(spec, physics: PhysicsConfig):
        """Write ``physics`` (timestep, gravity, solver settings) and the offscreen buffer's
        size into a model spec's options (also for scenes built outside a World)."""
        opt = spec.option
        opt.timestep = physics.timestep
        opt.gravity = physics.gravity
        opt.iterations = physics.iterations
        opt.tolerance = physics.tolerance
        opt.solver = {"newton": mujoco.mjtSolver.mjSOL_NEWTON, "cg": mujoco.mjtSolver.mjSOL_CG,
                      "pgs": mujoco.mjtSolver.mjSOL_PGS}[physics.solver]
        opt.cone = {"pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL,
                    "elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC}[physics.cone]
        opt.jacobian = {"dense": mujoco.mjtJacobian.mjJAC_DENSE,
                        "sparse": mujoco.mjtJacobian.mjJAC_SPARSE,
                        "auto": mujoco.mjtJacobian.mjJAC_AUTO}[physics.jacobian]
        spec.visual.global_.offwidth = 640
        spec.visual.global_.offheight = 480
        spec.visual.quality.shadowsize = 0

    @staticmethod
    def _rest_pose(build, posture: str, setup: AgentSetup):
        """Joint angles of the posture, the root orientation, and the hip height on the floor."""
        spec = build.spec.copy()
        hip = spec.body("hip")
        if hip.first_joint() is None or hip.first_joint().type != mujoco.mjtJoint.mjJNT_FREE:
            hip.add_freejoint(name="root")  # only to orient this measuring copy
        model = spec.compile()
        data = mujoco.MjData(model)
        by_name = {j.name: j for j in build.tables.joints}
        wanted = posture_joints(posture, build.tables.body)
        pose = {}
        for name in build.joints:
            j = by_name[name]
            lo, hi = np.deg2rad(j.range_deg)
            pose[name] = float(np.clip(np.deg2rad(wanted.get(name, j.springref_deg)), lo, hi))
        for name in build.joints:  # coupled trunk joints follow their driver
            j = by_name[name]
            if j.coupled_to in pose:
                lo, hi = np.deg2rad(j.range_deg)
                pose[name] = float(np.clip(pose[j.coupled_to] * j.coupling, lo, hi))
        for name in build.locked:
            pose[name] = build.frozen[name]
        pitch = axis_angle_quat((0, 1, 0), np.deg2rad(posture_pitch(posture, build.tables.body)))
        root_quat = quat_mul(_yaw_quat(setup.position, setup.facing), pitch)
        data.qpos[model.joint("root").qposadr[0] + 3:][:4] = root_quat
        for name, angle in pose.items():
            data.qpos[model.joint(name).qposadr[0]] = angle
        mujoco.mj_kinematics(model, data)
        low = float(_support_below(model, data, np.arange(model.ngeom)).min())
        return pose, root_quat, -low + 0.002

    def _index(self, builds):
        m = self.model
        self.agents: list[AgentIndex] = []
        body_agent = np.full(m.nbody, -1, dtype=np.intp)
        for i, (build, _) in enumerate(builds):
            p = f"{self.names[i]}/"
            jids = np.array([m.joint(p + n).id for n in build.joints], dtype=np.intp)
            actuated = [n for n in build.actuated
                        if self.agent_setups[i].actuated is None
                        or n in self.agent_setups[i].actuated]
            act_names = {j: a for j, a in zip(build.actuated, build.actuators)}
            act_ids = np.array([m.actuator(p + act_names[n]).id for n in actuated], dtype=np.intp)
            root = m.body(p + "hip").id
            bodies = np.array([b for b in range(m.nbody)
                               if m.body(b).name.startswith(p)], dtype=np.intp)
            body_agent[bodies] = i
            geoms = np.flatnonzero(np.isin(m.geom_bodyid, bodies)).astype(np.intp)
            free = m.body_jntadr[root]
            has_free = free >= 0 and m.jnt_type[free] == mujoco.mjtJoint.mjJNT_FREE
            gaze = self.agent_setups[i].gaze_joints
            missing = sorted(set(gaze) - set(build.joints))
            if missing:
                raise ValueError(f"{self.names[i]}: gaze joints {missing} are not in the model")
            self.agents.append(AgentIndex(
                name=self.names[i],
                joint_names=list(build.joints),
                qpos_adr=m.jnt_qposadr[jids].astype(np.intp),
                dof_adr=m.jnt_dofadr[jids].astype(np.intp),
                joint_range=m.jnt_range[jids].copy(),
                actuated_names=actuated,
                actuator_ids=act_ids,
                actuated_joint_idx=np.array([build.joints.index(n) for n in actuated],
                                            dtype=np.intp),
                gaze_idx=np.array([build.joints.index(n) for n in gaze], dtype=np.intp),
                body_ids=bodies, geom_ids=geoms, root_body=root,
                free_qpos=int(m.jnt_qposadr[free]) if has_free else -1,
                free_dof=int(m.jnt_dofadr[free]) if has_free else -1,
                head_geom=m.geom(p + "head").id,
                head_material=m.material(p + "face").id,
                head_site=m.site(p + "head_centre").id,
                palm_sites=np.array([m.site(p + f"{s}_palm_centre").id for s in ("right", "left")]),
                fingertip_sites=np.array([m.site(p + f"{s}_fingertips").id
                                          for s in ("right", "left")]),
                eye_cameras=np.array([m.camera(p + f"{s}_eye").id for s in ("right", "left")]),
                gyro_adr=int(m.sensor_adr[m.sensor(p + "vestibular_gyro").id]),
                accel_adr=int(m.sensor_adr[m.sensor(p + "vestibular_accel").id]),
            ))
        self.body_agent = body_agent
        self.geom_agent = body_agent[m.geom_bodyid]
        self.prop_bodies = {p.name: m.body(p.name).id for p in self.props}
        self.prop_qpos = {p.name: int(m.jnt_qposadr[m.body_jntadr[m.body(p.name).id]])
                          for p in self.props if not p.fixed}
        self.prop_dof = {p.name: int(m.jnt_dofadr[m.body_jntadr[m.body(p.name).id]])
                         for p in self.props if not p.fixed}
        # each agent's (scaled) body tables: what its actuation and skin are built from
        self.tables = [build.tables for build, _ in builds]
        self.welds = np.array([(m.equality(f"{p.name}__{o}").id, m.body(o).id, m.body(p.name).id)
                               for p in self.props for o in p.welds], dtype=np.intp).reshape(-1, 3)

    # -- state ---------------------------------------------------------------------------------
    def place_prop(self, name: str, position, quat=(1.0, 0.0, 0.0, 0.0)) -> None:
        """Put free prop ``name`` at a world position and orientation, at rest (kinematics
        updated, so positions read right away are the new ones)."""
        if name not in self.prop_qpos:
            raise KeyError(f"no free prop {name!r}; free props: {sorted(self.prop_qpos)}")
        q, v = self.prop_qpos[name], self.prop_dof[name]
        self.data.qpos[q:q + 3] = position
        self.data.qpos[q + 3:q + 7] = quat
        self.data.qvel[v:v + 6] = 0.0
        mujoco.mj_kinematics(self.model, self.data)

    def reset(self, qpos: np.ndarray | None = None):
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[:] = self._initial_qpos if qpos is None else qpos
        for a in self.agents:
            self.faces.show(self.model, a.head_material, 0)
        mujoco.mj_forward(self.model, self.data)
        fill_sensor_history(self.model, self.data, self.delayed_sensors)
        self._bad_count = 0

    def hold_welds(self) -> None:
        """Anchor every prop weld (:attr:`Prop.welds`) at the bodies' current relative pose
        (``data`` kinematics must be up to date): ``eq_data`` holds the welded body's pose in the
        prop's frame as MuJoCo stores it (position of the anchor in the body's frame, then the
        relative orientation ``q_body^-1 q_prop``)."""
        m, d = self.model, self.data
        for eq, b1, b2 in self.welds:
            anchor = m.eq_data[eq, :3]
            R1 = d.xmat[b1].reshape(3, 3)
            m.eq_data[eq, 3:6] = R1.T @ (d.xpos[b2] + d.xmat[b2].reshape(3, 3) @ anchor - d.xpos[b1])
            q1 = d.xquat[b1] * np.array([1.0, -1.0, -1.0, -1.0])
            mujoco.mju_mulQuat(m.eq_data[eq, 6:10], q1, d.xquat[b2])

    def scratch_contacts(self) -> mujoco.MjData:
        """A scratch copy of the state at the world's current positions with its contacts found
        (``mj_kinematics`` + ``mj_collision``: ``d.ncon``, ``d.contact``); the world's own data
        is left as it is. The start checks read it (agents inside each other or in furniture)."""
        d = mujoco.MjData(self.model)
        d.qpos[:] = self.data.qpos
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_collision(self.model, d)
        return d

    @property
    def initial_qpos(self) -> np.ndarray:
        return self._initial_qpos.copy()

    #: Divergence bounds, checked after every physics step: a speed of any degree of freedom
    #: (rad/s or m/s) above ``VEL_LIMIT``, an acceleration (rad/s^2 or m/s^2) above
    #: ``ACC_LIMIT``, or a NaN/inf in either, is a simulation that went unstable. Measured
    #: maxima: every catalogue env (random, bang-bang and scripted actions) at most 91 rad/s and
    #: 1.0e4 rad/s^2; bang-bang actions (every motor at -1 or +1, redrawn each step) at every
    #: allowed strength and scale at most 275 rad/s and 6.6e4 rad/s^2 (a finger); five-finger hands
    #: 888 rad/s and 1.3e5 rad/s^2 (a fingertip; measured with the sparse Jacobian under MuJoCo
    #: 4.0.0's factorization bug; with the dense Jacobian (then the default), 214 rad/s and 4.3e4 rad/s^2 at strength
    #: 3 over 20k physics steps: docs/reliability.md). A diverging simulation grows about tenfold per
    #: physics step from there, so it passes the limits within a step or two of leaving the
    #: normal range, long before MuJoCo's own check (1e10).
    VEL_LIMIT = 2e3
    ACC_LIMIT = 1e6

    def step(self, n: int, before_substep=None) -> str | None:
        """Advance ``n`` physics steps; return a reason string if the simulation went unstable.

        The state is checked after every physics step (:attr:`VEL_LIMIT`, :attr:`ACC_LIMIT`,
        MuJoCo's warnings); at the first bad one the world stops there and is put back to its
        initial pose at rest (the clock keeps running), so no diverged value is ever read."""
        m, d = self.model, self.data
        qvel, qacc = d.qvel, d.qacc          # views: MjData arrays never move
        v2, a2 = self.VEL_LIMIT ** 2, self.ACC_LIMIT ** 2
        reason = None
        for _ in range(n):
            if before_substep is not None:
                before_substep()
            mujoco.mj_step(m, d)
            # a sum of squares within the square of a limit keeps every value within it (a
            # NaN/inf fails the comparison): well under a microsecond; only past it is each
            # value looked at
            if not (qvel.dot(qvel) <= v2 and qacc.dot(qacc) <= a2):
                reason = self._diverged()
                if reason is not None:
                    break
        if reason is None:
            reason = self._mujoco_reset()    # MuJoCo met a bad value and reset the data itself
        if reason is not None:
            self._restart()
        # mj_step leaves positions of the state before its last integration; bring body, geom,
        # site and camera poses up to date so tasks and senses read the state they are given.
        mujoco.mj_kinematics(m, d)
        mujoco.mj_camlight(m, d)
        return reason

    _BAD = np.array([mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL,
                     mujoco.mjtWarning.mjWARN_BADQACC, mujoco.mjtWarning.mjWARN_BADCTRL], int)
    assert np.array_equal(np.diff(_BAD), [1, 1, 1]), "MuJoCo's warning ids are not consecutive"

    def instability(self) -> str | None:
        """A reason string when the simulation diverged: its speeds or accelerations now pass
        :attr:`VEL_LIMIT` / :attr:`ACC_LIMIT` (or are NaN/inf), or MuJoCo met a NaN/inf or huge
        value since the last check (and reset the data). Only reads the state (:meth:`step` checks
        after every physics step and restarts a diverged world itself)."""
        return self._diverged() or self._mujoco_reset()

    def _diverged(self) -> str | None:
        m, d = self.model, self.data
        for values, limit, what in ((d.qvel, self.VEL_LIMIT, "speed"),
                                    (d.qacc, self.ACC_LIMIT, "acceleration")):
            bad = ~(np.abs(values) <= limit)                 # NaN counts as bad
            if bad.any():
                k = int(np.flatnonzero(bad)[np.argmax(np.nan_to_num(
                    np.abs(values[bad]), nan=np.inf))])
                joint = m.joint(int(m.dof_jntid[k])).name
                return (f"the simulation diverged at t = {d.time:.4f} s: the {what} of {joint} "
                        f"(dof {k}) is {values[k]:.3g}, beyond the limit {limit:g}; the world was "
                        f"put back to its initial pose")
        return None

    def _mujoco_reset(self) -> str | None:
        # the four counters are consecutive in MuJoCo's warning table: one view of them, summed
        # as a list (a tenth of a microsecond; numpy's reductions take a microsecond)
        counts = self.data.warning.number[self._BAD[0]:self._BAD[-1] + 1].tolist()
        total = sum(counts)
        if total > self._bad_count:
            self._bad_count = total
            which = [mujoco.mjtWarning(w).name for w, c in zip(self._BAD, counts) if c]
            return (f"MuJoCo found NaN, inf or huge values ({', '.join(which)}) and reset the "
                    f"simulation: it went unstable; the world was put back to its initial pose")
        return None

    def _restart(self) -> None:
        """The initial pose at rest, after a divergence (the clock keeps its time)."""
        m, d = self.model, self.data
        t = d.time
        mujoco.mj_resetData(m, d)            # clears MuJoCo's warning counters too
        d.qpos[:] = self._initial_qpos
        d.time = t
        mujoco.mj_forward(m, d)
        fill_sensor_history(m, d, self.delayed_sensors)
        self._bad_count = 0

    # -- another age without compiling (core/regrow.py) -----------------------------------------
    def regrow(self, i: int, setup: AgentSetup) -> None:
        """Agent ``i`` as ``setup`` says: its body at the ages of ``setup.config`` and its place
        and held angles, written into the compiled model in place
        (:func:`~mimo_social.core.regrow.regrow_agent`: a ConfigError when the setup needs
        another model); its tables, setup and start pose follow from the next :meth:`reset`."""
        self.tables[i] = regrow_agent(self, i, setup,
                                      self.physics.timestep * self.physics.frame_skip)
        self.agent_setups = self.agent_setups[:i] + (setup,) + self.agent_setups[i + 1:]
        self.regrown[i] = setup

    def regrow_props(self, props) -> None:
        """The props of another size, place, mass or colour (a task sizing them by the agents),
        written into the compiled model in place (:func:`~mimo_social.core.regrow.regrow_props`)."""
        regrow_props(self, props)
        self.props = self.regrown_props = tuple(props)

    def regrow_maps(self, i: int):
        """Agent ``i``'s table rows as model ids (:func:`~mimo_social.core.regrow.agent_maps`),
        resolved once."""
        if i not in self._regrow_maps:
            self._regrow_maps[i] = agent_maps(self, i)
        return self._regrow_maps[i]

    def scratch_data(self) -> mujoco.MjData:
        """A scratch MjData of this model (kept; its contents are any)."""
        if self._scratch is None or self._scratch.model is not self.model:
            self._scratch = mujoco.MjData(self.model)
        return self._scratch

    def set_initial_qpos(self, address: int, value: float) -> None:
        """One value of the start pose (``qpos`` address)."""
        self._initial_qpos[address] = value

    def set_initial_root(self, i: int, position, quat) -> None:
        """The start position (m) and orientation of agent ``i``'s free root."""
        a = self.agents[i]
        self._initial_qpos[a.free_qpos:a.free_qpos + 3] = position
        self._initial_qpos[a.free_qpos + 3:a.free_qpos + 7] = quat

    def set_expression(self, agent: int, expression: int) -> None:
        self.faces.show(self.model, self.agents[agent].head_material, expression)

    def expression_of(self, agent: int) -> int:
        return self.faces.shown(self.model, self.agents[agent].head_material)
