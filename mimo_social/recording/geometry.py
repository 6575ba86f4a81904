"""Rerun shapes of MuJoCo geoms: their colours, an archetype per geom type, textured heads.

Also which bodies a recording shows (those with visible geoms) and the static logging of their
shapes, each in its body's frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
import rerun as rr

from .columns import entity

__all__ = [
    "EYE_PARTS",
    "EYE_SCALE",
    "HIDDEN_GEOM_GROUP",
    "RGB_ROLE",
    "WXYZ_TO_XYZW",
    "Bodies",
    "cube_sphere",
    "face_head_mesh",
    "geom_archetype",
    "geom_rgba",
    "log_shapes",
    "visible_bodies",
]

HIDDEN_GEOM_GROUP = 3             # MuJoCo geom group left out of recordings (a user's hidden geoms)
RGB_ROLE = int(mujoco.mjtTextureRole.mjTEXROLE_RGB)
WXYZ_TO_XYZW = np.array([1, 2, 3, 0])  # MuJoCo: (w, x, y, z); Rerun: (x, y, z, w)

#: the eyeballs (sclera, iris, pupil: geoms of an eye body, named ``<side>_eye[_part]``) are
#: drawn this much larger than the model's, about their centre, so that where an agent looks
#: shows at the 3D view's default zoom; the model, its physics and every eye's images keep them
EYE_SCALE = 1.5
EYE_PARTS = ("_eye", "_eye_iris", "_eye_pupil")

_DEFAULT_GEOM_RGBA = (0.5, 0.5, 0.5, 1.0)   # a geom left at this colour shows its material's
_PLANE_HALF_THICKNESS = 0.0025              # a plane becomes a thin box below z = 0 of its frame
_MAX_PLANE_HALF_SIZE = 2.0                  # planes are drawn at most 4 m x 4 m (the view fits it)
_G = mujoco.mjtGeom


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
        tex = int(model.mat_texid[mat, RGB_ROLE])
        if tex >= 0:
            rgba[:3] *= _texture_mean_rgb(model, tex)
    return rgba


def _to_rgba8(rgba) -> np.ndarray:
    return np.round(np.clip(np.asarray(rgba, np.float64), 0.0, 1.0) * 255).astype(np.uint8)


def _rotate(quat_wxyz: np.ndarray, vec) -> np.ndarray:
    out = np.empty(3)
    mujoco.mju_rotVecQuat(out, np.asarray(vec, np.float64), np.asarray(quat_wxyz, np.float64))
    return out


def geom_archetype(model: mujoco.MjModel, g: int, rgba=None, scale: float = 1.0) -> Any | None:
    """A Rerun archetype drawing geom ``g`` in its body's frame (None for height fields, SDFs),
    ``scale`` times its size and its distance from the body's origin.

    Spheres and ellipsoids become Ellipsoids3D, boxes Boxes3D, capsules Capsules3D (which start
    at their translation and extend along +z), cylinders Cylinders3D, planes a thin box whose top
    face is the plane (at most 4 m x 4 m), meshes a Mesh3D with the geom pose baked into the
    vertices.
    """
    t = int(model.geom_type[g])
    size = scale * model.geom_size[g].astype(np.float64)
    pos = scale * model.geom_pos[g].astype(np.float64)
    q_wxyz = model.geom_quat[g].astype(np.float64)
    quat = rr.Quaternion(xyzw=q_wxyz[WXYZ_TO_XYZW])
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
                             colors=[color], fill_mode="solid")
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


def cube_sphere(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
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


def face_head_mesh(model: mujoco.MjModel, g: int, n: int = 12) -> rr.Mesh3D:
    """Static geometry of a textured sphere head in its body's frame (the texture comes later).

    The face image goes on the +x side of the geom, as MuJoCo's cube texture puts it: direction
    (1, u, v) shows image column (u + 1) / 2 (column 0 is the face's own right, -y) and row
    (1 - v) / 2 (row 0 at the top). Other sides map to the image corner, which is plain skin.
    """
    dirs, tris, uv, front = cube_sphere(n)
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


@dataclass
class Bodies:
    """The bodies a recording shows: those with visible geoms (not in group 3, not transparent)."""

    scene_geoms: list[int]            # visible geoms of the world body
    ids: np.ndarray                   # body ids: the agents' in order, then the props
    paths: list[str]                  # entity path of each (/world/<agent>/<body>, /world/props/..)
    geoms_of: dict[int, list[int]]    # body id -> its visible geoms


def visible_bodies(world) -> Bodies:
    """Bodies with visible geoms, their entity paths, and the visible geoms of each."""
    m = world.model
    visible = (m.geom_group != HIDDEN_GEOM_GROUP) & (m.geom_rgba[:, 3] > 0)
    geoms_of: dict[int, list[int]] = {}
    for g in np.flatnonzero(visible):
        geoms_of.setdefault(int(m.geom_bodyid[g]), []).append(int(g))
    scene_geoms = geoms_of.pop(0, [])
    ids, paths = [], []
    for a in world.agents:
        prefix = f"{a.name}/"
        for b in a.body_ids:
            if int(b) in geoms_of:
                ids.append(int(b))
                paths.append(entity("world", a.name, m.body(int(b)).name.removeprefix(prefix)))
    for b in sorted(set(geoms_of) - set(ids)):
        ids.append(b)
        paths.append(entity("world", "props", m.body(b).name or f"body_{b}"))
    return Bodies(scene_geoms, np.array(ids, dtype=np.intp), paths, geoms_of)


def log_shapes(rec: rr.RecordingStream, world, bodies: Bodies,
               textured_heads: bool) -> list[str | None]:
    """Log the static shape of every visible geom (the world body's under /world/scene); return
    each agent's head mesh path (``textured_heads`` and a sphere head), else None."""
    m = world.model
    for g in bodies.scene_geoms:
        shape = geom_archetype(m, g)
        if shape is not None:
            rec.log(entity("world", "scene", m.geom(g).name or f"geom_{g}"), shape, static=True)
    head_of = {int(a.head_geom): i for i, a in enumerate(world.agents)}
    head_paths: list[str | None] = [None] * len(world.agents)
    agent_bodies = {int(b) for a in world.agents for b in a.body_ids}
    for b, path in zip(bodies.ids, bodies.paths):
        prefix = m.body(int(b)).name.split("/")[0] + "/"
        for g in bodies.geoms_of[int(b)]:
            name = m.geom(g).name.removeprefix(prefix) or f"geom_{g}"
            geom_path = f"{path}/{rr.escape_entity_path_part(name)}"
            if textured_heads and g in head_of and m.geom_type[g] == _G.mjGEOM_SPHERE:
                shape = face_head_mesh(m, g)
                head_paths[head_of[g]] = geom_path
            elif name.endswith(EYE_PARTS) and int(b) in agent_bodies:
                shape = geom_archetype(m, g, scale=EYE_SCALE)    # readable at the default zoom
            else:
                shape = geom_archetype(m, g)
            if shape is not None:
                rec.log(geom_path, shape, static=True)
    return head_paths
