"""Record simulations to Rerun ``.rrd`` files (written to disk only: no viewer, no network).

A :class:`Recorder` attaches to a :class:`~mimo_social.envs.parallel.MimoParallelEnv` (or a
Gymnasium :class:`~mimo_social.envs.single.SingleAgentEnv`, through its ``.parallel``)::

    env = free_play_v0.parallel_env(n_agents=2)
    with Recorder(env, "recordings/run.rrd") as rec:
        obs, infos = env.reset(seed=0)
        rec.log_reset()
        while env.agents:
            actions = policy(obs)
            obs, rewards, term, trunc, infos = env.step(actions)
            rec.log_step(actions, rewards)

Open the file with ``rerun recordings/run.rrd``. Layout of a recording::

    /world                          view coordinates (right-handed, z up)
    /world/scene/<geom>             static geoms of the world body (the floor)
    /world/<agent>/<body>           Transform3D of the body in the world, every logged step
    /world/<agent>/<body>/<geom>    static shape of each visible geom, in its body's frame
    /world/props/<body>[/<geom>]    the same for every other body (props)
    /agents/<agent>/reward          Scalars: reward, summed over the steps since the last row
    /agents/<agent>/action_norm     Scalars: L2 norm of the motor action, clipped to [-1, 1]
    /agents/<agent>/expression      TextLog at reset and whenever the expression changes
    /agents/<agent>/face            Image of the face at reset and whenever it changes

Heads are textured spheres (Mesh3D) that show the current face; geoms in group 3 (the hidden eye
spheres) are left out. Two timelines: ``sim_time`` (simulated seconds: ``data.time`` in the first
episode, continued without overlap across later resets) and ``step`` (env steps since the
recording started, the reset of each episode counting as one).

Cost: entity paths, index arrays and the Arrow schema are built once. Per step the recorder
copies ``data.xpos``/``data.xquat`` of the tracked bodies into a buffer; every ~1 s of simulated
time (``flush_every_s``) the buffer goes out as **one** Arrow record batch holding the poses of
all bodies and the scalars of all agents (Rerun splits it into one chunk per entity), and the
file sink is asked to write it. A crash therefore loses at most the rows of the last second.
Expression changes are rare and logged at once.
"""

from __future__ import annotations

import math
import time
import uuid
from pathlib import Path
from collections.abc import Callable, Mapping
from typing import Any

import mujoco
import numpy as np
import pyarrow as pa
import rerun as rr
import rerun.blueprint as rrb

from .expressions.faces import EXPRESSIONS, face_images

__all__ = ["Recorder", "record_episode", "geom_rgba", "geom_archetype", "SIM_TIME", "STEP",
           "HIDDEN_GEOM_GROUP"]

SIM_TIME = "sim_time"
STEP = "step"
HIDDEN_GEOM_GROUP = 3             # MuJoCo geom group of the eye spheres (not drawn)

_RGB_ROLE = int(mujoco.mjtTextureRole.mjTEXROLE_RGB)
_DEFAULT_GEOM_RGBA = (0.5, 0.5, 0.5, 1.0)   # a geom left at this colour shows its material's
_PLANE_HALF_THICKNESS = 0.0025              # a plane becomes a thin box below z = 0 of its frame
_INFINITE_PLANE_HALF_SIZE = 5.0             # drawn size of a plane with size 0 ("infinite")
_WXYZ_TO_XYZW = np.array([1, 2, 3, 0])
_VEC3 = pa.list_(pa.field("item", pa.float32(), nullable=False), 3)
_QUAT = pa.list_(pa.field("item", pa.float32(), nullable=False), 4)
_G = mujoco.mjtGeom


# -- geometry ------------------------------------------------------------------------------------

def _texture_mean_rgb(model: mujoco.MjModel, tex: int) -> np.ndarray:
    """Mean RGB colour of texture ``tex`` in [0, 1]."""
    nch = int(model.tex_nchannel[tex])
    n = int(model.tex_width[tex] * model.tex_height[tex] * nch)
    adr = int(model.tex_adr[tex])
    pixels = model.tex_data[adr:adr + n].reshape(-1, nch).astype(np.float64) / 255.0
    return pixels[:, :3].mean(axis=0) if nch >= 3 else np.repeat(pixels[:, 0].mean(), 3)


