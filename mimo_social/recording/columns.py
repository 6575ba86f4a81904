"""Arrow columns that Rerun reads as components, and the buffer of rows between two flushes.

A recording is sent as Arrow record batches whose fields carry Rerun's metadata (entity path,
archetype, component); these helpers build those fields and the list columns of them.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pyarrow as pa
import rerun as rr

__all__ = [
    "BLOBS",
    "BYTES",
    "COLORS",
    "POINTS",
    "QUAT",
    "SCALARS",
    "SIM_TIME",
    "STEP",
    "TEXTS",
    "VEC3",
    "Rows",
    "blob_values",
    "component_field",
    "entity",
    "index_columns",
    "index_fields",
    "offsets",
    "optional_scalars",
    "sparse_column",
]

SIM_TIME = "sim_time"
STEP = "step"

VEC3 = pa.list_(pa.field("item", pa.float32(), nullable=False), 3)
QUAT = pa.list_(pa.field("item", pa.float32(), nullable=False), 4)
SCALARS = pa.list_(pa.field("item", pa.float64(), nullable=False))
POINTS = pa.list_(pa.field("item", VEC3, nullable=False))
COLORS = pa.list_(pa.field("item", pa.uint32(), nullable=False))
BYTES = pa.list_(pa.field("item", pa.uint8(), nullable=False))
BLOBS = pa.list_(pa.field("item", BYTES, nullable=False))
TEXTS = pa.list_(pa.field("item", pa.utf8(), nullable=False))


def entity(*parts: str) -> str:
    """The entity path of ``parts``, each escaped."""
    return "/" + "/".join(rr.escape_entity_path_part(p) for p in parts)


def component_field(name: str, path: str, descriptor, dtype: pa.DataType) -> pa.Field:
    """An Arrow field that Rerun reads as ``descriptor`` of the entity at ``path``."""
    return pa.field(name, dtype, metadata={
        rr.SORBET_ENTITY_PATH: path.encode(),
        rr.SORBET_ARCHETYPE_NAME: descriptor.archetype.encode(),
        rr.SORBET_COMPONENT: descriptor.component.encode(),
        rr.SORBET_COMPONENT_TYPE: descriptor.component_type.encode()})


def _index_field(name: str, dtype: pa.DataType) -> pa.Field:
    return pa.field(name, dtype, nullable=False, metadata={
        rr.SORBET_INDEX_NAME: name.encode(), rr.RERUN_KIND: rr.RERUN_KIND_INDEX})


def index_fields() -> list[pa.Field]:
    """The two index fields every batch starts with: ``sim_time`` and ``step``."""
    return [_index_field(SIM_TIME, pa.duration("ns")), _index_field(STEP, pa.int64())]


def index_columns(times, steps) -> list[pa.Array]:
    """The ``sim_time`` (seconds, stored as ns) and ``step`` columns of a batch."""
    ns = np.round(np.asarray(times, dtype=np.float64) * 1e9).astype(np.int64)
    return [pa.array(ns, pa.duration("ns")), pa.array(np.asarray(steps, dtype=np.int64))]


def optional_scalars(values: np.ndarray, present: np.ndarray) -> pa.ListArray:
    """A Scalars column: one value per row where ``present``, no data (a null row) elsewhere.

    ``values`` must own its memory (Arrow wraps contiguous numpy arrays without copying).
    """
    if present.all():
        offs = np.arange(len(values) + 1, dtype=np.int32)
        return pa.ListArray.from_arrays(pa.array(offs), pa.array(values), type=SCALARS)
    offs = np.zeros(len(values) + 1, dtype=np.int32)
    np.cumsum(present, out=offs[1:])
    return pa.ListArray.from_arrays(pa.array(offs), pa.array(values[present]), type=SCALARS,
                                    mask=pa.array(~present))


def offsets(counts) -> pa.Array:
    """List offsets (int32) of lists with ``counts`` items."""
    out = np.zeros(len(counts) + 1, dtype=np.int32)
    np.cumsum(counts, out=out[1:])
    return pa.array(out)


def sparse_column(items: list, values: pa.Array, dtype: pa.DataType) -> pa.ListArray:
    """A component column with one instance per row where ``items`` is not None and no data (a
    null row) elsewhere; ``values`` holds the instances of the rows with data, in row order."""
    present = np.array([x is not None for x in items], dtype=bool)
    return pa.ListArray.from_arrays(offsets(present), values, type=dtype,
                                    mask=None if present.all() else pa.array(~present))


def blob_values(blobs: list[bytes]) -> pa.ListArray:
    """Byte strings as Rerun blobs (lists of uint8), one per entry."""
    data = np.frombuffer(b"".join(blobs), dtype=np.uint8)
    return pa.ListArray.from_arrays(offsets([len(b) for b in blobs]), pa.array(data), type=BYTES)


class Rows:
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
