"""Starts made once and kept: a :class:`~mimo_social.gpu.task_env.BatchedTaskEnv` with
``reset_bank=K`` resets its finished worlds from ``K`` CPU resets captured up front instead of
resetting a CPU env per finished world (the module docstring of ``task_env`` has the seeds).
"""

from __future__ import annotations

from typing import Callable

__all__ = ["ResetBank"]


class ResetBank:
    """``size`` starts, the ``n``-th from ``capture(first_seed + n)`` (whatever the caller keeps
    of one CPU reset: a snapshot and the task's and partners' draws)."""

    def __init__(self, size: int, capture: Callable[[int], tuple]):
        self.size = int(size)
        self._capture = capture
        self._starts: list[tuple] = []
        self.first_seed: int | None = None

    def fill(self, first_seed: int) -> None:
        """Make the ``size`` starts from seeds ``first_seed`` .. ``first_seed + size - 1``
        (nothing to do when they are already those)."""
        if first_seed == self.first_seed and len(self._starts) == self.size:
            return
        self._starts = [self._capture(s) for s in range(first_seed, first_seed + self.size)]
        self.first_seed = first_seed

    def start(self, n: int) -> tuple:
        """The kept start ``n`` (0 <= n < size)."""
        return self._starts[n]
