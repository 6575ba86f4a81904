"""Captured starts as rows: what one CPU reset leaves for a world (a
:meth:`~mimo_social.gpu.batched.BatchedEnv.snapshot`, the task's and the partners' draws: dicts,
lists and tuples of arrays and numbers, None where an agent has nothing) stacked leaf by leaf
into one structure of ``(k, ...)`` arrays, so that loading ``k`` worlds copies one array per
leaf; carried to the device once and indexed there (:class:`~mimo_social.gpu.reset_bank.ResetBank`),
the rows of a reset never pass through the host.
"""

from __future__ import annotations

import numpy as np

__all__ = ["stack_rows", "rows_to", "take_rows"]


def stack_rows(items: list):
    """``k`` structures of the same shape -> one with each leaf stacked ``(k, ...)`` (numpy);
    a leaf None in every item stays None."""
    first = items[0]
    if isinstance(first, dict):
        return {key: stack_rows([it[key] for it in items]) for key in first}
    if isinstance(first, (list, tuple)):
        return type(first)(stack_rows([it[n] for it in items]) for n in range(len(first)))
    if first is None:
        if any(it is not None for it in items):
            raise ValueError("a leaf is None in some captures and not in others")
        return None
    return np.stack([np.asarray(it) for it in items])


def rows_to(rows, torch, device):
    """Stacked rows (:func:`stack_rows`) as torch tensors on ``device`` (same structure)."""
    if isinstance(rows, dict):
        return {key: rows_to(v, torch, device) for key, v in rows.items()}
    if isinstance(rows, (list, tuple)):
        return type(rows)(rows_to(v, torch, device) for v in rows)
    return None if rows is None else torch.as_tensor(rows, device=device)


def take_rows(rows, index):
    """The rows ``index`` (an index array or tensor) of every leaf (same structure)."""
    if isinstance(rows, dict):
        return {key: take_rows(v, index) for key, v in rows.items()}
    if isinstance(rows, (list, tuple)):
        return type(rows)(take_rows(v, index) for v in rows)
    return None if rows is None else rows[index]
