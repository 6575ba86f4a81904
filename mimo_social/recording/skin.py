"""Skin points in a recording: the points of every agent with touch that feel a force.

Each logged row notes which points feel a force (one pass over the touch system's force array);
at flush time they are placed in the world, coloured and sized by the magnitude of the force
(log scale, :data:`SKIN_FORCE_RANGE`: yellow and 2.5 mm at 0.01 N or less, orange 5 mm at 0.1 N,
red 7.5 mm at 1 N, dark red and 10 mm at 10 N or more) and summed per agent, for all buffered
rows at once. A legend is logged once (static): a colour bar with a dot per decade, coloured,
sized and labelled in newtons, at :data:`SKIN_LEGEND_PATH` (a 2D space), and a short text at
:data:`SKIN_LEGEND_TEXT_PATH` (markdown).
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

__all__ = ["SKIN_FORCE_RANGE", "SKIN_LEGEND_PATH", "SKIN_LEGEND_TEXT_PATH", "SKIN_RADIUS_RANGE",
           "SkinLog", "force_colors", "force_level", "force_radii", "legend_text"]

# skin points: colour and radius grow with the force on the point, on a log scale from
# SKIN_FORCE_RANGE[0] (yellow, smallest) to SKIN_FORCE_RANGE[1] newtons (dark red, largest)
SKIN_FORCE_RANGE = (0.01, 10.0)
SKIN_RADIUS_RANGE = (0.0025, 0.010)               # metres, at the ends of SKIN_FORCE_RANGE
#: the skin-force legend: a 2D space with a colour bar (``bar``, Image), a dot per decade of
#: force (``ticks``, Points2D: coloured and sized like the skin points) and their ``labels``
#: ("0.01 N" ... "10 N", Points2D under the dots)
SKIN_LEGEND_PATH = "/legend/skin_force"
#: the legend's text (TextDocument, markdown): what colour and size say, in newtons
SKIN_LEGEND_TEXT_PATH = "/legend/skin_force_text"
_LEGEND_PX = 256                                  # colour bar height (pixels); 24 wide
RADII = pa.list_(pa.field("item", pa.float32(), nullable=False))
_SKIN_STOPS = np.array([0.0, 0.35, 0.7, 1.0])
_SKIN_RGB = np.array([[255, 235, 0], [255, 140, 0], [225, 20, 0], [120, 0, 30]], np.float64)


def _colour_table(levels: int = 256) -> np.ndarray:
    t = np.linspace(0.0, 1.0, levels)
    c = np.round(np.stack([np.interp(t, _SKIN_STOPS, _SKIN_RGB[:, k]) for k in range(3)],
                          axis=1)).astype(np.uint32)
    return (c[:, 0] << 24) | (c[:, 1] << 16) | (c[:, 2] << 8) | np.uint32(255)


_SKIN_COLOURS = _colour_table()


def force_level(force: np.ndarray) -> np.ndarray:
    """Where ``force`` newtons lie on the legend's log scale: 0 at ``SKIN_FORCE_RANGE[0]`` or
    less, 1 at ``SKIN_FORCE_RANGE[1]`` or more."""
    lo, hi = SKIN_FORCE_RANGE
    t = np.asarray(np.log(np.maximum(np.asarray(force, np.float64), lo) * (1.0 / lo)))
    t *= 1.0 / math.log(hi / lo)
    return np.clip(t, 0.0, 1.0, out=t)


def force_colors(force: np.ndarray) -> np.ndarray:
    """Rerun colours (uint32 0xRRGGBBAA) of skin points feeling ``force`` newtons: yellow at
    ``SKIN_FORCE_RANGE[0]`` or less, through orange and red to dark red at
    ``SKIN_FORCE_RANGE[1]`` or more (log scale, 256 steps)."""
    t = force_level(force)
    t *= len(_SKIN_COLOURS) - 1
    t += 0.5
    return _SKIN_COLOURS.take(t.astype(np.intp))


def force_radii(force: np.ndarray) -> np.ndarray:
    """Radii (metres, float32) of skin points feeling ``force`` newtons: from
    ``SKIN_RADIUS_RANGE[0]`` at ``SKIN_FORCE_RANGE[0]`` or less to ``SKIN_RADIUS_RANGE[1]`` at
    ``SKIN_FORCE_RANGE[1]`` or more, linear in the log of the force."""
    r0, r1 = SKIN_RADIUS_RANGE
    return (r0 + (r1 - r0) * force_level(force)).astype(np.float32)


def _decades() -> np.ndarray:
    lo, hi = SKIN_FORCE_RANGE
    return 10.0 ** np.arange(round(math.log10(lo)), round(math.log10(hi)) + 1)


def legend_text() -> str:
    """The legend's text (markdown): what the colour and the size of a skin point say."""
    names = {0.0: "yellow", 0.35: "orange", 0.7: "red", 1.0: "dark red"}
    rows = []
    for f in _decades():
        t = float(force_level(f))
        name = names[min(names, key=lambda s: abs(s - t))]
        rows.append(f"- **{f:g} N**: {name}, {1e3 * float(force_radii(f)):g} mm")
    lo, hi = SKIN_FORCE_RANGE
    return "\n".join([
        "### Skin forces",
        "Each skin point that feels a force is a dot in the 3D view, **coloured and sized by "
        "the magnitude of the force** on it (log scale; colour, radius):", "", *rows, "",
        f"Forces below {lo:g} N look like {lo:g} N, above {hi:g} N like {hi:g} N. "
        "`touch_total`: the summed normal force on an agent's skin (N)."])


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
        #: the legend's entity paths: the 2D colour bar with its dots, the text
        self.legend_paths = [SKIN_LEGEND_PATH, SKIN_LEGEND_TEXT_PATH]

    def fields(self) -> list[pa.Field]:
        """Per agent: its touch total (Scalars) and its points' positions, colours and radii."""
        out = []
        s_desc = rr.Scalars.descriptor_scalars()
        for total, points in zip(self.total_paths, self.point_paths):
            out.append(component_field(f"{total}:scalars", total, s_desc, SCALARS))
            for desc, dtype in ((rr.Points3D.descriptor_positions(), POINTS),
                                (rr.Points3D.descriptor_colors(), COLORS),
                                (rr.Points3D.descriptor_radii(), RADII)):
                out.append(component_field(f"{points}:{desc.component}", points, desc, dtype))
        return out

    def log_static(self, rec: rr.RecordingStream) -> None:
        """The legend (colour bar, a dot per decade of force, the text), once."""
        h = _LEGEND_PX
        level = np.linspace(1.0, 0.0, h)                       # top row: the largest force
        rgba = _SKIN_COLOURS.take(np.round(level * (len(_SKIN_COLOURS) - 1)).astype(np.intp))
        rgb = np.stack([(rgba >> s) & 0xFF for s in (24, 16, 8)], axis=-1).astype(np.uint8)
        rec.log(f"{SKIN_LEGEND_PATH}/bar", rr.Image(np.repeat(rgb[:, None, :], 24, axis=1)),
                static=True)
        forces = _decades()
        r = 1000.0 * force_radii(forces)                       # a dot's radius: 1 px per mm
        x, y = 24 + 8 + r.max(), (1.0 - force_level(forces)) * (h - 1)
        rec.log(f"{SKIN_LEGEND_PATH}/ticks", rr.Points2D(
            np.stack([np.full(len(forces), x), y], axis=1), radii=r,
            colors=force_colors(forces)), static=True)
        # the labels under the dots, in dark grey (a label takes its point's colour)
        rec.log(f"{SKIN_LEGEND_PATH}/labels", rr.Points2D(
            np.stack([np.full(len(forces), x), y + r + 4], axis=1), radii=0.5,
            colors=[(60, 60, 60)], labels=[f"{f:g} N" for f in forces], show_labels=True),
            static=True)
        rec.log(SKIN_LEGEND_TEXT_PATH, rr.TextDocument(legend_text(),
                                                       media_type=rr.MediaType.MARKDOWN),
                static=True)

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
        magnitude = np.sqrt(np.einsum("ij,ij->i", xyz, xyz))
        colors, radii = force_colors(magnitude), force_radii(magnitude)
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
                pa.ListArray.from_arrays(offs, pa.array(colors[sel]), type=COLORS),
                pa.ListArray.from_arrays(offs, pa.array(radii[sel]), type=RADII)]
        return columns
