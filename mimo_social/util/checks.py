"""Checks of user-given values whose errors say who owns the setting, what was given and what is
allowed. Every config, task option and partner setting of the package goes through these."""

from __future__ import annotations

import math
import numbers
from typing import Any, Sequence

import numpy as np

__all__ = ["ConfigError", "check_number", "check_int", "check_bool", "check_choice"]


class ConfigError(ValueError):
    """A configuration key or value that is not allowed."""


def _who(owner: str) -> str:
    """``"owner: "``, or nothing for an empty owner (the caller names it)."""
    return f"{owner}: " if owner else ""


def _range_text(lo, hi, what: str) -> str:
    if lo is None and hi is None:
        return f"any finite {what}"
    if hi is None:
        return f"{what} >= {lo:g}"
    if lo is None:
        return f"{what} <= {hi:g}"
    return f"{what} from {lo:g} to {hi:g}"


def check_number(owner: str, name: str, value: Any, lo: float | None = None,
                 hi: float | None = None) -> float:
    """``value`` as a float if it is a finite real number (not a bool) in [lo, hi], else a
    :class:`ConfigError` naming the owner (agent, task, partner; an empty owner: the caller
    names it), the setting and the range."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real) \
            or not math.isfinite(value) or (lo is not None and value < lo) \
            or (hi is not None and value > hi):
        raise ConfigError(f"{_who(owner)}{name}={value!r} not allowed; allowed: "
                          f"{_range_text(lo, hi, 'a number')}")
    return float(value)


def check_int(owner: str, name: str, value: Any, lo: int | None = None,
              hi: int | None = None) -> int:
    """``value`` as an int if it is an integer (not a bool) in [lo, hi], else a ConfigError."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral) \
            or (lo is not None and value < lo) or (hi is not None and value > hi):
        raise ConfigError(f"{_who(owner)}{name}={value!r} not allowed; allowed: "
                          f"{_range_text(lo, hi, 'an integer')}")
    return int(value)


def check_bool(owner: str, name: str, value: Any) -> bool:
    """``value`` if it is a bool (numpy's too), else a ConfigError (truthy strings are not)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ConfigError(f"{_who(owner)}{name}={value!r} not allowed; allowed: True or False")
    return bool(value)


def check_choice(owner: str, name: str, value: Any, allowed: Sequence) -> Any:
    """``value`` if it is one of ``allowed``, else a ConfigError listing them."""
    try:
        ok = value in allowed
    except TypeError:  # an unhashable value against a set
        ok = False
    if not ok:
        raise ConfigError(f"{_who(owner)}{name}={value!r} not allowed; allowed: {list(allowed)}")
    return value
