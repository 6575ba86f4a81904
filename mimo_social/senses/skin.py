"""The skin of one infant: sensor points over every body part and their surface neighbourhoods.

Built once per (geometry, spacing, density, excluded parts) and kept in memory and on disk.

Points
    Every collidable primitive of a body part (sphere, capsule, cylinder, box, ellipsoid) is
    covered evenly at the part's spacing ``s = published spacing / sqrt(density)``, about one
    point per ``s**2`` of surface (the published head, a sphere: 404 points; this rule: 402):
    Fibonacci lattices on spheres and hemispherical caps, staggered rings on tubes, sunflower
    spirals on discs, cell-centred grids on box faces, farthest-point sampling on ellipsoids.
    A primitive too small for its spacing (the eyes: spacing 1 m) gets one point. The primitives
    of a part are merged: points inside another primitive of the same part are removed, and of
    two points closer than ``0.4 s`` (where primitives meet) the later one. Each point has a
    position and an outward unit normal in the frame of its body part. Nothing is random: the
    same inputs give the same points, bit for bit.

Neighbourhoods (no bleed-through)
    The points of a part form a graph: two points are joined when they are closer than ``1.6 s``
    and their normals differ by less than ~127 degrees (so the two faces of a thin part, whose
    normals are opposite, are never joined directly). Distances over this graph approximate
    distances over the skin surface. For every point, the points within ``3 s`` over the graph
    (Dijkstra, ``scipy.sparse.csgraph``) are its neighbourhood, stored sorted by that distance
    (the point itself first) in padded ``(n, K)`` arrays. At run time a contact's force is only
    ever spread over the neighbourhood of the skin point nearest to it, so it cannot reach the
    far side of a thin part.

Lookup grid (finding the point nearest to a contact)
    Each part also gets a regular grid in its body frame (cells of ``s / 2``, reaching ``1.5 s``
    beyond its points) holding, per cell, the point nearest to the cell's centre. At run time a
    contact, moved ``s / 2`` outward along its normal (so that on a thin part it lands on the
    touched side), is looked up in the grid with a few array operations for all contacts at once.

Scaled bodies
    A body ``scale`` times the infant's size (``AgentConfig.scale``) has every length and every
    spacing times ``scale``: its skin is the infant's skin, scaled. It is computed (and cached) on
    the unit body (sizes, positions and spacings divided by ``scale``, read back to 10 significant
    digits, which recovers the published table values exactly) and its points and distances are
    then multiplied by ``scale``: every scale has the same points per part, bit for bit the same
    choices, and shares one cache entry.

Cache
    The arrays are saved as ``<sha1>.npz`` under ``$MIMO_SOCIAL_CACHE/skin/`` (default
    ``~/.cache/mimo_social/skin/``); the key hashes this module's algorithm version, the geometry
    of every skinned primitive (type, size, placement in its body), the spacings and the density.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import mujoco
import numpy as np

# scipy (k-d trees, Dijkstra) is imported where a skin is computed: a cached skin needs none of it

__all__ = ["Skin", "build_skin", "surface_points", "signed_distance", "cache_dir",
           "SKIN_ALGORITHM_VERSION", "EDGE_FACTOR", "REACH_FACTOR", "MERGE_FACTOR", "GRID_CELL",
           "GRID_MARGIN"]

SKIN_ALGORITHM_VERSION = 2
EDGE_FACTOR = 1.6        # graph edges join points closer than this many spacings
REACH_FACTOR = 3.0       # neighbourhood: points within this many spacings over the graph
MERGE_FACTOR = 0.4       # of two points of a part closer than this many spacings, drop one
MIN_NORMAL_COS = -0.6    # graph edges only between points whose normals agree this much
GRID_CELL = 0.5          # lookup grid: cell edge in spacings
GRID_MARGIN = 1.5        # lookup grid: reaches this many spacings beyond the points
GOLDEN_ANGLE = np.pi * (3.0 - np.sqrt(5.0))

_G = mujoco.mjtGeom
SHAPES = {int(_G.mjGEOM_SPHERE): "sphere", int(_G.mjGEOM_CAPSULE): "capsule",
          int(_G.mjGEOM_CYLINDER): "cylinder", int(_G.mjGEOM_BOX): "box",
          int(_G.mjGEOM_ELLIPSOID): "ellipsoid"}


# -- points on one primitive (geom frame) -------------------------------------------------------
def _count(area: float, s: float) -> int:
    return max(1, int(round(area / (s * s))))


def _fibonacci(n: int, z_lo: float = -1.0) -> np.ndarray:
    """``n`` unit vectors spread evenly over the sphere zone ``z >= z_lo`` (Fibonacci lattice)."""
    k = np.arange(n) + 0.5
    z = 1.0 - (1.0 - z_lo) * k / n
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    phi = GOLDEN_ANGLE * np.arange(n)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def _tube(r: float, h: float, s: float, min_rings: int) -> tuple[np.ndarray, np.ndarray]:
    """Staggered rings on the side of a cylinder of radius r from z=-h to z=h."""
    n_around = max(3, int(round(2 * np.pi * r / s)))
    n_rings = max(min_rings, int(round(2 * h / s)))
    if n_rings == 0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    z = -h + (np.arange(n_rings) + 0.5) * (2 * h / n_rings)
    phi = (np.arange(n_around)[None, :] + 0.5 * (np.arange(n_rings) % 2)[:, None]) \
        * (2 * np.pi / n_around)
    zz = np.broadcast_to(z[:, None], phi.shape)
    normals = np.stack([np.cos(phi), np.sin(phi), np.zeros_like(phi)], -1).reshape(-1, 3)
    points = np.stack([r * np.cos(phi), r * np.sin(phi), zz], -1).reshape(-1, 3)
    return points, normals


def _disc(r: float, s: float) -> np.ndarray:
    """Points spread over a disc of radius r in the plane z=0 (sunflower spiral)."""
    n = _count(np.pi * r * r, s)
    if n == 1:
        return np.zeros((1, 3))
    rho = r * np.sqrt((np.arange(n) + 0.5) / n)
    phi = GOLDEN_ANGLE * np.arange(n)
    return np.stack([rho * np.cos(phi), rho * np.sin(phi), np.zeros(n)], axis=1)


def _box(half: np.ndarray, s: float) -> tuple[np.ndarray, np.ndarray]:
    pts, nrm = [], []
    for axis in range(3):
        u, v = [a for a in range(3) if a != axis]
        nu = max(1, int(round(2 * half[u] / s)))
        nv = max(1, int(round(2 * half[v] / s)))
        cu = -half[u] + (np.arange(nu) + 0.5) * (2 * half[u] / nu)
        cv = -half[v] + (np.arange(nv) + 0.5) * (2 * half[v] / nv)
        gu, gv = np.meshgrid(cu, cv, indexing="ij")
        for sign in (1.0, -1.0):
            p = np.zeros((gu.size, 3))
            p[:, axis] = sign * half[axis]
            p[:, u] = gu.ravel()
            p[:, v] = gv.ravel()
            n = np.zeros_like(p)
            n[:, axis] = sign
            pts.append(p)
            nrm.append(n)
    return np.concatenate(pts), np.concatenate(nrm)


def _ellipsoid(abc: np.ndarray, s: float) -> tuple[np.ndarray, np.ndarray]:
    a, b, c = abc
    p = 1.6075  # Knud Thomsen's approximation of the surface area
    area = 4 * np.pi * (((a * b) ** p + (a * c) ** p + (b * c) ** p) / 3) ** (1 / p)
    n = _count(area, s)
    if n == 1:
        return np.array([[a, 0.0, 0.0]]), np.array([[1.0, 0.0, 0.0]])
    cand = _fibonacci(max(20 * n, 2000)) * abc
    chosen = np.empty(n, dtype=np.intp)  # farthest-point sampling: even spacing on the surface
    chosen[0] = 0
    dmin = np.linalg.norm(cand - cand[0], axis=1)
    for k in range(1, n):
        chosen[k] = int(np.argmax(dmin))
        np.minimum(dmin, np.linalg.norm(cand - cand[chosen[k]], axis=1), out=dmin)
    pts = cand[chosen]
    nrm = pts / (abc * abc)
    return pts, nrm / np.linalg.norm(nrm, axis=1, keepdims=True)


def surface_points(shape: str, size: Sequence[float], s: float) -> tuple[np.ndarray, np.ndarray]:
    """Points (n, 3) and outward unit normals (n, 3) spread over one primitive, in its frame.

    ``size`` follows MuJoCo: sphere (r), capsule and cylinder (r, half-length along z),
    box (half-extents), ellipsoid (semi-axes).
    """
    size = np.asarray(size, dtype=float)
    if shape == "sphere":
        r = size[0]
        n = _count(4 * np.pi * r * r, s)
        u = np.array([[1.0, 0.0, 0.0]]) if n == 1 else _fibonacci(n)
        return r * u, u.copy()
    if shape == "capsule":
        r, h = size[0], size[1]
        side, side_n = _tube(r, h, s, 0)
        u = _fibonacci(_count(2 * np.pi * r * r, s), 0.0)
        top = r * u + [0.0, 0.0, h]
        bottom = r * u * [1.0, 1.0, -1.0] - [0.0, 0.0, h]
        return (np.concatenate([side, top, bottom]),
                np.concatenate([side_n, u, u * [1.0, 1.0, -1.0]]))
    if shape == "cylinder":
        r, h = size[0], size[1]
        side, side_n = _tube(r, h, s, 1)
        d = _disc(r, s)
        caps = np.concatenate([d + [0.0, 0.0, h], d - [0.0, 0.0, h]])
        caps_n = np.concatenate([np.tile([0.0, 0.0, 1.0], (len(d), 1)),
                                 np.tile([0.0, 0.0, -1.0], (len(d), 1))])
        return np.concatenate([side, caps]), np.concatenate([side_n, caps_n])
    if shape == "box":
        return _box(size[:3], s)
    if shape == "ellipsoid":
        return _ellipsoid(size[:3], s)
    raise ValueError(f"no skin for geom shape {shape!r}; allowed: {sorted(set(SHAPES.values()))}")


def signed_distance(shape: str, size: Sequence[float], q: np.ndarray) -> np.ndarray:
    """Signed distance of points ``q`` (n, 3, primitive frame) to a primitive (< 0 inside)."""
    size = np.asarray(size, dtype=float)
    if shape == "sphere":
        return np.linalg.norm(q, axis=1) - size[0]
    if shape == "capsule":
        c = np.zeros_like(q)
        c[:, 2] = np.clip(q[:, 2], -size[1], size[1])
        return np.linalg.norm(q - c, axis=1) - size[0]
    if shape == "cylinder":
        d = np.stack([np.hypot(q[:, 0], q[:, 1]) - size[0], np.abs(q[:, 2]) - size[1]], axis=1)
        return (np.minimum(d.max(axis=1), 0.0)
                + np.linalg.norm(np.maximum(d, 0.0), axis=1))
    if shape == "box":
        d = np.abs(q) - size[:3]
        return np.minimum(d.max(axis=1), 0.0) + np.linalg.norm(np.maximum(d, 0.0), axis=1)
    if shape == "ellipsoid":
        abc = size[:3]
        k0 = np.linalg.norm(q / abc, axis=1)
        k1 = np.linalg.norm(q / (abc * abc), axis=1)
        return np.where(k1 > 0, k0 * (k0 - 1.0) / np.maximum(k1, 1e-300), -abc.min())
    raise ValueError(f"no signed distance for shape {shape!r}")


# -- one body part ---------------------------------------------------------------------------
def _quat_mat(q) -> np.ndarray:
    m = np.empty(9)
    mujoco.mju_quat2Mat(m, np.asarray(q, dtype=float))
    return m.reshape(3, 3)


def _part_points(geoms: list[tuple[str, np.ndarray, np.ndarray, np.ndarray]], s: float):
    """Merged points, normals and primitive index of one part from (shape, size, pos, quat)."""
    frames = [(shape, size, pos, _quat_mat(quat)) for shape, size, pos, quat in geoms]
    pts, nrm, src = [], [], []
    for g, (shape, size, pos, R) in enumerate(frames):
        p, n = surface_points(shape, size, s)
        p = p @ R.T + pos
        n = n @ R.T
        keep = np.ones(len(p), bool)
        for h, (shape2, size2, pos2, R2) in enumerate(frames):
            if h != g:  # drop points inside another primitive of the same part
                keep &= signed_distance(shape2, size2, (p - pos2) @ R2) >= -1e-9
        pts.append(p[keep])
        nrm.append(n[keep])
        src.append(np.full(int(keep.sum()), g, dtype=np.int16))
    P, N, S = np.concatenate(pts), np.concatenate(nrm), np.concatenate(src)
    from scipy.spatial import cKDTree
    if len(P) > 1:  # where primitives meet, points of both can crowd: keep the first of a pair
        pairs = cKDTree(P).query_pairs(MERGE_FACTOR * s, output_type="ndarray")
        if len(pairs):
            drop = np.zeros(len(P), bool)
            for i, j in pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]:
                if not drop[i] and not drop[j]:
                    drop[j] = True
            P, N, S = P[~drop], N[~drop], S[~drop]
    N = N / np.linalg.norm(N, axis=1, keepdims=True)
    return P, N, S


def _neighbourhoods(P: np.ndarray, N: np.ndarray, s: float):
    """Per point: indices (n, K) and graph distances (n, K) of the points within reach over the
    skin, sorted by distance, padded with the point itself at distance inf."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra
    from scipy.spatial import cKDTree

    n = len(P)
    reach = REACH_FACTOR * s
    if n == 1:
        return np.zeros((1, 1), np.int32), np.zeros((1, 1), np.float32)
    pairs = cKDTree(P).query_pairs(EDGE_FACTOR * s, output_type="ndarray")
    if len(pairs):
        i, j = pairs[:, 0], pairs[:, 1]
        ok = np.einsum("ij,ij->i", N[i], N[j]) > MIN_NORMAL_COS
        i, j = i[ok], j[ok]
        w = np.linalg.norm(P[i] - P[j], axis=1)
    else:
        i = j = np.zeros(0, np.intp)
        w = np.zeros(0)
    graph = coo_matrix((w, (i, j)), shape=(n, n)).tocsr()
    rows, cols, dist = [], [], []
    chunk = max(1, int(4_000_000 // n))
    for start in range(0, n, chunk):
        src = np.arange(start, min(n, start + chunk))
        D = dijkstra(graph, directed=False, indices=src, limit=reach)
        r, c = np.nonzero(D <= reach)
        rows.append(src[r])
        cols.append(c)
        dist.append(D[r, c])
    rows, cols, dist = np.concatenate(rows), np.concatenate(cols), np.concatenate(dist)
    order = np.lexsort((cols, dist, rows))  # by row, then distance (self first), then index
    rows, cols, dist = rows[order], cols[order], dist[order]
    counts = np.bincount(rows, minlength=n)
    K = int(counts.max())
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    slot = np.arange(len(rows)) - start[rows]
    nbr = np.repeat(np.arange(n, dtype=np.int32)[:, None], K, axis=1)
    nd = np.full((n, K), np.inf, np.float32)
    nbr[rows, slot] = cols
    nd[rows, slot] = dist
    return nbr, nd


def _grid(P: np.ndarray, s: float):
    """Nearest point (local index) of every cell centre of a grid around the points.

    Returns the flat cell array (int32, C order), its lower corner in spacings, and its shape."""
    from scipy.spatial import cKDTree

    lo = P.min(0) / s - GRID_MARGIN
    dims = np.ceil((P.max(0) / s + GRID_MARGIN - lo) / GRID_CELL).astype(np.int64) + 1
    centres = lo + (np.indices(dims).reshape(3, -1).T + 0.5) * GRID_CELL
    _, idx = cKDTree(P / s).query(centres)
    return idx.astype(np.int32), lo, dims


# -- one infant ------------------------------------------------------------------------------
@dataclass
class Skin:
    """The skin of one infant: points of all its skinned parts, part after part.

    Positions and normals are in each part's body frame; ``nbr`` indexes this skin's points.
    """

    part_names: list[str]       # unprefixed body names, model body order
    part_bodies: np.ndarray     # (P,) model body ids
    part_spacing: np.ndarray    # (P,) spacing in m (published / sqrt(density))
    part_start: np.ndarray      # (P + 1,) first point of each part (and the total)
    part_geoms: list[np.ndarray]  # model geom ids of each part's skinned primitives
    points: np.ndarray          # (n, 3) body frame
    normals: np.ndarray         # (n, 3) body frame, unit, outward
    point_part: np.ndarray      # (n,) part index
    point_geom: np.ndarray      # (n,) model geom id the point lies on
    nbr: np.ndarray             # (n, K) int32 neighbour point indices (padded with self)
    nbr_dist: np.ndarray        # (n, K) float32 distance over the skin (inf = padding)
    grid: np.ndarray            # (cells,) int32 nearest point of each lookup-grid cell
    grid_start: np.ndarray      # (P + 1,) first cell of each part's grid
    grid_lo: np.ndarray         # (P, 3) lower grid corner of each part, in its spacings
    grid_dims: np.ndarray       # (P, 3) grid shape of each part
    from_cache: str             # "memory", "disk" or "" (built now)
    build_seconds: float

    @property
    def n_points(self) -> int:
        return len(self.points)

    def counts(self) -> dict[str, int]:
        return {name: int(self.part_start[k + 1] - self.part_start[k])
                for k, name in enumerate(self.part_names)}


_MEMORY: dict[str, dict] = {}


def cache_dir() -> Path:
    root = os.environ.get("MIMO_SOCIAL_CACHE")
    base = Path(root) if root else Path.home() / ".cache" / "mimo_social"
    return base / "skin"


def _unit(values, scale: float) -> np.ndarray:
    """Lengths of a body ``scale`` times the infant's, brought back to the infant's size.

    Dividing ``v * scale`` by ``scale`` lands within an ulp or two of ``v``; the published table
    values have at most 6 significant digits, so reading the quotient back to 10 significant
    digits gives ``v`` exactly (and the same rounding decisions in the point layout)."""
    values = np.asarray(values, dtype=float)
    if scale == 1.0:
        return values.copy()
    return np.array([float(f"{v / scale:.10g}") for v in values.ravel()]).reshape(values.shape)


def _skin_parts(model, body_ids, prefix: str, spacing: Mapping[str, float], exclude,
                scale: float = 1.0):
    """(name, body id, published spacing, [(geom id, shape, size, pos, quat)]) per skinned part,
    lengths of the unit body (divided by ``scale``)."""
    parts = []
    for b in body_ids:
        name = model.body(int(b)).name
        name = name[len(prefix):] if name.startswith(prefix) else name
        if name in exclude:
            continue
        geoms = []
        for g in range(model.body_geomadr[b], model.body_geomadr[b] + model.body_geomnum[b]):
            t = int(model.geom_type[g])
            if t not in SHAPES or not (model.geom_contype[g] or model.geom_conaffinity[g]):
                continue
            geoms.append((g, SHAPES[t], _unit(model.geom_size[g], scale),
                          _unit(model.geom_pos[g], scale), model.geom_quat[g].copy()))
        if not geoms:
            continue
        if name not in spacing:
            raise ValueError(f"touch: body part {name!r} has no skin spacing in the touch "
                             f"spacing table (known: {sorted(spacing)})")
        parts.append((name, int(b), float(_unit([spacing[name]], scale)[0]), geoms))
    return parts


def _key(parts, density: float) -> str:
    h = hashlib.sha1()
    h.update(f"skin v{SKIN_ALGORITHM_VERSION} {EDGE_FACTOR} {REACH_FACTOR} {MERGE_FACTOR} "
             f"{MIN_NORMAL_COS} {GRID_CELL} {GRID_MARGIN} density {float(density)!r}".encode())
    for name, _, sp, geoms in parts:
        h.update(f"|{name} {sp!r}".encode())
        for _, shape, size, pos, quat in geoms:
            h.update(shape.encode())
            h.update(np.round(np.concatenate([size, pos, quat]), 10).tobytes())
    return h.hexdigest()


_ARRAYS = ("points", "normals", "point_part", "geom_local", "nbr", "nbr_dist", "counts",
           "grid", "grid_counts", "grid_lo", "grid_dims")


def _compute(parts, density: float) -> dict:
    pts, nrm, part_of, geom_local, nbrs, dists, counts = [], [], [], [], [], [], []
    grids, grid_lo, grid_dims = [], [], []
    offset = 0
    for k, (name, _, sp, geoms) in enumerate(parts):
        s = sp / np.sqrt(density)
        P, N, S = _part_points([(g[1], g[2], g[3], g[4]) for g in geoms], s)
        nb, nd = _neighbourhoods(P, N, s)
        cells, lo, dims = _grid(P, s)
        grids.append(cells + offset)
        grid_lo.append(lo)
        grid_dims.append(dims)
        pts.append(P)
        nrm.append(N)
        part_of.append(np.full(len(P), k, np.int32))
        geom_local.append(S)
        nbrs.append(nb + offset)
        dists.append(nd)
        counts.append(len(P))
        offset += len(P)
    K = max(nb.shape[1] for nb in nbrs)   # pad every part to the widest neighbourhood
    nbr = np.concatenate([np.pad(nb, ((0, 0), (0, K - nb.shape[1]))) for nb in nbrs])
    nd = np.concatenate([np.pad(d, ((0, 0), (0, K - d.shape[1])), constant_values=np.inf)
                         for d in dists])
    pad = ~np.isfinite(nd)
    nbr[pad] = np.nonzero(pad)[0]          # a padded slot names the point itself
    return {"points": np.concatenate(pts), "normals": np.concatenate(nrm),
            "point_part": np.concatenate(part_of), "geom_local": np.concatenate(geom_local),
            "nbr": nbr.astype(np.int32), "nbr_dist": nd.astype(np.float32),
            "counts": np.array(counts, np.int64),
            "grid": np.concatenate(grids).astype(np.int32),
            "grid_counts": np.array([len(g) for g in grids], np.int64),
            "grid_lo": np.array(grid_lo), "grid_dims": np.array(grid_dims, np.int64)}


def _load(path: Path, part_geom_counts: Sequence[int]) -> dict | None:
    """The cached arrays, or None (computed again, and the file rewritten) when the file is
    missing, unreadable, of another layout, or a valid archive whose arrays do not fit
    together or this body (lengths, index ranges, finite values: see :func:`_consistent`)."""
    try:
        with np.load(path) as z:
            arrays = {k: z[k] for k in _ARRAYS}
    except Exception:  # missing, unreadable or from another layout: compute it again
        return None
    try:
        ok = _consistent(arrays, np.asarray(part_geom_counts, np.int64))
    except (ValueError, TypeError, IndexError):
        ok = False
    return arrays if ok else None


def _consistent(a: dict, n_geoms: np.ndarray) -> bool:
    """Whether cached skin arrays describe a skin of parts with ``n_geoms`` geoms each: every
    length agrees with the per-part point counts, every index points inside its range (points
    of their own part for the grid), positions and normals are finite."""
    n_parts = len(n_geoms)
    ints = ("counts", "point_part", "geom_local", "nbr", "grid", "grid_counts", "grid_dims")
    if any(a[k].dtype.kind not in "iu" for k in ints):
        return False
    counts = a["counts"]
    if counts.shape != (n_parts,) or (counts < 0).any():
        return False
    n = int(counts.sum())
    starts = np.concatenate([[0], np.cumsum(counts)])
    if a["points"].shape != (n, 3) or a["normals"].shape != (n, 3):
        return False
    if not (np.isfinite(a["points"]).all() and np.isfinite(a["normals"]).all()):
        return False
    part = a["point_part"]
    if not np.array_equal(part, np.repeat(np.arange(n_parts), counts)):
        return False
    local = a["geom_local"]
    if local.shape != (n,) or (n and ((local < 0).any() or (local >= n_geoms[part]).any())):
        return False
    nbr, dist = a["nbr"], a["nbr_dist"]
    if nbr.ndim != 2 or nbr.shape[0] != n or dist.shape != nbr.shape:
        return False
    if n and ((nbr < 0).any() or (nbr >= n).any() or np.isnan(dist).any()):
        return False
    cells, dims = a["grid_counts"], a["grid_dims"]
    if cells.shape != (n_parts,) or dims.shape != (n_parts, 3) \
            or a["grid_lo"].shape != (n_parts, 3):
        return False
    if (dims < 1).any() or not np.array_equal(cells, dims.prod(axis=1)):
        return False
    grid = a["grid"]
    if grid.shape != (int(cells.sum()),):
        return False
    owner = np.repeat(np.arange(n_parts), cells)
    return not grid.size or bool(((grid >= starts[owner]) & (grid < starts[owner + 1])).all())


def _save(path: Path, arrays: dict) -> None:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
        with os.fdopen(fd, "wb") as f:
            np.savez(f, **arrays)
        os.replace(tmp, path)
    except OSError as e:
        warnings.warn(f"touch: could not write the skin cache {path}: {e}", stacklevel=3)


def build_skin(model: mujoco.MjModel, body_ids: Sequence[int], prefix: str,
               spacing: Mapping[str, float], density: float = 1.0,
               exclude: Sequence[str] = (), cache: bool = True, scale: float = 1.0) -> Skin:
    """The skin of one infant (its bodies ``body_ids``, names prefixed ``prefix``).

    ``spacing``: point spacing (m) per unprefixed body name (the body's own: the published one
    times ``scale``); ``density`` multiplies the point density (spacing / sqrt(density));
    ``exclude``: body parts without skin; ``cache``: read and write the disk cache (the
    in-process memory cache is always used); ``scale``: the body's size factor (its tables'
    ``scale``): the skin is laid out on the unit body and scaled (see the module docstring).
    """
    t0 = time.perf_counter()
    scale = float(scale)
    if not scale > 0:
        raise ValueError(f"build_skin: scale={scale!r}; allowed: a positive size factor")
    parts = _skin_parts(model, body_ids, prefix, spacing, set(exclude), scale)
    key = _key(parts, density)
    source = ""
    arrays = _MEMORY.get(key)
    if arrays is not None:
        source = "memory"
    else:
        path = cache_dir() / f"{key}.npz"
        if cache:
            arrays = _load(path, [len(geoms) for _, _, _, geoms in parts])
            if arrays is not None:
                source = "disk"
        if arrays is None:
            arrays = _compute(parts, density)
            if cache:
                _save(path, arrays)
        for a in arrays.values():
            a.setflags(write=False)
        _MEMORY[key] = arrays
    counts = arrays["counts"]
    part_geoms = [np.array([g[0] for g in geoms], dtype=np.intp) for _, _, _, geoms in parts]
    point_geom = np.concatenate([part_geoms[k][arrays["geom_local"][arrays["point_part"] == k]]
                                 for k in range(len(parts))]) if parts else np.zeros(0, np.intp)
    points, nbr_dist = arrays["points"], arrays["nbr_dist"]
    if scale != 1.0:  # the unit body's skin, scaled (grid corners are in spacings: unchanged)
        points, nbr_dist = points * scale, nbr_dist * np.float32(scale)
        points.setflags(write=False)
        nbr_dist.setflags(write=False)
    return Skin(
        part_names=[p[0] for p in parts],
        part_bodies=np.array([p[1] for p in parts], dtype=np.intp),
        part_spacing=np.array([p[2] * scale / np.sqrt(density) for p in parts]),
        part_start=np.concatenate([[0], np.cumsum(counts)]).astype(np.intp),
        part_geoms=part_geoms,
        points=points, normals=arrays["normals"],
        point_part=arrays["point_part"].astype(np.intp), point_geom=point_geom,
        nbr=arrays["nbr"], nbr_dist=nbr_dist, grid=arrays["grid"],
        grid_start=np.concatenate([[0], np.cumsum(arrays["grid_counts"])]).astype(np.intp),
        grid_lo=arrays["grid_lo"], grid_dims=arrays["grid_dims"],
        from_cache=source, build_seconds=time.perf_counter() - t0,
    )
