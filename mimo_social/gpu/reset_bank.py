"""Starts made once and kept: a :class:`~mimo_social.gpu.task_env.BatchedTaskEnv` with
``reset_bank=K`` resets its finished worlds from ``K`` CPU resets captured up front instead of
resetting a CPU env per finished world (the module docstring of ``task_env`` has the seeds).
The starts live on the device, stacked: a reset copies its worlds' rows there, with no host
stacking and no copy from the host.
"""

from __future__ import annotations

from typing import Callable

from .stacking import stack_rows, take_rows

__all__ = ["ResetBank"]


class ResetBank:
    """``size`` starts, the ``n``-th from ``capture(first_seed + n)`` (whatever the caller keeps
    of one CPU reset: a snapshot and the task's and partners' draws), kept stacked
    (:func:`~mimo_social.gpu.stacking.stack_rows`) and passed once through ``place`` (e.g. to
    the device: :func:`~mimo_social.gpu.stacking.rows_to`; None: kept as numpy)."""

    def __init__(self, size: int, capture: Callable[[int], tuple],
                 place: Callable | None = None):
        self.size = int(size)
        self._capture = capture
        self._place = place if place is not None else (lambda rows: rows)
        self._rows = None
        self.first_seed: int | None = None

    def fill(self, first_seed: int) -> None:
        """Make the ``size`` starts from seeds ``first_seed`` .. ``first_seed + size - 1``
        (nothing to do when they are already those)."""
        if first_seed == self.first_seed and self._rows is not None:
            return
        starts = [self._capture(s) for s in range(first_seed, first_seed + self.size)]
        self._rows = self._place(stack_rows(starts))
        self.first_seed = first_seed

    def rows(self, index):
        """The kept starts ``index`` (an index array or tensor, each 0 <= n < size), stacked:
        each leaf's rows in that order."""
        return take_rows(self._rows, index)
