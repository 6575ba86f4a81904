"""A skin carried onto the same body at another age: the same points, moved with their
primitives (an age change at reset, :mod:`mimo_social.core.regrow`; no new layout, so the touch
observation keeps its size)."""

from __future__ import annotations

import mujoco
import numpy as np

from ..body.inertia import CAPSULE, CYLINDER, SPHERE, quat_matrices
from .skin import GRID_CELL, GRID_MARGIN, Skin

__all__ = ["regrown_skin"]


def regrown_skin(skin: Skin, model: mujoco.MjModel, old_size: np.ndarray,
                 old_pos: np.ndarray, spacing_ratio: np.ndarray,
                 part_factors: np.ndarray) -> Skin:
    """``skin`` carried onto the same body at another age (its geoms resized in ``model``;
    ``old_size``, ``old_pos``: every geom's size and position before), with the same points:
    the observation keeps its size.

    Each point moves with its primitive, in the primitive's frame: a sphere's by the ratio of
    radii; a cylinder's across by the radii's ratio and along by the half-lengths'; a capsule's
    tube likewise and its caps rigidly with the radius (the caps stay hemispheres on the new
    tube's ends); a box's and an ellipsoid's axis by axis. Normals follow by the inverse
    transpose of each point's map, renormalised. Each part's spacing and its neighbourhoods'
    distances are multiplied by ``spacing_ratio`` (per part). Each part's lookup grid is laid
    out around the moved points and takes, per cell, the point of the old grid's cell at the
    place the part's own map (``part_factors``: per part the x, y, z length ratios of its
    segment frame) brings it back to (no nearest-neighbour search: a few milliseconds); probed
    at each point half a spacing outward, as a contact is, it gives the point itself or one
    within about a spacing of it (tests/core/test_age_change.py). A skin laid out afresh on
    the new body may have a few points more or fewer (the layout rounds point counts per
    primitive)."""
    g = skin.point_geom
    kind = model.geom_type[g]
    R = quat_matrices(model.geom_quat)[g]
    q = np.einsum("nji,nj->ni", R, skin.points - old_pos[g])
    a, b = old_size[g], model.geom_size[g]
    ratio = np.divide(b, a, out=np.ones_like(b), where=a > 0)
    lin = ratio.copy()                                  # the map's diagonal, per point
    sph = kind == SPHERE
    lin[sph] = ratio[sph, :1]
    tube = (kind == CAPSULE) | (kind == CYLINDER)
    lin[tube, 1] = ratio[tube, 0]
    lin[tube, 2] = ratio[tube, 1]
    new_q = q * lin
    cap = (kind == CAPSULE) & (np.abs(q[:, 2]) > a[:, 1])
    if cap.any():   # the caps keep their shape: their offset beyond the tube's end by radius
        h0, h1, rr = a[cap, 1], b[cap, 1], ratio[cap, 0]
        z = q[cap, 2]
        new_q[cap, 2] = np.sign(z) * (h1 + (np.abs(z) - h0) * rr)
        lin[cap, 2] = rr
    points = np.einsum("nij,nj->ni", R, new_q) + model.geom_pos[g]
    local_n = np.einsum("nji,nj->ni", R, skin.normals) / lin
    normals = np.einsum("nij,nj->ni", R, local_n)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    spacing = skin.part_spacing * spacing_ratio
    grids, los, dims = [], [], []
    old_start = skin.grid_start
    for k in range(len(skin.part_names)):
        P = points[skin.part_start[k]:skin.part_start[k + 1]]
        s_new, s_old = spacing[k], skin.part_spacing[k]
        lo = P.min(0) / s_new - GRID_MARGIN
        dim = np.ceil((P.max(0) / s_new + GRID_MARGIN - lo) / GRID_CELL).astype(np.int64) + 1
        # each new cell's centre (metres), brought back by the part's map, in old cells
        axes = [(lo[d] + (np.arange(dim[d]) + 0.5) * GRID_CELL) * s_new / part_factors[k, d]
                for d in range(3)]
        old_lo, old_dim = skin.grid_lo[k], skin.grid_dims[k]
        idx = [np.clip(np.floor((axes[d] / s_old - old_lo[d]) / GRID_CELL), 0,
                       old_dim[d] - 1).astype(np.intp) for d in range(3)]
        plane = (idx[0][:, None] * (old_dim[1] * old_dim[2]) + idx[1][None, :] * old_dim[2]
                 + old_start[k]).ravel()
        flat = np.add.outer(plane, idx[2]).ravel()
        grids.append(np.take(skin.grid, flat))
        los.append(lo)
        dims.append(dim)
    nbr_dist = skin.nbr_dist * spacing_ratio.astype(np.float32)[skin.point_part][:, None]
    return Skin(
        part_names=list(skin.part_names), part_bodies=skin.part_bodies, part_spacing=spacing,
        part_start=skin.part_start, part_geoms=skin.part_geoms, points=points, normals=normals,
        point_part=skin.point_part, point_geom=skin.point_geom, nbr=skin.nbr, nbr_dist=nbr_dist,
        grid=np.concatenate(grids),
        grid_start=np.concatenate([[0], np.cumsum([len(c) for c in grids])]).astype(np.intp),
        grid_lo=np.array(los), grid_dims=np.array(dims, np.int64), from_cache="regrown",
        build_seconds=0.0)
