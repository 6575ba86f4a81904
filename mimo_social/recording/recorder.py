"""Record simulations to Rerun ``.rrd`` files (written to disk only: no viewer, no network).

A :class:`Recorder` attaches to a :class:`~mimo_social.core.env.MimoParallelEnv` (or a
Gymnasium :class:`~mimo_social.core.gym_adapter.SingleAgentEnv`, through its ``.parallel``)::

    env = free_play_v0.parallel_env(n_agents=2)
    with Recorder(env, "recordings/run.rrd") as rec:
        obs, infos = env.reset(seed=0)
        rec.log_reset(obs)
        while env.agents:
            actions = policy(obs)
            obs, rewards, term, trunc, infos = env.step(actions)
            rec.log_step(actions, rewards, obs)

Open the file with ``rerun recordings/run.rrd`` or ``mimo-social replay recordings/run.rrd``
(``--summary`` prints what it holds without a viewer). For training, :class:`RecordingParallelEnv`
records every k-th episode of one env by itself and :func:`recording_env_fn` makes an ``env_fn``
for :func:`~mimo_social.train.vector.sb3_vec_env` whose first sub-environment records.

Layout of a recording::

    /world                          view coordinates (right-handed, z up)
    /world/scene/<geom>             static geoms of the world body (the floor)
    /world/<agent>/<body>           Transform3D of the body in the world, every logged step
    /world/<agent>/<body>/<geom>    static shape of each visible geom, in its body's frame
    /world/<agent>/skin             Points3D (world frame): the skin points that feel a force,
                                    coloured by its magnitude (yellow 0.01 N -> dark red 10 N,
                                    log scale; touch on); every logged step, empty when nothing
                                    touches
    /world/props/<body>[/<geom>]    the same for every other body (props)
    /agents/<agent>/reward          Scalars: reward, summed over the steps since the last row
    /agents/<agent>/action_norm     Scalars: L2 norm of the motor action, clipped to [-1, 1]
    /agents/<agent>/touch_total     Scalars: summed normal force (N) on the agent's skin (touch on)
    /agents/<agent>/expression      TextLog at reset and at every change of the expression
    /agents/<agent>/face            Image of the face at reset and at every change (see below)
    /agents/<agent>/eyes/left|right EncodedImage (PNG, lossless) of each eye (vision on)
    /events/contacts                TextLog, one row when a body part of one agent starts
                                    touching a body part of another ("infant_0 right_hand touches
                                    infant_1 right_fingers")
    /scalars/<name>                 Scalars: the ``scalars={name: fn(env)}`` given to the Recorder

Heads are textured spheres (Mesh3D) that show the current face; geoms in group 3 (the hidden eye
spheres) are left out. Face images and head textures are logged for expressions that stay at
least ``face_hold_s`` (0.05 s), stamped with the step they appeared, so that a policy switching
faces every step does not fill the file with images; the text log has every change.

Two timelines: ``sim_time`` (simulated seconds: ``data.time`` in the first episode, continued
without overlap across later resets) and ``step`` (env steps since the recording started, the
reset of each episode counting as one).

Cost: entity paths, index arrays and the Arrow schema are built once. Per step the recorder only
copies ``data.xpos``/``data.xquat`` and the motor actions into preallocated buffers, notes an
expression change (seen as a change of the head materials' texture), looks for new contacts
between agents (one lookup of all ``data.contact`` geom pairs in a table of "two different
agents"), with touch on notes which skin points of all agents feel a force (one pass over the
skin's force array), and with vision on encodes the eye images as PNG (zlib level 1, ~2 KB and
~0.1 ms for a 64x64 image). Every ``flush_every_s`` of simulated time the buffer goes out as
**one** Arrow record batch with the poses of all bodies, the scalars of all agents and their skin
points (placed in the world and coloured then, for all rows at once), followed by a batch each of
expression changes, eye images and contact events of that interval (Rerun splits a batch into one
chunk per entity, which its file sink writes on its own thread). The next flush first waits until
the previous one is written (by then it long is), so a crash keeps every row up to
:attr:`Recorder.flushed_step` and loses at most the last two intervals. Rerun's cost is mostly per
chunk, i.e. per entity and flush, so the interval sets the price. With 2 infants without images
(44 entities; measured on a 2-core VM busy with other work, against the plain env's step): 4 s
(the default) costs 7-8 % in the stepping thread and ~10 % with Rerun's own threads, 13.5 MB
per simulated minute; 2 s ~9 % and ~12 %. A crash then loses at most 8 simulated seconds (well
under a second of wall-clock time). Touch adds ~15 MB/min of skin points (``every_k_steps=2``
halves everything); 2 x 64x64 eyes per infant add ~24 MB/min as PNG.
``python -m mimo_social.recording.recorder`` measures cost and file size (see :func:`bench_recording`). Call :meth:`Recorder.close` (or use ``with``): it sends the
rest and writes the file's footer.
"""

from __future__ import annotations

import io
import math
import multiprocessing
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
from pettingzoo import ParallelEnv

from ..expressions.faces import EXPRESSIONS, face_images
from ..render.png import encode_png

__all__ = ["Recorder", "record_episode", "RecordingParallelEnv", "recording_env_fn",
           "RecordSubEnv", "encode_png", "force_colors", "geom_rgba", "geom_archetype",
           "bench_recording", "SIM_TIME", "STEP", "HIDDEN_GEOM_GROUP", "EYE_FORMATS",
           "CONTACTS_PATH", "SKIN_POINT_RADIUS", "SKIN_FORCE_RANGE"]

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
_POINTS = pa.list_(pa.field("item", _VEC3, nullable=False))
_COLORS = pa.list_(pa.field("item", pa.uint32(), nullable=False))
_BYTES = pa.list_(pa.field("item", pa.uint8(), nullable=False))
_BLOBS = pa.list_(pa.field("item", _BYTES, nullable=False))
_TEXTS = pa.list_(pa.field("item", pa.utf8(), nullable=False))
_G = mujoco.mjtGeom

