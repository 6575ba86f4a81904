"""Mass properties and bounds of the body's primitive shapes, as MuJoCo's compiler computes them.

Pure numpy (and :func:`mujoco.mju_eig3` to diagonalise), vectorised over geoms: what an age
change at reset (:mod:`mimo_social.core.regrow`) writes into a compiled model instead of
compiling it again.

- :func:`geom_moments`: each geom's principal moments of inertia in its own frame, from its
  shape, sizes (MuJoCo's half-sizes) and mass: a sphere ``2/5 m r^2``; a cylinder of half-length
  ``h`` ``m (3 r^2 + 4 h^2) / 12`` across and ``m r^2 / 2`` along; a capsule as its cylinder and
  two hemispheres, the mass shared by volume (the caps' moments about the capsule's centre by the
  parallel-axis theorem: ``2/5 m_s r^2 + m_s (H^2/4 + 3 H r / 8)`` across, ``H = 2 h``); a box
  ``m (b^2 + c^2) / 3`` (half-sizes); an ellipsoid ``m (b^2 + c^2) / 5``.
- :func:`body_inertials`: per body, the total mass, the centre of mass and the inertia tensor
  about it in the body frame (each geom's tensor rotated into the body frame, then moved to the
  centre of mass by the parallel-axis theorem: ``I + m (|d|^2 E - d d^T)``), diagonalised:
  ``body_mass``, ``body_ipos``, ``body_iquat``, ``body_inertia``.
- :func:`geom_rbound`, :func:`geom_aabb`: the bounding sphere's radius and the axis-aligned box
  (centre, half-sizes) in the geom's frame; :func:`boxes_in_parent`: such boxes carried into
  the parent frame (a rotated box's axis-aligned bound).
"""

from __future__ import annotations

import mujoco
import numpy as np

__all__ = ["geom_moments", "geom_volumes", "geom_rbound", "geom_aabb", "quat_matrices",
           "body_inertials", "boxes_in_parent", "SPHERE", "CAPSULE", "CYLINDER", "BOX",
           "ELLIPSOID"]

_G = mujoco.mjtGeom
SPHERE, CAPSULE = int(_G.mjGEOM_SPHERE), int(_G.mjGEOM_CAPSULE)
CYLINDER, BOX, ELLIPSOID = int(_G.mjGEOM_CYLINDER), int(_G.mjGEOM_BOX), int(_G.mjGEOM_ELLIPSOID)


def _columns(kind, size):
    kind = np.asarray(kind, dtype=np.intp)
    size = np.asarray(size, dtype=float).reshape(len(kind), 3)
    known = np.isin(kind, (SPHERE, CAPSULE, CYLINDER, BOX, ELLIPSOID))
    if not known.all():
        raise ValueError(f"geom types {sorted(set(kind[~known].tolist()))} not supported; "
                         "allowed: sphere, capsule, cylinder, box, ellipsoid")
    return kind, size, size[:, 0], size[:, 1], size[:, 2]


def geom_volumes(kind, size) -> np.ndarray:
    """Each geom's volume (m^3)."""
    kind, size, a, b, c = _columns(kind, size)
    sphere = 4.0 / 3.0 * np.pi * a ** 3
    tube = np.pi * a * a * 2.0 * b
    return np.select([kind == SPHERE, kind == CAPSULE, kind == CYLINDER, kind == BOX],
                     [sphere, tube + sphere, tube, 8.0 * a * b * c],
                     4.0 / 3.0 * np.pi * a * b * c)


def geom_moments(kind, size, mass) -> np.ndarray:
    """(n, 3) principal moments of inertia of each geom about its centre, in its frame."""
    kind, size, a, b, c = _columns(kind, size)
    m = np.asarray(mass, dtype=float).reshape(len(kind))
    out = np.zeros((len(kind), 3))
    sph = kind == SPHERE
    out[sph] = (0.4 * m[sph] * a[sph] ** 2)[:, None]
    for k in (CYLINDER, CAPSULE):
        sel = kind == k
        r, H, mk = a[sel], 2.0 * b[sel], m[sel]
        if k == CAPSULE:
            vs = 4.0 / 3.0 * np.pi * r ** 3
            vc = np.pi * r * r * H
            ms = mk * vs / (vs + vc)
            mc = mk - ms
        else:
            ms, mc = np.zeros_like(mk), mk
        across = mc * (3.0 * r * r + H * H) / 12.0 + ms * (
            0.4 * r * r + H * H / 4.0 + 3.0 * H * r / 8.0)
        along = mc * r * r / 2.0 + ms * 0.4 * r * r
        out[sel] = np.stack([across, across, along], axis=1)
    for k, div in ((BOX, 3.0), (ELLIPSOID, 5.0)):
        sel = kind == k
        sq = size[sel] ** 2
        out[sel] = m[sel, None] * np.stack([sq[:, 1] + sq[:, 2], sq[:, 0] + sq[:, 2],
                                            sq[:, 0] + sq[:, 1]], axis=1) / div
    return out


