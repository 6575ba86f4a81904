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
    /agents/<agent>/expression      TextLog at reset and at every change of the expression
    /agents/<agent>/face            Image of the face at reset and at every change (see below)

Heads are textured spheres (Mesh3D) that show the current face; geoms in group 3 (the hidden eye
spheres) are left out. Face images and head textures are logged for expressions that stay at
least ``face_hold_s`` (0.05 s), stamped with the step they appeared, so that a policy switching
faces every step does not fill the file with images; the text log has every change.

Two timelines: ``sim_time`` (simulated seconds: ``data.time`` in the first episode, continued
without overlap across later resets) and ``step`` (env steps since the recording started, the
reset of each episode counting as one).

Cost: entity paths, index arrays and the Arrow schema are built once. Per step the recorder only
copies ``data.xpos``/``data.xquat`` and the motor actions into preallocated buffers (and notes an
expression change, seen as a change of the head materials' texture). Every ``flush_every_s`` of
simulated time the buffer goes out as **one** Arrow record batch with the poses of all bodies
and the scalars of all agents (Rerun splits it into one chunk per entity, which its file sink
writes at once), followed by the expression changes of that interval. A crash therefore loses at
most the last interval. Rerun's cost is mostly per chunk, i.e. per entity and flush (~0.1 ms of
CPU), so the interval sets the price: with 2 infants (46 entities) a 1 s interval costs about
11 % of an env step and 2 s (the default) about 7 % (measured on a 2-core VM). Call
:meth:`Recorder.close` (or use ``with``): it sends the rest and writes the file's footer.
"""

from __future__ import annotations

import math
import time
import uuid
from collections.abc import Callable, Mapping
from pathlib import Path
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
_MAX_PLANE_HALF_SIZE = 2.0                  # planes are drawn at most 4 m x 4 m (the view fits it)
_WXYZ_TO_XYZW = np.array([1, 2, 3, 0])
_VEC3 = pa.list_(pa.field("item", pa.float32(), nullable=False), 3)
_QUAT = pa.list_(pa.field("item", pa.float32(), nullable=False), 4)
_SCALARS = pa.list_(pa.field("item", pa.float64(), nullable=False))
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
    """A Rerun archetype drawing geom ``g`` in its body's frame (None for height fields, SDFs).

    Spheres and ellipsoids become Ellipsoids3D, boxes Boxes3D, capsules Capsules3D (which start
    at their translation and extend along +z), cylinders Cylinders3D, planes a thin box whose top
    face is the plane (at most 4 m x 4 m), meshes a Mesh3D with the geom pose baked into the
    vertices.
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
        half = [min(size[0] or np.inf, _MAX_PLANE_HALF_SIZE),
                min(size[1] or np.inf, _MAX_PLANE_HALF_SIZE), _PLANE_HALF_THICKNESS]
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
    quads = np.concatenate([np.stack([a, a + 1, a + n + 2], 1),
                            np.stack([a, a + n + 2, a + n + 1], 1)])
    verts = np.concatenate(sides)
    tris = np.concatenate([quads + k * len(u) for k in range(len(sides))])
    verts /= np.linalg.norm(verts, axis=1, keepdims=True)
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
    return pa.field(name, dtype, nullable=False, metadata={
        rr.SORBET_INDEX_NAME: name.encode(), rr.RERUN_KIND: rr.RERUN_KIND_INDEX})


def _optional_scalars(values: np.ndarray, present: np.ndarray) -> pa.ListArray:
    """A Scalars column: one value per row where ``present``, no data (a null row) elsewhere.

    ``values`` must own its memory (Arrow wraps contiguous numpy arrays without copying).
    """
    if present.all():
        offsets = np.arange(len(values) + 1, dtype=np.int32)
        return pa.ListArray.from_arrays(pa.array(offsets), pa.array(values), type=_SCALARS)
    offsets = np.zeros(len(values) + 1, dtype=np.int32)
    np.cumsum(present, out=offsets[1:])
    return pa.ListArray.from_arrays(pa.array(offsets), pa.array(values[present]), type=_SCALARS,
                                    mask=pa.array(~present))


# -- the recorder --------------------------------------------------------------------------------