def geom_rgba(model: mujoco.MjModel, g: int) -> np.ndarray:
    """The colour (RGBA in [0, 1]) MuJoCo gives geom ``g``, without lighting.

    A geom's own ``rgba`` wins; a geom left at MuJoCo's default colour shows its material's
    ``rgba``, modulated by the mean colour of the material's RGB texture if it has one.
    """
    rgba = model.geom_rgba[g].astype(np.float64)
    mat = int(model.geom_matid[g])
    if mat >= 0 and np.allclose(rgba, _DEFAULT_GEOM_RGBA):
        rgba = model.mat_rgba[mat].astype(np.float64)
        tex = int(model.mat_texid[mat, _RGB_ROLE])
        if tex >= 0:
            rgba[:3] *= _texture_mean_rgb(model, tex)
    return rgba


def _to_rgba8(rgba) -> np.ndarray:
    return np.round(np.clip(np.asarray(rgba, np.float64), 0.0, 1.0) * 255).astype(np.uint8)


def _rotate(quat_wxyz: np.ndarray, vec) -> np.ndarray:
    out = np.empty(3)
    mujoco.mju_rotVecQuat(out, np.asarray(vec, np.float64), np.asarray(quat_wxyz, np.float64))
    return out


def geom_archetype(model: mujoco.MjModel, g: int, rgba=None) -> Any | None:
    """A Rerun archetype drawing geom ``g`` in its body's frame (``None`` for height fields and SDFs).

    Spheres and ellipsoids become Ellipsoids3D, boxes Boxes3D, capsules Capsules3D (which start
    at their translation and extend along +z), cylinders Cylinders3D, planes a thin box whose top
    face is the plane, meshes a Mesh3D with the geom pose baked into the vertices.
    """
    t = int(model.geom_type[g])
    size = model.geom_size[g].astype(np.float64)
    pos = model.geom_pos[g].astype(np.float64)
    q_wxyz = model.geom_quat[g].astype(np.float64)
    quat = rr.Quaternion(xyzw=q_wxyz[_WXYZ_TO_XYZW])
    color = _to_rgba8(geom_rgba(model, g) if rgba is None else rgba)
    axis = _rotate(q_wxyz, (0.0, 0.0, 1.0))
    if t in (_G.mjGEOM_SPHERE, _G.mjGEOM_ELLIPSOID):
        half = np.full(3, size[0]) if t == _G.mjGEOM_SPHERE else size
        return rr.Ellipsoids3D(half_sizes=[half], centers=[pos], quaternions=[quat],
                               colors=[color], fill_mode="solid")
    if t == _G.mjGEOM_BOX:
        return rr.Boxes3D(half_sizes=[size], centers=[pos], quaternions=[quat], colors=[color],
                          fill_mode="solid")
    if t == _G.mjGEOM_CAPSULE:
        return rr.Capsules3D(lengths=[2 * size[1]], radii=[size[0]],
                             translations=[pos - size[1] * axis], quaternions=[quat],
                             colors=[color])
    if t == _G.mjGEOM_CYLINDER:
        return rr.Cylinders3D(lengths=[2 * size[1]], radii=[size[0]], centers=[pos],
                              quaternions=[quat], colors=[color], fill_mode="solid")
    if t == _G.mjGEOM_PLANE:
        half = [size[0] or _INFINITE_PLANE_HALF_SIZE, size[1] or _INFINITE_PLANE_HALF_SIZE,
                _PLANE_HALF_THICKNESS]
        return rr.Boxes3D(half_sizes=[half], centers=[pos - _PLANE_HALF_THICKNESS * axis],
                          quaternions=[quat], colors=[color], fill_mode="solid")
    if t == _G.mjGEOM_MESH:
        mesh = int(model.geom_dataid[g])
        va, vn = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
        fa, fn = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, q_wxyz)
        verts = model.mesh_vert[va:va + vn] @ R.reshape(3, 3).T + pos
        return rr.Mesh3D(vertex_positions=verts, triangle_indices=model.mesh_face[fa:fa + fn],
                         albedo_factor=color)
    return None


