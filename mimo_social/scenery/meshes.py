"""Boxes merged into one mesh: what keeps the eyes fast with a furnished room.

The eyes' renderer (software OpenGL) pays a fixed cost for every geom it draws (~0.05 ms per
drawn geom and stereo pair at 64 x 64 px here), far more than for the few triangles of a box.
A crib of 4 posts, 8 rails and 46 slats is 58 geoms; merged per material it is one mesh. So
every piece of furniture is drawn as one mesh per material (:func:`add_box_mesh`), while its
colliding parts stay boxes, invisible (group 3: neither the eyes nor the recorder draw them).

Each box face gets its own four vertices (flat shading) and texture coordinates taken from
its world position (so many texture repeats per metre, like ``texuniform`` boxes).
"""

from __future__ import annotations

import mujoco
import numpy as np

__all__ = ["box_mesh", "add_box_mesh"]


def box_mesh(boxes, repeat: tuple[float, float] = (1.0, 1.0)):
    """Vertices (n, 3), triangles (m, 3) and texture coordinates (n, 2) of ``boxes``, a list
    of (centre (3,), rotation (3, 3), half sizes (3,)) in world coordinates."""
    verts, faces, uv = [], [], []
    corners = ((-1, -1), (1, -1), (1, 1), (-1, 1))
    for c, R, h in boxes:
        c, R, h = np.asarray(c, float), np.asarray(R, float), np.asarray(h, float)
        for axis in range(3):
            a, b = (axis + 1) % 3, (axis + 2) % 3
            for sign in (-1.0, 1.0):
                n0 = len(verts)
                normal = sign * R[:, axis]
                # the two world axes the face lies most along: its texture's u and v
                k = int(np.argmax(np.abs(normal)))
                u_ax, v_ax = [(1, 2), (0, 2), (0, 1)][k]
                for sa, sb in corners:
                    p = np.zeros(3)
                    p[axis], p[a], p[b] = sign * h[axis], sa * h[a], sb * h[b]
                    w = c + R @ p
                    verts.append(w)
                    uv.append((w[u_ax] * repeat[0], w[v_ax] * repeat[1]))
                # counter-clockwise seen from outside: e_a x e_b = e_axis
                tri = ((0, 1, 2), (0, 2, 3)) if sign > 0 else ((0, 2, 1), (0, 3, 2))
                faces += [(n0 + i, n0 + j, n0 + k2) for i, j, k2 in tri]
    return np.array(verts), np.array(faces, dtype=np.int32), np.array(uv)


def add_box_mesh(spec: mujoco.MjSpec, name: str, boxes, material: str | None = None,
                 rgba=None, repeat=(1.0, 1.0), body=None) -> mujoco.MjsGeom:
    """``boxes`` (see :func:`box_mesh`) as one visual mesh geom ``name`` of ``body`` (default
    the world body; coordinates in its frame), which neither collides nor weighs anything, with
    ``material`` (a texture's material; texture coordinates at ``repeat`` per metre) or a plain
    ``rgba``."""
    v, f, uv = box_mesh(boxes, repeat)
    mesh = spec.add_mesh(name=name)
    mesh.uservert = v.ravel().tolist()
    mesh.userface = f.ravel().tolist()
    mesh.usertexcoord = uv.ravel().tolist()
    mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
    g = (body or spec.worldbody).add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_MESH,
                                         meshname=name, density=0.0)
    g.contype = g.conaffinity = 0
    if material is not None:
        g.material = material
    if rgba is not None:
        g.rgba = list(rgba)
    return g
