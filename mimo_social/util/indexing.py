"""Index arrays as slices where they can be: a contiguous run of ids reads and writes MuJoCo's
arrays as a view (no gather, no scatter), several times cheaper per call than fancy indexing."""

from __future__ import annotations

import numpy as np

__all__ = ["as_slice"]


def as_slice(ids) -> slice | np.ndarray:
    """``ids`` (integers) as ``slice(first, last + 1)`` when they are consecutive and
    increasing, else as an intp array; either indexes an array to the same values."""
    ids = np.asarray(ids, dtype=np.intp).ravel()
    if len(ids) and np.array_equal(ids, np.arange(ids[0], ids[0] + len(ids))):
        return slice(int(ids[0]), int(ids[0]) + len(ids))
    return ids