class _Rows:
    """One chunk of buffered rows: raw copies of ``data.xpos``/``xquat``, per-agent scalars."""

    def __init__(self, capacity: int, nbody: int, motor_counts: list[int]):
        self.xpos = np.empty((capacity, nbody, 3))
        self.xquat = np.empty((capacity, nbody, 4))
        self.time: list[float] = []                  # plain lists: cheapest to append to
        self.step: list[int] = []
        self.reward: list[list[float]] = []          # per row, per agent (NaN: none)
        # float32 like the action spaces (a plain copy per step); NaN rows: no action
        self.motors = [np.empty((capacity, k), dtype=np.float32) for k in motor_counts]
        # expression changes, as (time, step, agent, expression): every one for the text log, and
        # those shown long enough for a face image / head texture
        self.texts: list[tuple[float, int, int, int]] = []
        self.images: list[tuple[float, int, int, int]] = []
        self.n = 0


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
        Send buffered rows at least this often, in simulated seconds; a crash loses at most the
        rows of one such interval. Shorter intervals cost more (see the module docstring).
    face_size:
        Edge length in pixels of the face images (and of the head textures).
    face_hold_s:
        Log the face image and head texture of an expression once it has been shown this long
        (simulated seconds), stamped with the step it appeared; every change is in the text log
        regardless. Keeps policies that switch faces every step from filling the file with
        images. 0: an image for every change.
    textured_heads:
        Draw sphere heads as meshes textured with the current face.
    blueprint:
        Store a default viewer layout (3D view, faces, reward and action plots, expressions).
    """

    def __init__(self, env, path: str | Path, every_k_steps: int = 1, *,
                 flush_every_s: float = 2.0, face_size: int = 64, face_hold_s: float = 0.05,
                 textured_heads: bool = True, blueprint: bool = True,
                 application_id: str = "mimo_social", recording_name: str | None = None):
        penv = getattr(env, "parallel", env)
        world = getattr(penv, "world", None)
        if world is None or not hasattr(penv, "possible_agents"):
            raise TypeError(f"Recorder needs a MimoParallelEnv (or an adapter with .parallel), "
                            f"got {type(env).__name__}")
        if (isinstance(every_k_steps, bool) or int(every_k_steps) != every_k_steps
                or every_k_steps < 1):
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
        self._hold_steps = max(0, math.ceil(face_hold_s / self._dt - 1e-9))
        self._pending: dict[int, tuple[float, int, int, int]] = {}   # agent -> image not yet due
        self._rows = _Rows(self._capacity, world.model.nbody, self._motor_counts)
        self._head_mats = np.array([a.head_material for a in world.agents], dtype=np.intp)
        faces = getattr(world, "faces", None)      # texture id -> expression id, for speed
        self._expression_of_texture = ({world.model.texture(name).id: e
                                        for e, name in enumerate(faces.names)} if faces else {})
        self._expression_paths = [_entity("agents", a, "expression") for a in self.agents]
        self._face_paths = [_entity("agents", a, "face") for a in self.agents]

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
        self._time_offset = 0.0
        self._last_time: float | None = None
        self.rows = 0                 # pose rows recorded so far
        self.overhead_s = 0.0         # wall-clock seconds spent in this recorder's methods
        self._log_static()
        self._build_event_columns(face_size)

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
        for a in w.agents:
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
                fields.append(_component_field(f"{p}:scalars", p, s_desc, _SCALARS))
        return pa.schema(fields)

    def _log_static(self):
        rec, m = self._rec, self.world.model
        rec.log("/world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for g in self._scene_geoms:
            shape = geom_archetype(m, g)
            if shape is not None:
                path = _entity("world", "scene", m.geom(g).name or f"geom_{g}")
                rec.log(path, shape, static=True)
        head_of = {int(a.head_geom): i for i, a in enumerate(self.world.agents)}
        self._head_paths: list[str | None] = [None] * len(self.agents)
        for b, path in zip(self._body_ids, self.body_paths):
            prefix = m.body(int(b)).name.split("/")[0] + "/"
            for g in self._geoms_of[int(b)]:
                name = m.geom(g).name.removeprefix(prefix) or f"geom_{g}"
                geom_path = f"{path}/{rr.escape_entity_path_part(name)}"
                if self._textured_heads and g in head_of and m.geom_type[g] == _G.mjGEOM_SPHERE:
                    shape = _face_head_mesh(m, g)
                    self._head_paths[head_of[g]] = geom_path
                else:
                    shape = geom_archetype(m, g)
                if shape is not None:
                    rec.log(geom_path, shape, static=True)

    def _build_event_columns(self, face_size: int) -> None:
        """Arrow schema and values of what is logged when an agent's expression changes.

        Per agent: the TextLog, the face Image and (textured heads) the head's texture. The values
        of each component are stacked over the expressions (row e: expression e), so an event
        batch is made by picking rows.
        """
        images = face_images(face_size)
        per_expression = {
            "expression": [rr.TextLog(name) for name in EXPRESSIONS],
            "face": [rr.Image(img) for img in images],
            "texture": [rr.Mesh3D(vertex_positions=np.zeros((1, 3), np.float32), albedo_texture=img)
                        for img in images]}
        stacked: dict[str, list] = {}
        for kind, archetypes in per_expression.items():
            batches = [a.as_component_batches() for a in archetypes]
            for k, first in enumerate(batches[0]):
                desc = first.component_descriptor()
                if kind == "texture" and "albedo_texture" not in desc.component:
                    continue
                values = [b[k].as_arrow_array() for b in batches]    # one row per expression
                stacked.setdefault(kind, []).append((desc, values))
        fields = [_index_field(SIM_TIME, pa.duration("ns")), _index_field(STEP, pa.int64())]
        self._event_columns: list[tuple[int, bool, list[pa.Array]]] = []  # agent, image?, values
        for i in range(len(self.agents)):
            paths = {"expression": self._expression_paths[i], "face": self._face_paths[i],
                     "texture": self._head_paths[i]}
            for kind, components in stacked.items():
                if paths[kind] is None:
                    continue
                for desc, values in components:
                    dtype = pa.list_(pa.field("item", values[0].type, nullable=False))
                    fields.append(_component_field(f"{paths[kind]}:{desc.component}", paths[kind],
                                                   desc, dtype))
                    self._event_columns.append((i, kind != "expression", values))
        self._event_schema = pa.schema(fields)
        self._event_fields = fields[2:]

    def blueprint(self) -> rrb.Blueprint:
        """The default viewer layout: 3D world, faces, reward and action plots, expressions."""
        faces = [rrb.Spatial2DView(origin=p, name=f"{a} face")
                 for a, p in zip(self.agents, self._face_paths)]
        return rrb.Blueprint(
            rrb.Horizontal(
                rrb.Spatial3DView(origin="/world", name="world", eye_controls=self._eye()),
                rrb.Vertical(
                    rrb.Horizontal(*faces),
                    rrb.TimeSeriesView(origin="/agents", name="rewards",
                                       contents=[_entity("agents", a, "reward")
                                                 for a in self.agents]),
                    rrb.TimeSeriesView(origin="/agents", name="action norms",
                                       contents=[_entity("agents", a, "action_norm")
                                                 for a in self.agents]),
                    rrb.TextLogView(origin="/agents", name="expressions"),
                ),
                column_shares=[3, 2]),
            rrb.TimePanel(timeline=SIM_TIME),
            collapse_panels=False)

    def _eye(self) -> rrb.EyeControls3D | None:
        """The 3D view's starting camera: the env's scene camera (which shows every agent)."""
        scene_camera = getattr(self.env, "scene_camera", None)
        if scene_camera is None:
            return None
        cam = scene_camera()
        az, el = np.deg2rad(cam.azimuth), np.deg2rad(cam.elevation)
        forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        look = np.array(cam.lookat, dtype=np.float64)
        return rrb.EyeControls3D(position=look - cam.distance * forward, look_target=look,
                                 eye_up=[0.0, 0.0, 1.0])

    # -- logging ----------------------------------------------------------------------------------
    def log_reset(self) -> None:
        """Record the state right after ``env.reset()`` (the first row of an episode)."""
        t0 = time.perf_counter()
        self._check_open()
        w = self.world
        # views into the model/data memory, valid for the life of the world; taken anew per episode
        self._data, self._xpos, self._xquat = w.data, w.data.xpos, w.data.xquat
        self._mat_texid = w.model.mat_texid
        if self._last_time is not None:  # later episodes continue the timeline
            self._time_offset = self._last_time + self._dt - float(w.data.time)
        self._started = True
        self._global_step += 1
        self._episode_steps = 0
        na = len(self.agents)
        self._reward_acc = [math.nan] * na
        self._tex_raw = self._mat_texid.tobytes()
        self._tex_shown = self._mat_texid[self._head_mats, _RGB_ROLE]
        self._commit_images(everything=True)     # the last faces of the previous episode
        self._note_expressions(range(na), at_once=True)
        self._append_row([math.nan] * na, None)
        self.overhead_s += time.perf_counter() - t0

    def log_step(self, actions: Mapping[str, Any] | Any,
                 rewards: Mapping[str, float] | float | None = None) -> None:
        """Record the state right after ``env.step(actions)`` returned ``rewards``.

        ``actions`` and ``rewards`` are the dicts given to and returned by ``env.step`` (with a
        single-agent adapter: that agent's action and reward). Agents missing from them (done)
        get no reward or action-norm value in that row.
        """
        t0 = time.perf_counter()
        if not self._started:
            self._check_open()
            raise RuntimeError("log_step() before log_reset(): "
                               "call rec.log_reset() after env.reset()")
        if self._single:
            actions = {self.agents[0]: actions}
            if rewards is not None and not isinstance(rewards, Mapping):
                rewards = {self.agents[0]: rewards}
        self._global_step += 1
        self._episode_steps += 1
        if rewards:
            acc = self._reward_acc                   # NaN: no reward yet since the last row
            for i, a in enumerate(self.agents):
                r = rewards.get(a)
                if r is not None:
                    x = acc[i]
                    acc[i] = float(r) if x != x else x + float(r)
        raw = self._mat_texid.tobytes()          # a cheap test for "some material changed"
        if raw != self._tex_raw:
            self._tex_raw = raw
            shown = self._mat_texid[self._head_mats, _RGB_ROLE]
            changed = np.flatnonzero(shown != self._tex_shown)
            self._tex_shown = shown
            self._note_expressions(changed)
        if self._pending:
            self._commit_images()
        if self._episode_steps % self.every_k_steps == 0:
            reward, self._reward_acc = self._reward_acc, [math.nan] * len(self.agents)
            self._append_row(reward, actions)
        self.overhead_s += time.perf_counter() - t0

    @staticmethod
    def _motor_count(space) -> int:
        motors = space["motors"] if hasattr(space, "spaces") and "motors" in space.spaces else space
        return int(np.prod(motors.shape))

    def _now(self) -> float:
        return self._time_offset + float(self.world.data.time)

    def _note_expressions(self, agents, at_once: bool = False) -> None:
        """Note the current expression of ``agents`` (sent with the next chunk): always as text;
        as face image and head texture once it has been shown ``face_hold_s`` (or ``at_once``)."""
        t, step, rows = self._now(), self._global_step, self._rows
        for i in agents:
            event = (t, step, int(i), self._expression_of(int(i)))
            rows.texts.append(event)
            if at_once or self._hold_steps == 0:
                self._pending.pop(int(i), None)
                rows.images.append(event)
            else:
                self._pending[int(i)] = event     # replaces a shorter-lived one
        self._last_time = t

    def _expression_of(self, i: int) -> int:
        """Agent ``i``'s expression id, read from its head material's texture."""
        e = self._expression_of_texture.get(int(self._tex_shown[i]))
        return self.world.expression_of(i) if e is None else e

    def _commit_images(self, everything: bool = False) -> None:
        """Queue the face images of expressions shown long enough (or of all, ``everything``)."""
        for i, event in list(self._pending.items()):
            if everything or self._global_step - event[1] >= self._hold_steps:
                self._rows.images.append(event)
                del self._pending[i]

    def _append_row(self, reward, actions) -> None:
        """Copy the poses, time, rewards and motor actions (NaN: none) into the next buffer row."""
        rows = self._rows
        n = rows.n
        rows.xpos[n] = self._xpos
        rows.xquat[n] = self._xquat
        self._last_time = self._time_offset + self._data.time
        rows.time.append(self._last_time)
        rows.step.append(self._global_step)
        rows.reward.append(reward)
        get = actions.get if isinstance(actions, Mapping) else None
        for i, a in enumerate(self.agents):
            action = get(a) if get is not None else None
            kind = type(action)
            if kind is dict or (kind is not np.ndarray and isinstance(action, Mapping)):
                action = action.get("motors")
            try:
                rows.motors[i][n] = np.nan if action is None else action
            except (ValueError, TypeError):   # not this agent's motor vector: leave it out
                rows.motors[i][n] = np.nan
        rows.n = n + 1
        self.rows += 1
        if rows.n == self._capacity:
            self._flush()

    def flush(self) -> None:
        """Send the buffered rows and expression changes now (this happens by itself when the
        buffer is full, i.e. every ``flush_every_s`` simulated seconds, and at :meth:`close`)."""
        t0 = time.perf_counter()
        if not self._closed:
            self._flush()
        self.overhead_s += time.perf_counter() - t0

    def _flush(self) -> None:
        rows = self._rows
        if rows.n:
            self._rec.send_record_batch(self._record_batch(rows))
        if rows.texts or rows.images:
            self._rec.send_record_batch(self._event_batch(rows.texts, rows.images))
        rows.n = 0
        rows.time, rows.step, rows.reward = [], [], []
        rows.texts, rows.images = [], []

    def _event_batch(self, texts, images) -> pa.RecordBatch:
        """Expression changes as one record batch: a row per step with a change; per agent its
        text (every change) and face image and head texture (changes held long enough) where it
        changed, no data elsewhere."""
        steps = sorted({step: t for t, step, _, _ in texts + images}.items())
        row_of = {step: r for r, (step, _) in enumerate(steps)}
        na = len(self.agents)
        shown = {False: [[-1] * na for _ in steps], True: [[-1] * na for _ in steps]}
        for is_image, events in ((False, texts), (True, images)):
            for _, step, i, e in events:
                shown[is_image][row_of[step]][i] = e
        times = np.round(np.array([t for _, t in steps]) * 1e9).astype(np.int64)
        columns = [pa.array(times, pa.duration("ns")),
                   pa.array(np.array([step for step, _ in steps], dtype=np.int64))]
        picks = {}    # (agent, image?) -> (expressions of the rows with data, offsets, nulls)
        for is_image, table in shown.items():
            for i in range(na):
                picked = [row[i] for row in table]
                present = np.array([e >= 0 for e in picked])
                offsets = np.zeros(len(picked) + 1, dtype=np.int32)
                np.cumsum(present, out=offsets[1:])
                picks[i, is_image] = ([e for e in picked if e >= 0], pa.array(offsets),
                                      pa.array(~present))
        for (i, is_image, values), field in zip(self._event_columns, self._event_fields):
            picked, offsets, nulls = picks[i, is_image]
            items = (pa.concat_arrays([values[e] for e in picked]) if picked
                     else values[0].slice(0, 0))
            columns.append(pa.ListArray.from_arrays(offsets, items, type=field.type, mask=nulls))
        return pa.RecordBatch.from_arrays(columns, schema=self._event_schema)

    def _record_batch(self, rows: _Rows) -> pa.RecordBatch:
        """The buffered rows as one Arrow record batch: poses of all bodies, agents' scalars."""
        n, nb, ids = rows.n, len(self._body_ids), self._body_ids
        # (rows, all bodies, k) -> tracked bodies, each body's rows one after the other, float32;
        # MuJoCo's quaternions are (w, x, y, z), Rerun's (x, y, z, w)
        pos = np.ascontiguousarray(rows.xpos[:n, ids].transpose(1, 0, 2), dtype=np.float32)
        quat = np.ascontiguousarray(rows.xquat[:n, ids[:, None], _WXYZ_TO_XYZW].transpose(1, 0, 2),
                                    dtype=np.float32)
        pos = pa.FixedSizeListArray.from_arrays(pos.ravel(), type=_VEC3)
        quat = pa.FixedSizeListArray.from_arrays(quat.ravel(), type=_QUAT)
        times = np.round(np.array(rows.time) * 1e9).astype(np.int64)
        # Arrow wraps numpy memory without copying and Rerun encodes later, on its own thread:
        # every column must own fresh memory, never a view of the reused buffers
        columns = [pa.array(times, pa.duration("ns")),
                   pa.array(np.array(rows.step, dtype=np.int64))]
        rewards = np.array(rows.reward, dtype=np.float64).reshape(n, -1)
        for b in range(nb):
            columns += [pos.slice(b * n, n), quat.slice(b * n, n)]
        for i in range(len(self.agents)):
            reward = rewards[:, i].copy()
            u = np.clip(rows.motors[i][:n].astype(np.float64), -1.0, 1.0)
            norm = np.sqrt(np.einsum("ij,ij->i", u, u))        # NaN where there was no action
            columns += [_optional_scalars(reward, ~np.isnan(reward)),
                        _optional_scalars(norm, ~np.isnan(norm))]
        return pa.RecordBatch.from_arrays(columns, schema=self._schema)

    # -- closing --------------------------------------------------------------------------------
    def _check_open(self):
        if self._closed:
            raise RuntimeError(f"the recorder of {self.path} is closed")

    def close(self) -> None:
        """Send what is buffered, finish the file (with its footer) and detach (idempotent)."""
        if self._closed:
            return
        t0 = time.perf_counter()
        try:
            self._commit_images(everything=True)
            self._flush()
        finally:
            self._rec.flush()
            self._rec.disconnect()
            self._closed = True
            self._started = False
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