def geom_rbound(kind, size) -> np.ndarray:
    """Radius of each geom's bounding sphere about its centre (MuJoCo's ``geom_rbound``)."""
    kind, size, a, b, _ = _columns(kind, size)
    return np.select([kind == SPHERE, kind == CAPSULE, kind == CYLINDER, kind == BOX],
                     [a, a + b, np.sqrt(a * a + b * b), np.linalg.norm(size, axis=1)],
                     size.max(axis=1))


def geom_aabb(kind, size) -> np.ndarray:
    """(n, 6) each geom's axis-aligned box in its own frame: centre (zeros), half-sizes."""
    kind, size, a, b, _ = _columns(kind, size)
    half = size.copy()
    half[kind == SPHERE] = a[kind == SPHERE, None]
    for k, z in ((CAPSULE, a + b), (CYLINDER, b)):
        sel = kind == k
        half[sel] = np.stack([a[sel], a[sel], z[sel]], axis=1)
    return np.concatenate([np.zeros_like(half), half], axis=1)


def quat_matrices(quat) -> np.ndarray:
    """(n, 3, 3) rotation matrices of unit quaternions (w, x, y, z)."""
    q = np.asarray(quat, dtype=float).reshape(-1, 4)
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1),
    ], axis=1)


def boxes_in_parent(aabb, pos, quat) -> np.ndarray:
    """(n, 6) boxes (centre, half-sizes) given in frames at ``pos``/``quat`` of a parent frame,
    as axis-aligned boxes of the parent frame that hold them (rotated boxes' bounds)."""
    aabb = np.asarray(aabb, dtype=float).reshape(-1, 6)
    R = quat_matrices(quat)
    centre = np.asarray(pos, dtype=float).reshape(-1, 3) + np.einsum("nij,nj->ni", R, aabb[:, :3])
    half = np.einsum("nij,nj->ni", np.abs(R), aabb[:, 3:])
    return np.concatenate([centre, half], axis=1)


def body_inertials(body_of_geom, n_bodies: int, mass, pos, quat, moments):
    """Per body (``0 .. n_bodies - 1``) its mass, centre of mass, principal frame and moments
    from its geoms (``body_of_geom``: each geom's body; ``pos``, ``quat``: the geom's frame in
    its body; ``moments``: :func:`geom_moments`).

    Returns ``(mass (B,), ipos (B, 3), iquat (B, 4), inertia (B, 3), tensor (B, 3, 3))``; the
    tensor is the full inertia about the centre of mass in the body frame. A body without mass
    gets zeros and the identity frame."""
    body = np.asarray(body_of_geom, dtype=np.intp)
    m = np.asarray(mass, dtype=float)
    p = np.asarray(pos, dtype=float).reshape(-1, 3)
    R = quat_matrices(quat)
    total = np.bincount(body, weights=m, minlength=n_bodies)
    first = np.zeros((n_bodies, 3))
    np.add.at(first, body, m[:, None] * p)
    safe = np.where(total > 0, total, 1.0)
    com = first / safe[:, None]
    # each geom's tensor in the body frame, moved to the body's centre of mass
    own = np.einsum("nij,nj,nkj->nik", R, np.asarray(moments, dtype=float), R)
    d = p - com[body]
    shift = m[:, None, None] * (np.einsum("ni,ni->n", d, d)[:, None, None] * np.eye(3)
                                - np.einsum("ni,nj->nij", d, d))
    tensor = np.zeros((n_bodies, 3, 3))
    np.add.at(tensor, body, own + shift)
    inertia = np.zeros((n_bodies, 3))
    iquat = np.tile([1.0, 0.0, 0.0, 0.0], (n_bodies, 1))
    vec, q = np.zeros(9), np.zeros(4)
    for b in np.flatnonzero(total > 0):
        mujoco.mju_eig3(inertia[b], vec, q, tensor[b].ravel())
        iquat[b] = q
    return total, com, iquat, inertia, tensor