EYE_FORMATS = ("png", "jpeg", "raw")   # how eye images are stored (see Recorder)
EYES = ("left", "right")
CONTACTS_PATH = "/events/contacts"
# skin points: colour and radius grow with the force on the point, on a log scale from
# SKIN_FORCE_RANGE[0] (yellow, smallest) to SKIN_FORCE_RANGE[1] newtons (dark red, largest)
SKIN_FORCE_RANGE = (0.01, 10.0)
SKIN_POINT_RADIUS = 0.004                         # metres (one static radius for all points)
_SKIN_STOPS = np.array([0.0, 0.35, 0.7, 1.0])
_SKIN_RGB = np.array([[255, 235, 0], [255, 140, 0], [225, 20, 0], [120, 0, 30]], np.float64)


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


def _encode_jpeg(image: np.ndarray, quality: int) -> bytes:
    from PIL import Image as PILImage

    out = io.BytesIO()
    PILImage.fromarray(np.ascontiguousarray(image)).save(out, format="JPEG", quality=quality)
    return out.getvalue()


def _colour_table(levels: int = 256) -> np.ndarray:
    t = np.linspace(0.0, 1.0, levels)
    c = np.round(np.stack([np.interp(t, _SKIN_STOPS, _SKIN_RGB[:, k]) for k in range(3)],
                          axis=1)).astype(np.uint32)
    return (c[:, 0] << 24) | (c[:, 1] << 16) | (c[:, 2] << 8) | np.uint32(255)


_SKIN_COLOURS = _colour_table()


def force_colors(force: np.ndarray) -> np.ndarray:
    """Rerun colours (uint32 0xRRGGBBAA) of skin points feeling ``force`` newtons: yellow at
    ``SKIN_FORCE_RANGE[0]`` or less, through orange and red to dark red at
    ``SKIN_FORCE_RANGE[1]`` or more (log scale, 256 steps)."""
    lo, hi = SKIN_FORCE_RANGE
    t = np.log(np.maximum(np.asarray(force, np.float64), lo) * (1.0 / lo))
    t *= (len(_SKIN_COLOURS) - 1) / math.log(hi / lo)
    np.clip(t, 0.0, len(_SKIN_COLOURS) - 1, out=t)
    t += 0.5
    return _SKIN_COLOURS.take(t.astype(np.intp))


def _offsets(counts) -> pa.Array:
    out = np.zeros(len(counts) + 1, dtype=np.int32)
    np.cumsum(counts, out=out[1:])
    return pa.array(out)


def _sparse_column(items: list, values: pa.Array, dtype: pa.DataType) -> pa.ListArray:
    """A component column with one instance per row where ``items`` is not None and no data (a
    null row) elsewhere; ``values`` holds the instances of the rows with data, in row order."""
    present = np.array([x is not None for x in items], dtype=bool)
    return pa.ListArray.from_arrays(_offsets(present), values, type=dtype,
                                    mask=None if present.all() else pa.array(~present))


def _blob_values(blobs: list[bytes]) -> pa.ListArray:
    """Byte strings as Rerun blobs (lists of uint8), one per entry."""
    data = np.frombuffer(b"".join(blobs), dtype=np.uint8)
    return pa.ListArray.from_arrays(_offsets([len(b) for b in blobs]), pa.array(data), type=_BYTES)


# -- the recorder --------------------------------------------------------------------------------

