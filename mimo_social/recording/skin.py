"""Skin points in a recording: the points of every agent with touch that feel a force.

Each logged row notes which points feel a force (one pass over the touch system's force array);
at flush time they are placed in the world, coloured by the force (yellow 0.01 N -> dark red
10 N, log scale) and summed per agent, for all buffered rows at once.
"""

from __future__ import annotations

import math

import numpy as np
import pyarrow as pa
import rerun as rr

from .columns import (
    COLORS,
    POINTS,
    SCALARS,
    VEC3,
    Rows,
    component_field,
    entity,
    offsets,
    optional_scalars,
)

__all__ = ["SKIN_FORCE_RANGE", "SKIN_POINT_RADIUS", "SkinLog", "force_colors"]

# skin points: colour and radius grow with the force on the point, on a log scale from
# SKIN_FORCE_RANGE[0] (yellow, smallest) to SKIN_FORCE_RANGE[1] newtons (dark red, largest)
SKIN_FORCE_RANGE = (0.01, 10.0)
SKIN_POINT_RADIUS = 0.004                         # metres (one static radius for all points)
_SKIN_STOPS = np.array([0.0, 0.35, 0.7, 1.0])
_SKIN_RGB = np.array([[255, 235, 0], [255, 140, 0], [225, 20, 0], [120, 0, 30]], np.float64)


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


class SkinLog:
    """The skin points with force and the touch totals of the agents with touch.

    ``touch``: the env's shared touch system; ``agents``: the names of all agents (by index).
    :attr:`agents` holds the indices of those with a skin.
    """

    def __init__(self, touch, agents: list[str]):
        self.touch = touch
        self.agents = [i for i, sk in enumerate(touch.skins) if sk is not None]
        # every point's body and local position; agents' points are consecutive slices
        self._body = touch.part_body[touch.point_part]
        self._local32 = touch.points.astype(np.float32)
        bounds = np.array([touch.agent_slices[i] for i in self.agents],
                          dtype=np.intp).reshape(-1, 2)
        self._bounds_flat = bounds.ravel()
        self._mask = np.empty(len(touch.force_normal), dtype=bool)
        self.total_paths = [entity("agents", agents[i], "touch_total") for i in self.agents]
        self.point_paths = [entity("world", agents[i], "skin") for i in self.agents]

    def fields(self) -> list[pa.Field]:
        """Per agent: its touch total (Scalars) and its points' positions and colours."""
        out = []
        s_desc = rr.Scalars.descriptor_scalars()
        for total, points in zip(self.total_paths, self.point_paths):
            out.append(component_field(f"{total}:scalars", total, s_desc, SCALARS))
            for desc, dtype in ((rr.Points3D.descriptor_positions(), POINTS),
                                (rr.Points3D.descriptor_colors(), COLORS)):
                out.append(component_field(f"{points}:{desc.component}", points, desc, dtype))
        return out

    def log_static(self, rec: rr.RecordingStream) -> None:
        """One radius for every skin point (the colour shows the force)."""
        for p in self.point_paths:
            rec.log(p, rr.Points3D.from_fields(radii=[SKIN_POINT_RADIUS]), static=True)

    def note(self, rows: Rows, n: int, xmat: np.ndarray) -> None:
        """Note in row ``n`` the skin points with force of all touch agents (one pass over all
        their points) and the body orientations ``xmat`` (``data.xmat``)."""
        touch = self.touch
        normal = touch.force_normal
        # (a boolean mask first: numpy's nonzero is ~6x faster on booleans than on floats)
        active = np.not_equal(normal, 0.0, out=self._mask).nonzero()[0]
        rows.xmat[n] = xmat
        rows.skin_cuts[n] = active.searchsorted(self._bounds_flat)
        rows.skin_idx.append(active)
        rows.skin_normal.append(normal[active])
        rows.skin_xyz.append(np.take(touch.force_xyz.reshape(-1, 3), active, axis=0))

    def columns(self, rows: Rows) -> list[pa.Array]:
        """Per touch agent: the touch total and the Points3D columns of the buffered rows."""
        n, nbody = rows.n, rows.xpos.shape[1]
        counts = np.fromiter((len(a) for a in rows.skin_idx), dtype=np.intp, count=n)
        idx = np.concatenate(rows.skin_idx)
        row_start = np.zeros(n, dtype=np.intp)
        np.cumsum(counts[:-1], out=row_start[1:])
        # every point in the world frame: xpos + xmat @ local, all points at once (float32)
        flat = np.repeat(np.arange(n) * nbody, counts) + self._body[idx]
        R = np.take(rows.xmat.reshape(-1, 9), flat, axis=0)
        world = np.take(rows.xpos.reshape(-1, 3), flat, axis=0).astype(np.float32)
        local = self._local32[idx]
        x, y, z = local[:, 0], local[:, 1], local[:, 2]
        for k in range(3):
            world[:, k] += R[:, 3 * k] * x + R[:, 3 * k + 1] * y + R[:, 3 * k + 2] * z
        xyz = np.concatenate(rows.skin_xyz)
        colors = force_colors(np.sqrt(np.einsum("ij,ij->i", xyz, xyz)))
        normal = np.concatenate(rows.skin_normal)
        columns = []
        for j in range(len(self.agents)):
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
            offs = offsets(per_row)
            columns += [
                optional_scalars(total, np.ones(n, dtype=bool)),
                pa.ListArray.from_arrays(offs, pa.FixedSizeListArray.from_arrays(
                    pa.array(world[sel].ravel()), type=VEC3), type=POINTS),
                pa.ListArray.from_arrays(offs, pa.array(colors[sel]), type=COLORS)]
        return columns