def _cube_sphere(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A unit sphere made of the six sides of a cube, each an ``n`` x ``n`` grid, pushed out.

    Returns vertex directions (V, 3), outward-facing triangles (F, 3) and, per vertex, the
    coordinates (u, v) in [-1, 1] on its cube side and whether that side is the +x one. Sides
    keep their own vertices, so no triangle spans two sides (a face texture on +x stays sharp).
    """
    g = np.linspace(-1.0, 1.0, n + 1)
    U, V = np.meshgrid(g, g, indexing="xy")          # U along columns, V along rows
    u, v = U.ravel(), V.ravel()
    one = np.ones_like(u)
    sides = [np.stack([one, u, v], 1), np.stack([-one, u, v], 1), np.stack([u, one, v], 1),
             np.stack([u, -one, v], 1), np.stack([u, v, one], 1), np.stack([u, v, -one], 1)]
    r, c = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (r * (n + 1) + c).ravel()
    quads = np.concatenate([np.stack([a, a + 1, a + n + 2], 1), np.stack([a, a + n + 2, a + n + 1], 1)])
    verts, tris = [], []
    for k, s in enumerate(sides):
        tris.append(quads + k * len(u))
        verts.append(s)
    verts = np.concatenate(verts)
    verts /= np.linalg.norm(verts, axis=1, keepdims=True)
    tris = np.concatenate(tris)
    # orient every triangle outward (its normal along the direction of its centroid)
    p0, p1, p2 = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    inward = np.einsum("ij,ij->i", np.cross(p1 - p0, p2 - p0), p0 + p1 + p2) < 0
    tris[inward] = tris[inward][:, ::-1]
    uv = np.tile(np.stack([u, v], 1), (6, 1))
    front = np.zeros(len(verts), bool)
    front[: len(u)] = True
    return verts, tris, uv, front


def _face_head_mesh(model: mujoco.MjModel, g: int, n: int = 12) -> rr.Mesh3D:
    """Static geometry of a textured sphere head in its body's frame (the texture comes later).

    The face image goes on the +x side of the geom, as MuJoCo's cube texture puts it: direction
    (1, u, v) shows image column (u + 1) / 2 (column 0 is the face's own right, -y) and row
    (1 - v) / 2 (row 0 at the top). Other sides map to the image corner, which is plain skin.
    """
    dirs, tris, uv, front = _cube_sphere(n)
    R = np.empty(9)
    mujoco.mju_quat2Mat(R, model.geom_quat[g].astype(np.float64))
    R = R.reshape(3, 3)
    normals = dirs @ R.T
    positions = model.geom_size[g, 0] * normals + model.geom_pos[g]
    texcoords = np.full((len(dirs), 2), 0.02)
    texcoords[front, 0] = (uv[front, 0] + 1.0) / 2.0
    texcoords[front, 1] = (1.0 - uv[front, 1]) / 2.0
    return rr.Mesh3D(vertex_positions=positions.astype(np.float32),
                     triangle_indices=tris.astype(np.uint32),
                     vertex_normals=normals.astype(np.float32),
                     vertex_texcoords=texcoords.astype(np.float32),
                     albedo_factor=[255, 255, 255, 255])


def _texture_batches(image: np.ndarray) -> list:
    """The Mesh3D albedo texture components of ``image`` (to update a logged mesh's texture)."""
    mesh = rr.Mesh3D(vertex_positions=np.zeros((1, 3), np.float32), albedo_texture=image)
    return [b for b in mesh.as_component_batches()
            if "albedo_texture" in b.component_descriptor().component]


def _entity(*parts: str) -> str:
    return "/" + "/".join(rr.escape_entity_path_part(p) for p in parts)


def _component_field(name: str, entity: str, descriptor, dtype: pa.DataType) -> pa.Field:
    """An Arrow field that Rerun reads as ``descriptor`` of ``entity``."""
    return pa.field(name, dtype, metadata={
        rr.SORBET_ENTITY_PATH: entity.encode(),
        rr.SORBET_ARCHETYPE_NAME: descriptor.archetype.encode(),
        rr.SORBET_COMPONENT: descriptor.component.encode(),
        rr.SORBET_COMPONENT_TYPE: descriptor.component_type.encode()})


def _index_field(name: str, dtype: pa.DataType) -> pa.Field:
    return pa.field(name, dtype, nullable=False,
                    metadata={rr.SORBET_INDEX_NAME: name.encode(), rr.RERUN_KIND: rr.RERUN_KIND_INDEX})


def _ns(seconds: float) -> np.timedelta64:
    return np.timedelta64(int(round(seconds * 1e9)), "ns")


# -- the recorder --------------------------------------------------------------------------------

class Recorder:
    """Writes an env's simulation to a Rerun ``.rrd`` file; see the module docstring for the layout.

    Parameters
    ----------
    env:
        A ``MimoParallelEnv`` or anything with a ``.parallel`` one (``SingleAgentEnv``). With a
        single-agent adapter, :meth:`log_step` takes that agent's action and reward directly.
    path:
        The ``.rrd`` file to write (its folder is created).
    every_k_steps:
        Record poses and scalars every k-th env step (rewards are summed over the k steps);
        expression changes are always recorded at the step they happen.
    flush_every_s:
        Send buffered rows at least this often, in simulated seconds.
    face_size:
        Edge length in pixels of the face images (and of the head textures).
    textured_heads:
        Draw sphere heads as meshes textured with the current face.
    blueprint:
        Store a default viewer layout (3D view, faces, reward and action plots, expressions).
    """

    def __init__(self, env, path: str | Path, every_k_steps: int = 1, *,
                 flush_every_s: float = 1.0, face_size: int = 64, textured_heads: bool = True,
                 blueprint: bool = True, application_id: str = "mimo_social",
                 recording_name: str | None = None):
        penv = getattr(env, "parallel", env)
        world = getattr(penv, "world", None)
        if world is None or not hasattr(penv, "possible_agents"):
            raise TypeError(f"Recorder needs a MimoParallelEnv (or an adapter with .parallel), "
                            f"got {type(env).__name__}")
        if isinstance(every_k_steps, bool) or int(every_k_steps) != every_k_steps or every_k_steps < 1:
            raise ValueError(f"every_k_steps={every_k_steps!r}; allowed: an integer >= 1")
        if not flush_every_s > 0:
            raise ValueError(f"flush_every_s={flush_every_s!r}; allowed: a positive number")
        self.env = penv
        self.world = world
        self.path = Path(path)
        self.every_k_steps = int(every_k_steps)
        self._single = penv is not env and len(penv.possible_agents) == 1
        self.agents = list(penv.possible_agents)
        self._dt = float(penv.dt)
        self._textured_heads = textured_heads
        self._motor_counts = [self._motor_count(penv.action_space(a)) for a in self.agents]
        self._collect_bodies()
        self._schema = self._build_schema()
        self._capacity = max(1, math.ceil(flush_every_s / (self._dt * self.every_k_steps)))
        self._alloc_buffers()
        self._faces = [rr.Image(img) for img in face_images(face_size)]
        self._head_textures = ([_texture_batches(img) for img in face_images(face_size)]
                               if textured_heads else None)
        self._head_mats = np.array([a.head_material for a in world.agents], dtype=np.intp)
        self._tex_shown = world.model.mat_texid[self._head_mats, _RGB_ROLE].copy()

        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._rec = rr.RecordingStream(application_id, recording_id=uuid.uuid4())
        self._rec.set_log_tick_enabled(False)
        self._rec.set_log_time_enabled(False)
        self._rec.save(self.path, default_blueprint=self.blueprint() if blueprint else None)
        if recording_name:
            self._rec.send_recording_name(recording_name)
        self._closed = False
        self._started = False
        self._global_step = -1
        self._episode_steps = 0
        self._episodes = 0
        self._time_offset = 0.0
        self._last_time: float | None = None
        self.rows = 0                 # pose rows recorded so far
        self.overhead_s = 0.0         # wall-clock seconds spent in log_reset/log_step/close
        self._log_static()

    # -- set-up ---------------------------------------------------------------------------------
    def _collect_bodies(self):
        """Bodies with visible geoms, their entity paths, and the visible geoms of each."""
        m, w = self.world.model, self.world
        visible = (m.geom_group != HIDDEN_GEOM_GROUP) & (m.geom_rgba[:, 3] > 0)
        geoms_of: dict[int, list[int]] = {}
        for g in np.flatnonzero(visible):
            geoms_of.setdefault(int(m.geom_bodyid[g]), []).append(int(g))
        self._scene_geoms = geoms_of.pop(0, [])
        ids, paths = [], []
        for i, a in enumerate(w.agents):
            prefix = f"{a.name}/"
            for b in a.body_ids:
                if int(b) in geoms_of:
                    ids.append(int(b))
                    paths.append(_entity("world", a.name, m.body(int(b)).name.removeprefix(prefix)))
        for b in sorted(set(geoms_of) - set(ids)):
            ids.append(b)
            paths.append(_entity("world", "props", m.body(b).name or f"body_{b}"))
        self._body_ids = np.array(ids, dtype=np.intp)
        self.body_paths: list[str] = paths
        self._geoms_of = geoms_of
        self._head_geoms = {int(a.head_geom) for a in w.agents}

    def _build_schema(self) -> pa.Schema:
        fields = [_index_field(SIM_TIME, pa.duration("ns")), _index_field(STEP, pa.int64())]
        t_desc = rr.Transform3D.descriptor_translation()
        q_desc = rr.Transform3D.descriptor_quaternion()
        for p in self.body_paths:
            fields.append(_component_field(f"{p}:translation", p, t_desc, _VEC3))
            fields.append(_component_field(f"{p}:quaternion", p, q_desc, _QUAT))
        s_desc = rr.Scalars.descriptor_scalars()
        for a in self.agents:
            for what in ("reward", "action_norm"):
                p = _entity("agents", a, what)
                fields.append(_component_field(f"{p}:scalars", p, s_desc, pa.float64()))
        return pa.schema(fields)

    def _alloc_buffers(self):
        n, nb, na = self._capacity, len(self._body_ids), len(self.agents)
        self._pos = np.empty((n, nb, 3))
        self._quat = np.empty((n, nb, 4))
        self._time = np.empty(n)
        self._step = np.empty(n, dtype=np.int64)
        self._reward = np.empty((n, na))
        self._motors = [np.empty((n, k)) for k in self._motor_counts]
        self._acted = np.zeros((n, na), bool)
        self._n = 0
        self._reward_acc = np.zeros(na)
        self._reward_seen = np.zeros(na, bool)

    def _log_static(self):
        rec, m = self._rec, self.world.model
        rec.log("/world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for g in self._scene_geoms:
            shape = geom_archetype(m, g)
            if shape is not None:
                rec.log(_entity("world", "scene", m.geom(g).name or f"geom_{g}"), shape, static=True)
        for b, path in zip(self._body_ids, self.body_paths):
            prefix = m.body(int(b)).name.split("/")[0] + "/"
            for g in self._geoms_of[int(b)]:
                name = m.geom(g).name.removeprefix(prefix) or f"geom_{g}"
                if (self._textured_heads and g in self._head_geoms
                        and m.geom_type[g] == _G.mjGEOM_SPHERE):
                    shape = _face_head_mesh(m, g)
                else:
                    shape = geom_archetype(m, g)
                if shape is not None:
                    rec.log(f"{path}/{rr.escape_entity_path_part(name)}", shape, static=True)
        self._head_paths = []
        for a in self.world.agents:
            b = int(m.geom_bodyid[a.head_geom])
            k = int(np.flatnonzero(self._body_ids == b)[0]) if b in self._body_ids else None
            name = m.geom(int(a.head_geom)).name.removeprefix(f"{a.name}/")
            ok = (self._textured_heads and k is not None
                  and m.geom_type[a.head_geom] == _G.mjGEOM_SPHERE)
            self._head_paths.append(f"{self.body_paths[k]}/{rr.escape_entity_path_part(name)}"
                                    if ok else None)

    def blueprint(self) -> rrb.Blueprint:
        """The default viewer layout: the 3D world, the faces, reward and action plots, expressions."""
        faces = [rrb.Spatial2DView(origin=_entity("agents", a, "face"), name=f"{a} face")
                 for a in self.agents]
        return rrb.Blueprint(
            rrb.Horizontal(
                rrb.Spatial3DView(origin="/world", name="world"),
                rrb.Vertical(
                    rrb.Horizontal(*faces),
                    rrb.TimeSeriesView(origin="/agents", name="rewards",
                                       contents=[_entity("agents", a, "reward") for a in self.agents]),
                    rrb.TimeSeriesView(origin="/agents", name="action norms",
                                       contents=[_entity("agents", a, "action_norm")
                                                 for a in self.agents]),
                    rrb.TextLogView(origin="/agents", name="expressions"),
                ),
                column_shares=[3, 2]),
            rrb.TimePanel(timeline=SIM_TIME),
            collapse_panels=False)

    # -- logging --------------------------------------------------------------------------------
    def log_reset(self) -> None:
        """Record the state right after ``env.reset()`` (the first row of an episode)."""
        t0 = time.perf_counter()
        self._check_open()
        d = self.world.data
        if self._last_time is not None:  # later episodes continue the timeline
            self._time_offset = self._last_time + self._dt - float(d.time)
        self._started = True
        self._episodes += 1
        self._global_step += 1
        self._episode_steps = 0
        self._reward_acc[:] = 0.0
        self._reward_seen[:] = False
        self._tex_shown[:] = self.world.model.mat_texid[self._head_mats, _RGB_ROLE]
        self._log_expressions(range(len(self.agents)))
        self._append_row(np.full(len(self.agents), np.nan), None)
        self.overhead_s += time.perf_counter() - t0

    def log_step(self, actions: Mapping[str, Any] | Any, rewards: Mapping[str, float] | float | None = None) -> None:
        """Record the state right after ``env.step(actions)`` returned ``rewards``."""
        t0 = time.perf_counter()
        if not self._started:
            self._check_open()
            raise RuntimeError("log_step() before log_reset(): call rec.log_reset() after env.reset()")
        if self._single:
            actions = {self.agents[0]: actions}
            if rewards is not None and not isinstance(rewards, Mapping):
                rewards = {self.agents[0]: rewards}
        self._global_step += 1
        self._episode_steps += 1
        if rewards is not None:
            for i, a in enumerate(self.agents):
                r = rewards.get(a)
                if r is not None:
                    self._reward_acc[i] += float(r)
                    self._reward_seen[i] = True
        shown = self.world.model.mat_texid[self._head_mats, _RGB_ROLE]
        if (shown != self._tex_shown).any():
            changed = np.flatnonzero(shown != self._tex_shown)
            self._tex_shown[:] = shown
            self._log_expressions(changed)
        if self._episode_steps % self.every_k_steps == 0:
            reward = np.where(self._reward_seen, self._reward_acc, np.nan)
            self._append_row(reward, actions)
            self._reward_acc[:] = 0.0
            self._reward_seen[:] = False
        self.overhead_s += time.perf_counter() - t0

    @staticmethod
    def _motor_count(space) -> int:
        motors = space["motors"] if hasattr(space, "spaces") and "motors" in space.spaces else space
        return int(np.prod(motors.shape))

    def _store_actions(self, n: int, actions) -> None:
        """Copy each agent's motor action into row ``n`` (norms are taken at flush time)."""
        acted = self._acted[n]
        acted[:] = False
        if not isinstance(actions, Mapping):
            return
        for i, a in enumerate(self.agents):
            action = actions.get(a)
            if action is not None and type(action) is not np.ndarray and isinstance(action, Mapping):
                action = action.get("motors")
            if action is None:
                continue
            try:
                self._motors[i][n] = action
            except (ValueError, TypeError):   # not this agent's motor vector: leave it out
                continue
            acted[i] = True

    def _now(self) -> float:
        return self._time_offset + float(self.world.data.time)

    def _log_expressions(self, agents) -> None:
        rec, t = self._rec, self._now()
        rec.set_time(SIM_TIME, duration=_ns(t))
        rec.set_time(STEP, sequence=self._global_step)
        for i in agents:
            e = self.world.expression_of(int(i))
            name = self.agents[int(i)]
            rec.log(_entity("agents", name, "expression"), rr.TextLog(EXPRESSIONS[e]))
            rec.log(_entity("agents", name, "face"), self._faces[e])
            if self._head_textures is not None and self._head_paths[int(i)] is not None:
                rec.log(self._head_paths[int(i)], self._head_textures[e])
        self._last_time = t

    def _append_row(self, reward: np.ndarray, actions) -> None:
        d, n, ids = self.world.data, self._n, self._body_ids
        self._pos[n] = d.xpos[ids]
        self._quat[n] = d.xquat[ids]
        self._time[n] = self._last_time = self._now()
        self._step[n] = self._global_step
        self._reward[n] = reward
        self._store_actions(n, actions)
        self._n += 1
        self.rows += 1
        if self._n == self._capacity:
            self.flush()

    def flush(self) -> None:
        """Send the buffered rows as one record batch and ask the file sink to write them."""
        n = self._n
        if n == 0 or self._closed:
            return
        nb = len(self._body_ids)
        pos = np.ascontiguousarray(self._pos[:n].astype(np.float32).transpose(1, 0, 2)).reshape(nb, -1)
        quat = np.ascontiguousarray(
            self._quat[:n][:, :, _WXYZ_TO_XYZW].astype(np.float32).transpose(1, 0, 2)).reshape(nb, -1)
        times = np.round(self._time[:n] * 1e9).astype(np.int64)
        columns = [pa.array(times, pa.duration("ns")), pa.array(self._step[:n])]
        for b in range(nb):
            columns.append(pa.FixedSizeListArray.from_arrays(pos[b], type=_VEC3))
            columns.append(pa.FixedSizeListArray.from_arrays(quat[b], type=_QUAT))
        for i in range(len(self.agents)):
            reward = self._reward[:n, i]
            columns.append(pa.array(reward, pa.float64(), mask=np.isnan(reward)))
            u = np.clip(self._motors[i][:n], -1.0, 1.0)
            norm = np.sqrt(np.einsum("ij,ij->i", u, u))
            columns.append(pa.array(norm, pa.float64(), mask=~self._acted[:n, i]))
        self._rec.send_record_batch(pa.RecordBatch.from_arrays(columns, schema=self._schema))
        self._rec.flush(timeout_sec=0)   # start writing now, without waiting
        self._n = 0

    # -- closing --------------------------------------------------------------------------------
    def _check_open(self):
        if self._closed:
            raise RuntimeError(f"the recorder of {self.path} is closed")

    def close(self) -> None:
        """Send what is buffered, finish the file and detach (idempotent)."""
        if self._closed:
            return
        t0 = time.perf_counter()
        self.flush()
        self._rec.flush()
        self._rec.disconnect()
        self._closed = True
        self.overhead_s += time.perf_counter() - t0

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self) -> "Recorder":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return (f"Recorder({str(self.path)!r}, agents={self.agents}, bodies={len(self._body_ids)}, "
                f"rows={self.rows}, closed={self._closed})")


# -- convenience ---------------------------------------------------------------------------------

def record_episode(env, path: str | Path, policy: Callable[[dict], dict] | None = None, *,
                   seed: int | None = None, max_steps: int | None = None,
                   every_k_steps: int = 1, **recorder_options) -> dict:
    """Reset ``env``, run one episode and record it to ``path``; return a small summary.

    ``policy(obs) -> actions`` gets the observation dict of the live agents and returns their
    actions; without one, actions are sampled from the action spaces (seeded by ``seed``). The
    episode ends when no agent is left or after ``max_steps`` steps.
    """
    penv = getattr(env, "parallel", env)
    if policy is None:
        for k, a in enumerate(penv.possible_agents):
            penv.action_space(a).seed(None if seed is None else seed + k)

        def policy(obs):
            return {a: penv.action_space(a).sample() for a in penv.agents}
    steps = 0
    with Recorder(penv, path, every_k_steps, **recorder_options) as rec:
        obs, _ = penv.reset(seed=seed)
        rec.log_reset()
        while penv.agents and (max_steps is None or steps < max_steps):
            actions = policy(obs)
            obs, rewards, _, _, _ = penv.step(actions)
            rec.log_step(actions, rewards)
            steps += 1
    return {"path": str(rec.path), "steps": steps, "sim_time": steps * penv.dt,
            "rows": rec.rows, "bytes": rec.path.stat().st_size, "overhead_s": rec.overhead_s}