class _Rows:
    """One chunk of buffered rows: raw copies of ``data.xpos``/``xquat``, per-agent scalars, skin
    points; and the events of the same interval (expression changes, eye images, contacts)."""

    def __init__(self, capacity: int, nbody: int, motor_counts: list[int], n_touch: int = 0,
                 n_scalars: int = 0):
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
        # touch: per row the skin points with force (global point index), their normal force and
        # force vector, and body orientations (to place the points in the world at flush time)
        self.xmat = np.empty((capacity, nbody, 9), np.float32) if n_touch else None
        self.skin_cuts = np.empty((capacity, 2 * n_touch), np.intp)  # each agent's part of idx
        self.skin_idx: list[np.ndarray] = []
        self.skin_normal: list[np.ndarray] = []
        self.skin_xyz: list[np.ndarray] = []
        self.scalars = np.empty((capacity, n_scalars))
        self.eyes: list[tuple[float, int, int, Any, Any]] = []   # time, step, agent, left, right
        self.contacts: list[tuple[float, int, str]] = []          # time, step, text
        self.n = 0

    def clear(self) -> None:
        self.n = 0
        self.time, self.step, self.reward = [], [], []
        self.texts, self.images, self.eyes, self.contacts = [], [], [], []
        self.skin_idx, self.skin_normal, self.skin_xyz = [], [], []


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
        Send buffered rows at least this often, in simulated seconds; a crash keeps the rows up
        to :attr:`flushed_step` (so it loses at most the rows of two such intervals). Shorter
        intervals cost more (see the module docstring).
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
        Store a default viewer layout: the 3D world; faces; each agent's two eyes side by side
        (vision on); rewards, touch totals (touch on) and chosen scalars over time; action
        norms, expressions and contact events in tabs.
    scalars:
        ``{name: fn}``: ``fn(env) -> float`` is called with the env given here at every logged
        step and goes to ``/scalars/<name>`` (a ``/`` in the name makes sub-paths); NaN: none.
    eyes:
        Log the eye images of agents with vision (``eye_left`` / ``eye_right``): taken from the
        ``observations`` given to :meth:`log_step` / :meth:`log_reset` when they hold them, else
        from the env's vision system. Only images rendered anew are logged (vision's ``every``).
    eye_format:
        ``"png"`` (default: lossless, ~2 KB a 64x64 image), ``"jpeg"`` (needs Pillow; smaller,
        lossy, ``eye_jpeg_quality``) or ``"raw"`` (uncompressed ``Image``; 12 KB a 64x64 image).
    eye_every_k_steps:
        Log eye images every k-th env step of an episode (default: ``every_k_steps``).
    skin:
        Log the skin points that feel a force (agents with touch) and each agent's touch total.
    contacts:
        Log an event when a body part of one agent starts touching a body part of another.
    """

    def __init__(self, env, path: str | Path, every_k_steps: int = 1, *,
                 flush_every_s: float = 4.0, face_size: int = 64, face_hold_s: float = 0.05,
                 textured_heads: bool = True, blueprint: bool = True,
                 application_id: str = "mimo_social", recording_name: str | None = None,
                 scalars: Mapping[str, Callable[[Any], float]] | None = None,
                 eyes: bool = True, eye_format: str = "png",
                 eye_every_k_steps: int | None = None, eye_jpeg_quality: int = 90,
                 skin: bool = True, contacts: bool = True):
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
        if eye_every_k_steps is None:
            eye_every_k_steps = every_k_steps
        if (isinstance(eye_every_k_steps, bool) or int(eye_every_k_steps) != eye_every_k_steps
                or eye_every_k_steps < 1):
            raise ValueError(f"eye_every_k_steps={eye_every_k_steps!r}; allowed: an integer >= 1")
        if eye_format not in EYE_FORMATS:
            raise ValueError(f"eye_format={eye_format!r}; allowed: {', '.join(EYE_FORMATS)}")
        scalars = dict(scalars or {})
        for name, fn in scalars.items():
            if not isinstance(name, str) or not name.strip("/") or not callable(fn):
                raise ValueError(f"scalars: {name!r}: {fn!r}; each entry must be a non-empty name "
                                 "-> a callable fn(env) returning a float")
        self._user_env = env
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
        self._find_senses(eyes, skin, contacts)
        self.eye_format = eye_format
        self.eye_every_k_steps = int(eye_every_k_steps)
        self._eye_jpeg_quality = int(eye_jpeg_quality)
        if self._vision_agents and eye_format == "jpeg":
            try:
                import PIL  # noqa: F401
            except ImportError:
                raise ImportError("eye_format='jpeg' needs Pillow (pip install pillow); "
                                  "'png' needs nothing") from None
        self._scalar_fns = list(scalars.values())
        self._scalar_paths = [_entity("scalars", *[p for p in name.split("/") if p])
                              for name in scalars]
        self.scalar_names = list(scalars)
        if len(set(self._scalar_paths)) < len(self._scalar_paths):
            raise ValueError(f"scalars: names {self.scalar_names} give the same entity path twice")
        self._schema = self._build_schema()
        self._capacity = max(1, math.ceil(flush_every_s / (self._dt * self.every_k_steps)))
        self._hold_steps = max(0, math.ceil(face_hold_s / self._dt - 1e-9))
        self._pending: dict[int, tuple[float, int, int, int]] = {}   # agent -> image not yet due
        self._rows = _Rows(self._capacity, world.model.nbody, self._motor_counts,
                           len(self._touch_agents), len(self._scalar_fns))
        self._head_mats = np.array([a.head_material for a in world.agents], dtype=np.intp)
        faces = getattr(world, "faces", None)      # texture id -> expression id, for speed
        self._expression_of_texture = ({world.model.texture(name).id: e
                                        for e, name in enumerate(faces.names)} if faces else {})
        self._expression_paths = [_entity("agents", a, "expression") for a in self.agents]
        self._face_paths = [_entity("agents", a, "face") for a in self.agents]

        import pyarrow.compute  # noqa: F401  (Arrow imports it at the first masked array: now)

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
        # pose rows (and the last step with one) known to be in the file: a crash keeps them
        self.flushed_rows = 0
        self.flushed_step = -1
        self._sent_rows, self._sent_step = 0, -1     # sent to Rerun, maybe not written yet
        self.eye_frames = 0           # eye image pairs recorded so far
        self.contact_events = 0       # contact events between agents recorded so far
        self.overhead_s = 0.0         # wall-clock seconds spent in this recorder's methods
        self._pairs: set[int] = set()  # body pairs of different agents in contact
        self._eye_renders: dict[int, int] = {}
        self._log_static()
        self._build_event_columns(face_size)
        self._build_eye_schema()

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

    def _find_senses(self, eyes: bool, skin: bool, contacts: bool) -> None:
        """The env's shared touch and vision systems (if on) and the index arrays to read them."""
        touch = self.env.systems.get("touch")
        vision = self.env.systems.get("vision")
        self._touch = touch if skin else None
        self._touch_agents: list[int] = []
        if self._touch is not None:
            self._touch_agents = [i for i, sk in enumerate(touch.skins) if sk is not None]
            # every point's body and local position; agents' points are consecutive slices
            self._skin_body = touch.part_body[touch.point_part]
            self._skin_local = touch.points
            self._skin_bounds = np.array([touch.agent_slices[i] for i in self._touch_agents],
                                         dtype=np.intp).reshape(-1, 2)
            self._skin_mask = np.empty(len(touch.force_normal), dtype=bool)
            self._skin_bounds_flat = self._skin_bounds.ravel()
            self._skin_local32 = self._skin_local.astype(np.float32)
        self._vision = vision if eyes else None
        self._vision_agents: list[int] = []
        self._eye_shapes: dict[int, tuple[int, int]] = {}
        if self._vision is not None:
            for i in sorted(getattr(vision, "agents", vision.images)):
                space = self.env.observation_space(self.agents[i])
                if hasattr(space, "spaces") and "eye_left" in space.spaces:
                    self._vision_agents.append(int(i))
                    self._eye_shapes[int(i)] = tuple(space["eye_left"].shape[:2])
        self._eye_paths = {i: [_entity("agents", self.agents[i], "eyes", e) for e in EYES]
                           for i in self._vision_agents}
        self._contacts = bool(contacts) and len(self.agents) > 1
        m, w = self.world.model, self.world
        # [geom a, geom b]: the geoms belong to two different agents; the extra last row and
        # column (geom id -1, as flex contacts have) are False
        agent = np.append(np.asarray(w.geom_agent, dtype=np.intp), -1)
        pairs = (agent[:, None] != agent[None, :]) & (agent[:, None] >= 0) & (agent[None, :] >= 0)
        self._geom_pairs = pairs.ravel()                   # looked up at geom a * stride + geom b
        self._geom_stride = np.array([pairs.shape[1], 1], dtype=np.intp)
        self._geom_body = np.append(m.geom_bodyid.astype(np.intp), 0)
        self._body_agent = np.asarray(w.body_agent, dtype=np.intp)
        self._body_part = [m.body(b).name.split("/", 1)[-1] for b in range(m.nbody)]

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
        for i in self._touch_agents:
            p = _entity("agents", self.agents[i], "touch_total")
            fields.append(_component_field(f"{p}:scalars", p, s_desc, _SCALARS))
            p = _entity("world", self.agents[i], "skin")
            for desc, dtype in ((rr.Points3D.descriptor_positions(), _POINTS),
                                (rr.Points3D.descriptor_colors(), _COLORS)):
                fields.append(_component_field(f"{p}:{desc.component}", p, desc, dtype))
        for p in self._scalar_paths:
            fields.append(_component_field(f"{p}:scalars", p, s_desc, _SCALARS))
        return pa.schema(fields)

    def _build_eye_schema(self) -> None:
        """Arrow schema of the eye image batches and, for raw images, each agent's format."""
        fields = [_index_field(SIM_TIME, pa.duration("ns")), _index_field(STEP, pa.int64())]
        self._eye_format_values: dict[int, pa.Array] = {}
        raw = self.eye_format == "raw"
        for i in self._vision_agents:
            if raw:
                h, w = self._eye_shapes[i]
                fmt = [b for b in rr.Image(np.zeros((h, w, 3), np.uint8)).as_component_batches()
                       if b.component_descriptor().component == "Image:format"][0]
                self._eye_format_values[i] = fmt.as_arrow_array()
                descs = [(rr.Image.descriptor_buffer(), _BLOBS),
                         (rr.Image.descriptor_format(),
                          pa.list_(pa.field("item", self._eye_format_values[i].type,
                                            nullable=False)))]
            else:
                descs = [(rr.EncodedImage.descriptor_blob(), _BLOBS),
                         (rr.EncodedImage.descriptor_media_type(), _TEXTS)]
            for p in self._eye_paths[i]:
                for desc, dtype in descs:
                    fields.append(_component_field(f"{p}:{desc.component}", p, desc, dtype))
        self._eye_schema = pa.schema(fields)
        self._media_type = "image/png" if self.eye_format == "png" else "image/jpeg"
        t_desc = rr.TextLog.descriptor_text()
        self._contact_schema = pa.schema([
            _index_field(SIM_TIME, pa.duration("ns")), _index_field(STEP, pa.int64()),
            _component_field(f"{CONTACTS_PATH}:text", CONTACTS_PATH, t_desc, _TEXTS)])

    def _log_static(self):
        rec, m = self._rec, self.world.model
        rec.log("/world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for i in self._touch_agents:      # one radius for every skin point (colour: the force)
            rec.log(_entity("world", self.agents[i], "skin"),
                    rr.Points3D.from_fields(radii=[SKIN_POINT_RADIUS]), static=True)
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
        """The default viewer layout: the 3D world beside faces, each agent's two eyes side by
        side (vision on), time series of rewards, touch totals (touch on) and chosen scalars, and
        tabs with the action norms, the expressions and the contact events."""
        side: list = [rrb.Horizontal(*[rrb.Spatial2DView(origin=p, name=f"{a} face")
                                       for a, p in zip(self.agents, self._face_paths)],
                                     name="faces")]
        if self._vision_agents:
            eyes = [rrb.Horizontal(*[rrb.Spatial2DView(origin=p, name=f"{self.agents[i]} {e} eye")
                                     for e, p in zip(EYES, self._eye_paths[i])],
                                   name=f"{self.agents[i]} eyes")
                    for i in self._vision_agents]
            side.append(eyes[0] if len(eyes) == 1 else rrb.Vertical(*eyes, name="eyes"))
        side.append(rrb.TimeSeriesView(origin="/agents", name="rewards",
                                       contents=[_entity("agents", a, "reward")
                                                 for a in self.agents]))
        if self._touch_agents:
            side.append(rrb.TimeSeriesView(
                origin="/agents", name="touch totals (N)",
                contents=[_entity("agents", self.agents[i], "touch_total")
                          for i in self._touch_agents]))
        if self._scalar_paths:
            side.append(rrb.TimeSeriesView(origin="/scalars", name="scalars"))
        tabs = [rrb.TimeSeriesView(origin="/agents", name="action norms",
                                   contents=[_entity("agents", a, "action_norm")
                                             for a in self.agents]),
                rrb.TextLogView(origin="/agents", name="expressions")]
        if self._contacts:
            tabs.append(rrb.TextLogView(origin=CONTACTS_PATH, name="contacts"))
        side.append(rrb.Tabs(*tabs))
        return rrb.Blueprint(
            rrb.Horizontal(
                rrb.Spatial3DView(origin="/world", name="world", eye_controls=self._eye()),
                rrb.Vertical(*side),
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
    def log_reset(self, observations: Mapping[str, Any] | None = None) -> None:
        """Record the state right after ``env.reset()`` (the first row of an episode).

        ``observations``: what ``reset`` returned (optional): the eye images are taken from it
        when it holds them (with a single-agent adapter: that agent's observation).
        """
        t0 = time.perf_counter()
        self._check_open()
        w = self.world
        # views into the model/data memory, valid for the life of the world; taken anew per episode
        self._data, self._xpos, self._xquat = w.data, w.data.xpos, w.data.xquat
        self._xmat = w.data.xmat
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
        self._pairs = set()                      # contacts at reset are new ones
        self._eye_renders = {}
        if self._contacts:
            self._note_contacts()
        if self._vision_agents:
            self._note_eyes(self._single_obs(observations))
        self._append_row([math.nan] * na, None)
        self.overhead_s += time.perf_counter() - t0

    def log_step(self, actions: Mapping[str, Any] | Any,
                 rewards: Mapping[str, float] | float | None = None,
                 observations: Mapping[str, Any] | None = None) -> None:
        """Record the state right after ``env.step(actions)`` returned ``rewards``.

        ``actions`` and ``rewards`` are the dicts given to and returned by ``env.step`` (with a
        single-agent adapter: that agent's action and reward). Agents missing from them (done)
        get no reward or action-norm value in that row. ``observations`` (optional): what
        ``env.step`` returned; eye images are taken from it when it holds them.
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
        if self._contacts:
            self._note_contacts()
        if self._vision_agents and self._episode_steps % self.eye_every_k_steps == 0:
            self._note_eyes(self._single_obs(observations))
        if self._episode_steps % self.every_k_steps == 0:
            reward, self._reward_acc = self._reward_acc, [math.nan] * len(self.agents)
            self._append_row(reward, actions)
        self.overhead_s += time.perf_counter() - t0

    def _single_obs(self, observations):
        if observations is None or not self._single:
            return observations
        return {self.agents[0]: observations}

    def _note_contacts(self) -> None:
        """Note every pair of bodies of two different agents that started touching (a contact
        at zero or negative distance) since the last call."""
        d = self._data
        if d.ncon == 0:
            self._pairs = set()
            return
        c = d.contact
        geoms = c.geom                                   # (ncon, 2)
        hit = self._geom_pairs.take(geoms.dot(self._geom_stride))
        if not np.count_nonzero(hit):                    # (cheaper than hit.any())
            self._pairs = set()
            return
        hit &= c.dist <= 0.0
        bodies = self._geom_body[geoms[hit]]
        nbody = len(self._body_part)
        keys = set((bodies.min(axis=1) * nbody + bodies.max(axis=1)).tolist())
        new = keys - self._pairs
        self._pairs = keys
        if not new:
            return
        t, step = self._now(), self._global_step
        for key in sorted(new):
            pair = sorted(divmod(key, nbody), key=lambda b: (self._body_agent[b], b))
            a, b = pair
            text = (f"{self.agents[self._body_agent[a]]} {self._body_part[a]} touches "
                    f"{self.agents[self._body_agent[b]]} {self._body_part[b]}")
            self._rows.contacts.append((t, step, text))
        self.contact_events += len(new)

    def _note_eyes(self, observations) -> None:
        """Encode the eye images of every agent with vision rendered anew since the last time."""
        renders = getattr(self._vision, "renders", None)
        t, step = self._now(), self._global_step
        for i in self._vision_agents:
            if renders is not None:
                if self._eye_renders.get(i) == renders[i]:
                    continue                                   # the same images as before
                self._eye_renders[i] = renders[i]
            obs = observations.get(self.agents[i]) if isinstance(observations, Mapping) else None
            if isinstance(obs, Mapping) and "eye_left" in obs and "eye_right" in obs:
                left, right = obs["eye_left"], obs["eye_right"]
            else:
                images = self._vision.images[i]
                left, right = images["eye_left"], images["eye_right"]
            self._rows.eyes.append((t, step, i, self._encode(left), self._encode(right)))
            self.eye_frames += 1

    def _encode(self, image: np.ndarray):
        if self.eye_format == "png":
            return encode_png(image)
        if self.eye_format == "jpeg":
            return _encode_jpeg(image, self._eye_jpeg_quality)
        return np.ascontiguousarray(image, dtype=np.uint8).tobytes()

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
        if self._touch_agents:
            self._note_skin(rows, n)
        for k, fn in enumerate(self._scalar_fns):
            try:
                rows.scalars[n, k] = fn(self._user_env)
            except Exception as e:
                raise RuntimeError(f"Recorder scalar {self.scalar_names[k]!r}: {fn!r} failed: "
                                   f"{type(e).__name__}: {e}") from e
        rows.n = n + 1
        self.rows += 1
        if rows.n == self._capacity:
            self._flush()

    def _note_skin(self, rows: _Rows, n: int) -> None:
        """Note the skin points with force of all touch agents (one pass over all their points);
        they are placed in the world, coloured and summed per agent at flush time."""
        touch = self._touch
        normal = touch.force_normal
        # (a boolean mask first: numpy's nonzero is ~6x faster on booleans than on floats)
        active = np.not_equal(normal, 0.0, out=self._skin_mask).nonzero()[0]
        rows.xmat[n] = self._xmat
        rows.skin_cuts[n] = active.searchsorted(self._skin_bounds_flat)
        rows.skin_idx.append(active)
        rows.skin_normal.append(normal[active])
        rows.skin_xyz.append(np.take(touch.force_xyz.reshape(-1, 3), active, axis=0))

    def _skin_columns(self, rows: _Rows) -> list[pa.Array]:
        """Per touch agent: the touch total and the Points3D columns of the buffered rows."""
        n, nbody = rows.n, rows.xpos.shape[1]
        counts = np.fromiter((len(a) for a in rows.skin_idx), dtype=np.intp, count=n)
        idx = np.concatenate(rows.skin_idx)
        row_start = np.zeros(n, dtype=np.intp)
        np.cumsum(counts[:-1], out=row_start[1:])
        # every point in the world frame: xpos + xmat @ local, all points at once (float32)
        flat = np.repeat(np.arange(n) * nbody, counts) + self._skin_body[idx]
        R = np.take(rows.xmat.reshape(-1, 9), flat, axis=0)
        world = np.take(rows.xpos.reshape(-1, 3), flat, axis=0).astype(np.float32)
        local = self._skin_local32[idx]
        x, y, z = local[:, 0], local[:, 1], local[:, 2]
        for k in range(3):
            world[:, k] += R[:, 3 * k] * x + R[:, 3 * k + 1] * y + R[:, 3 * k + 2] * z
        xyz = np.concatenate(rows.skin_xyz)
        colors = force_colors(np.sqrt(np.einsum("ij,ij->i", xyz, xyz)))
        normal = np.concatenate(rows.skin_normal)
        columns = []
        for j in range(len(self._touch_agents)):
            first, stop = rows.skin_cuts[:n, 2 * j], rows.skin_cuts[:n, 2 * j + 1]
            per_row = stop - first
            # the agent's points, row after row: positions in the concatenated arrays
            before = np.zeros(n, dtype=np.intp)
            np.cumsum(per_row[:-1], out=before[1:])
            sel = np.repeat(row_start + first - before, per_row) + np.arange(per_row.sum())
            # (np.bincount gives integers, not floats, when no row has a point)
            total = np.bincount(np.repeat(np.arange(n), per_row), weights=normal[sel],
                                minlength=n).astype(np.float64)
            # every row has a (maybe empty) list of points: an empty one clears the last points
            offsets = _offsets(per_row)
            columns += [
                _optional_scalars(total, np.ones(n, dtype=bool)),
                pa.ListArray.from_arrays(offsets, pa.FixedSizeListArray.from_arrays(
                    pa.array(world[sel].ravel()), type=_VEC3), type=_POINTS),
                pa.ListArray.from_arrays(offsets, pa.array(colors[sel]), type=_COLORS)]
        return columns

    def flush(self) -> None:
        """Send the buffered rows and events now and wait until they are in the file (this
        happens by itself when the buffer is full, i.e. every ``flush_every_s`` simulated
        seconds, without the wait, and at :meth:`close`)."""
        t0 = time.perf_counter()
        if not self._closed:
            self._flush()
            self._rec.flush()
            self.flushed_rows, self.flushed_step = self._sent_rows, self._sent_step
        self.overhead_s += time.perf_counter() - t0

    def _flush(self) -> None:
        rows = self._rows
        if self._sent_step > self.flushed_step:
            # what the last flush sent is written by Rerun's own thread meanwhile: wait for it
            # (it is long done: this costs ~0.5 ms), so everything up to there is on disk
            self._rec.flush()
            self.flushed_rows, self.flushed_step = self._sent_rows, self._sent_step
        if rows.n:
            self._rec.send_record_batch(self._record_batch(rows))
        if rows.texts or rows.images:
            self._rec.send_record_batch(self._event_batch(rows.texts, rows.images))
        if rows.eyes:
            self._rec.send_record_batch(self._eye_batch(rows.eyes))
        if rows.contacts:
            self._rec.send_record_batch(self._contact_batch(rows.contacts))
        if rows.n:
            self._sent_rows += rows.n
            self._sent_step = rows.step[-1]
        rows.clear()

    @staticmethod
    def _index_columns(times, steps) -> list[pa.Array]:
        ns = np.round(np.asarray(times, dtype=np.float64) * 1e9).astype(np.int64)
        return [pa.array(ns, pa.duration("ns")), pa.array(np.asarray(steps, dtype=np.int64))]

    def _eye_batch(self, eyes) -> pa.RecordBatch:
        """Eye images as one record batch: a row per step with images, per agent and eye its
        image where rendered, no data elsewhere."""
        steps = sorted({step: t for t, step, _, _, _ in eyes}.items())
        row_of = {step: r for r, (step, _) in enumerate(steps)}
        cells = {(i, e): [None] * len(steps) for i in self._vision_agents for e in range(2)}
        for _, step, i, left, right in eyes:
            r = row_of[step]
            cells[i, 0][r], cells[i, 1][r] = left, right
        columns = self._index_columns([t for _, t in steps], [step for step, _ in steps])
        raw = self.eye_format == "raw"
        for i in self._vision_agents:
            for e in range(2):
                items = cells[i, e]
                blobs = [b for b in items if b is not None]
                columns.append(_sparse_column(items, _blob_values(blobs), _BLOBS))
                if raw:
                    fmt = self._eye_format_values[i]
                    second = fmt.take(pa.array(np.zeros(len(blobs), dtype=np.int64)))
                    dtype = pa.list_(pa.field("item", fmt.type, nullable=False))
                else:
                    second = pa.array([self._media_type] * len(blobs), pa.utf8())
                    dtype = _TEXTS
                columns.append(_sparse_column(items, second, dtype))
        return pa.RecordBatch.from_arrays(columns, schema=self._eye_schema)

    def _contact_batch(self, contacts) -> pa.RecordBatch:
        """Contact events as one record batch: a row per event (events of one step share it)."""
        columns = self._index_columns([t for t, _, _ in contacts], [s for _, s, _ in contacts])
        texts = [text for _, _, text in contacts]
        columns.append(pa.ListArray.from_arrays(_offsets(np.ones(len(texts), np.int32)),
                                                pa.array(texts, pa.utf8()), type=_TEXTS))
        return pa.RecordBatch.from_arrays(columns, schema=self._contact_schema)

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
        if self._touch_agents:
            columns += self._skin_columns(rows)
        for k in range(len(self._scalar_fns)):
            value = rows.scalars[:n, k].copy()
            columns.append(_optional_scalars(value, ~np.isnan(value)))
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
            self.flushed_rows, self.flushed_step = self._sent_rows, self._sent_step
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
        rec.log_reset(obs)
        while penv.agents and (max_steps is None or steps < max_steps):
            actions = policy(obs)
            obs, rewards, _, _, _ = penv.step(actions)
            rec.log_step(actions, rewards, obs)
            steps += 1
    return {"path": str(rec.path), "steps": steps, "sim_time": steps * penv.dt,
            "rows": rec.rows, "bytes": rec.path.stat().st_size, "overhead_s": rec.overhead_s}


# -- recording during training ---------------------------------------------------------------------

def _check_episode_options(path_pattern, every_k_episodes) -> None:
    if (isinstance(every_k_episodes, bool) or int(every_k_episodes) != every_k_episodes
            or every_k_episodes < 1):
        raise ValueError(f"every_k_episodes={every_k_episodes!r}; allowed: an integer >= 1")
    try:
        str(path_pattern).format(episode=0)
    except (KeyError, IndexError, ValueError) as e:
        raise ValueError(f"path_pattern={str(path_pattern)!r}: {e!r}; it may only use "
                         "{episode} (e.g. 'runs/ep{episode:05d}.rrd')") from None


#: per claim key: how many wrappers with that key have reset in this process (see
#: :class:`RecordingParallelEnv`'s ``claim``)
_CLAIMS: dict[str, int] = {}

#: the name of the first worker process of :func:`mimo_social.train.vector.sb3_vec_env`
FIRST_VEC_WORKER = "mimo_social-vec-0"


def _main_or_first_worker() -> bool:
    return (multiprocessing.parent_process() is None
            or multiprocessing.current_process().name == FIRST_VEC_WORKER)


class RecordingParallelEnv(ParallelEnv):
    """A ParallelEnv wrapper that records every ``every_k_episodes``-th episode to its own file.

    ``env``: a ``MimoParallelEnv`` (or a wrapper of one that keeps its dict observations and
    actions). Episodes are counted by the resets of this wrapper, from 0: episodes 0, k, 2k ...
    are recorded to ``path_pattern.format(episode=n)`` (e.g. ``"runs/ep{episode:05d}.rrd"``),
    each with a :class:`Recorder` (``recorder_options`` go to it) that the wrapper feeds itself
    with the actions, rewards and observations it passes on, and closes (writing the file's
    footer) when the episode ends, at the next reset or at :meth:`close`.

    It pickles (for vector envs in worker processes): an open recorder stays with the process
    that opened it and the copy starts its own at its next chosen episode; files are opened
    lazily, at the reset of a chosen episode, in the process that steps the env.

    ``claim=(key, n)`` makes it record only if it is the n-th (from 0) of the wrappers with that
    key to reset in its process, in the main process or the first worker of ``sb3_vec_env``
    (:func:`recording_env_fn` uses it: SuperSuit makes every world as a pickled copy of one env,
    so the worlds can only tell themselves apart by the order they reset in, world 0 first).
    """

    def __init__(self, env, path_pattern: str | Path = "recordings/ep{episode:05d}.rrd",
                 every_k_episodes: int = 10, *, claim: tuple[str, int] | None = None,
                 **recorder_options):
        _check_episode_options(path_pattern, every_k_episodes)
        self.env = env
        self.path_pattern = str(path_pattern)
        self.every_k_episodes = int(every_k_episodes)
        self.recorder_options = dict(recorder_options)
        self.claim = None if claim is None else (str(claim[0]), int(claim[1]))
        self.rank: int | None = None         # with a claim: its place among the wrappers
        self.chosen = claim is None          # records (with a claim: known at the first reset)
        self.episode = -1                    # index of the current episode (-1: before a reset)
        self.recorder: Recorder | None = None
        self.paths: list[Path] = []          # the files this wrapper (in this process) wrote
        self.metadata = dict(getattr(env, "metadata", {}))
        self.render_mode = getattr(env, "render_mode", None)
        self.possible_agents = list(env.possible_agents)

    # the live agents and the spaces are the wrapped env's
    @property
    def agents(self):
        return self.env.agents

    @property
    def unwrapped(self):
        return self.env.unwrapped

    def observation_space(self, agent):
        return self.env.observation_space(agent)

    def action_space(self, agent):
        return self.env.action_space(agent)

    def _recorded_env(self):
        return self.env if hasattr(self.env, "world") else self.env.unwrapped

    def reset(self, seed: int | None = None, options: dict | None = None):
        obs, infos = self.env.reset(seed=seed, options=options)
        self._stop_recording()
        if self.claim is not None and self.rank is None:
            key, wanted = self.claim
            self.rank = _CLAIMS.get(key, 0)
            _CLAIMS[key] = self.rank + 1
            self.chosen = self.rank == wanted and _main_or_first_worker()
        self.episode += 1
        if self.chosen and self.episode % self.every_k_episodes == 0:
            path = Path(self.path_pattern.format(episode=self.episode))
            options = {"recording_name": f"episode {self.episode}", **self.recorder_options}
            self.recorder = Recorder(self._recorded_env(), path, **options)
            self.paths.append(path)
            self.recorder.log_reset(obs)
        return obs, infos

    def step(self, actions):
        obs, rewards, terminations, truncations, infos = self.env.step(actions)
        rec = self.recorder
        if rec is not None:
            rec.log_step(actions, rewards, obs)
            if not self.env.agents:
                self._stop_recording()
        return obs, rewards, terminations, truncations, infos

    def _stop_recording(self) -> None:
        if self.recorder is not None:
            rec, self.recorder = self.recorder, None
            rec.close()

    def render(self):
        return self.env.render()

    def state(self):
        return self.env.state()

    def close(self):
        self._stop_recording()
        return self.env.close()

    def __getstate__(self):
        state = self.__dict__.copy()
        state["recorder"] = None             # an open file never travels
        if self.claim is not None:           # a copy claims its own place at its first reset
            state["rank"], state["chosen"] = None, False
        return state

    def __getattr__(self, name: str):
        env = self.__dict__.get("env")
        if env is None or name.startswith("_"):
            raise AttributeError(f"{type(self).__name__} has no attribute {name!r}")
        return getattr(env, name)

    def __str__(self):
        return f"RecordingParallelEnv<{self.env}>"


class RecordSubEnv:
    """The ``env_fn`` made by :func:`recording_env_fn` (picklable when ``env_fn`` is)."""

    def __init__(self, env_fn: Callable[[], Any], path_pattern: str | Path,
                 every_k_episodes: int = 10, sub_env: int = 0, **recorder_options):
        if isinstance(sub_env, bool) or int(sub_env) != sub_env or sub_env < 0:
            raise ValueError(f"sub_env={sub_env!r}; allowed: an integer >= 0")
        _check_episode_options(path_pattern, every_k_episodes)
        self.env_fn = env_fn
        self.path_pattern = str(path_pattern)
        self.every_k_episodes = int(every_k_episodes)
        self.sub_env = int(sub_env)
        self.recorder_options = dict(recorder_options)
        self.key = uuid.uuid4().hex          # travels with the pickle: the same in every worker

    def __call__(self) -> RecordingParallelEnv:
        return RecordingParallelEnv(self.env_fn(), self.path_pattern, self.every_k_episodes,
                                    claim=(self.key, self.sub_env), **self.recorder_options)


def recording_env_fn(env_fn: Callable[[], Any], path_pattern: str | Path,
                     every_k_episodes: int = 10, sub_env: int = 0,
                     **recorder_options) -> RecordSubEnv:
    """``env_fn`` for :func:`~mimo_social.train.vector.sb3_vec_env` whose world ``sub_env``
    (default 0) records every ``every_k_episodes``-th episode to ``path_pattern``::

        venv = sb3_vec_env(recording_env_fn(high_five_v0.parallel_env, "runs/ep{episode:05d}.rrd",
                                            every_k_episodes=10), n_envs=8, n_cpus=2)

    Every world gets a :class:`RecordingParallelEnv` (inside ``FlattenParallel``, so it sees the
    dict actions and observations), but only one records: the ``sub_env``-th to reset in the
    main process (``n_cpus=0``) or in the first worker process (``n_cpus>=1``, which holds
    worlds 0, 1, ...; ``sub_env`` must be below its number of worlds). SuperSuit resets worlds
    in order, so that is world ``sub_env``. The others pass everything through.
    """
    return RecordSubEnv(env_fn, path_pattern, every_k_episodes, sub_env, **recorder_options)


# -- benchmark -------------------------------------------------------------------------------------

#: the configurations of :func:`bench_recording`: env keyword arguments of ``free_play_v0``
BENCH_CONFIGS = {
    "2 infants, no images": dict(n_agents=2),
    "2 infants, touch (skin points)": dict(n_agents=2, touch=True),
    "2 infants, 2 x 64x64 eyes each": dict(n_agents=2, vision={"width": 64, "height": 64}),
}


def _render_threads_cpu() -> float:
    """CPU seconds so far of Mesa's rendering threads (``llvmpipe-*``) of this process (Linux;
    else 0)."""
    import os

    total = 0
    try:
        tasks = os.listdir("/proc/self/task")
    except OSError:
        return 0.0
    for tid in tasks:
        try:
            with open(f"/proc/self/task/{tid}/comm") as f:
                if not f.read().startswith("llvmpipe"):
                    continue
            with open(f"/proc/self/task/{tid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            total += int(fields[11]) + int(fields[12])      # utime + stime, in clock ticks
        except (OSError, ValueError, IndexError):
            continue
    return total / os.sysconf("SC_CLK_TCK")


def bench_recording(configs: Mapping[str, dict] | None = None, sim_seconds: float = 60.0,
                    block: int = 100, seed: int = 0, folder: str | Path | None = None,
                    **recorder_options) -> list[dict]:
    """Cost and file size of recording, per configuration (default :data:`BENCH_CONFIGS`).

    Two envs of a configuration take the same smooth random actions (with expressions switching
    about every second), in alternating blocks of ``block`` steps: one plain, one recorded (its
    observations go to :meth:`Recorder.log_step`). The recording's cost is given as a share of
    the plain env's step time, three ways:

    * ``cpu_pct``: CPU time, the main thread's (env + recorder) plus Rerun's own threads
      (encoding, compressing, writing: the process's CPU time less the main thread's and Mesa's
      rendering threads', read from ``/proc``), against the plain env's main-thread CPU time; the most stable figure on a busy
      machine, and the whole price on one core;
    * ``main_cpu_pct``: the main thread's CPU time alone (what stepping feels while Rerun's
      threads have another core);
    * ``wall_pct``: wall clock, which on a loaded machine also holds waiting for a core.

    Also the wall-clock ms per step of both and the file's size in MB per simulated minute.
    """
    import tempfile

    from ..core.random_actions import smooth_random_actions
    from ..envs import free_play_v0

    configs = BENCH_CONFIGS if configs is None else configs
    folder = Path(folder) if folder is not None else Path(tempfile.mkdtemp(prefix="mimo_rec_"))
    out = []
    for k, (name, kwargs) in enumerate(configs.items()):
        envs = [free_play_v0.parallel_env(max_steps=10 ** 9, **kwargs) for _ in range(2)]
        n_steps = int(round(sim_seconds / envs[0].dt))
        agents = envs[0].possible_agents
        acts = [smooth_random_actions(n_steps, envs[0].action_space(a)["motors"].shape[0],
                                      seed + i) for i, a in enumerate(agents)]
        path = folder / f"bench_{k}.rrd"
        obs = [env.reset(seed=seed)[0] for env in envs]
        rec = Recorder(envs[1], path, **recorder_options)
        rec.log_reset(obs[1])
        wall, cpu = [0.0, 0.0], [0.0, 0.0]
        process0, main0, render0 = time.process_time(), time.thread_time(), _render_threads_cpu()
        for start in range(0, n_steps, block):
            for e, env in enumerate(envs):
                t0, c0 = time.perf_counter(), time.thread_time()
                for s in range(start, min(n_steps, start + block)):
                    actions = {a: {"motors": acts[i][0][s], "expression": int(acts[i][1][s])}
                               for i, a in enumerate(agents)}
                    o, rewards, _, _, _ = env.step(actions)
                    if e == 1:
                        rec.log_step(actions, rewards, o)
                wall[e] += time.perf_counter() - t0
                cpu[e] += time.thread_time() - c0
        render = _render_threads_cpu() - render0
        t0, c0 = time.perf_counter(), time.thread_time()
        rec.close()
        wall[1] += time.perf_counter() - t0
        cpu[1] += time.thread_time() - c0
        # every thread but the main one and the renderer's: Rerun's (they end at close, so
        # they are counted through the process's total, which keeps the time of ended threads)
        other_threads = max(0.0, time.process_time() - process0 - (time.thread_time() - main0)
                            - render)
        for env in envs:
            env.close()
        size = path.stat().st_size
        minutes = n_steps * envs[0].dt / 60.0
        out.append({"config": name, "steps": n_steps, "sim_s": n_steps * envs[0].dt,
                    "ms_per_step": 1e3 * wall[0] / n_steps,
                    "ms_per_step_recorded": 1e3 * wall[1] / n_steps,
                    "cpu_pct": 100.0 * (cpu[1] + other_threads - cpu[0]) / cpu[0],
                    "main_cpu_pct": 100.0 * (cpu[1] - cpu[0]) / cpu[0],
                    "wall_pct": 100.0 * (wall[1] - wall[0]) / wall[0],
                    "in_recorder_pct": 100.0 * rec.overhead_s / wall[0],
                    "mb_per_sim_minute": size / 1e6 / minutes, "file_mb": size / 1e6,
                    "rerun_threads_cpu_s": other_threads, "eye_frames": rec.eye_frames,
                    "path": str(path)})
    return out


def _bench_main(argv=None) -> None:
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m mimo_social.recording.recorder",
        description="Cost (share of the env step time) and size (MB per simulated minute) of "
                    "recording with the Recorder, for 2 infants without images, with touch and "
                    "with 2 x 64x64 eyes each.")
    parser.add_argument("--sim-seconds", type=float, default=60.0)
    parser.add_argument("--only", default=None,
                        help="comma-separated indices of the configurations to run (0, 1, 2)")
    parser.add_argument("--folder", default=None, help="where to keep the .rrd files")
    args = parser.parse_args(argv)
    configs = dict(BENCH_CONFIGS)
    if args.only:
        keep = {int(x) for x in args.only.split(",")}
        configs = {k: v for i, (k, v) in enumerate(configs.items()) if i in keep}
    print("| configuration | ms/step plain | ms/step recorded | cost: CPU (all threads) | "
          "CPU (main thread) | wall clock | MB per sim. minute |")
    print("|---|---|---|---|---|---|---|")
    for r in bench_recording(configs, args.sim_seconds, folder=args.folder):
        print(f"| {r['config']} | {r['ms_per_step']:.3f} | {r['ms_per_step_recorded']:.3f} | "
              f"{r['cpu_pct']:.1f} % | {r['main_cpu_pct']:.1f} % | {r['wall_pct']:.1f} % | "
              f"{r['mb_per_sim_minute']:.1f} |", flush=True)


if __name__ == "__main__":
    _bench_main()
