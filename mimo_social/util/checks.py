"""Checks of user-given values whose errors say who owns the setting, what was given and what is
allowed. Every config, task option and partner setting of the package goes through these."""

from __future__ import annotations

import math
import numbers
from typing import Any, Mapping, Sequence

import numpy as np

__all__ = ["number_array", "ConfigError", "check_number", "check_int", "check_bool", "check_choice",
           "check_numbers", "check_names", "check_seed"]


class ConfigError(ValueError):
    """A configuration key or value that is not allowed."""


def _who(owner: str) -> str:
    """``"owner: "``, or nothing for an empty owner (the caller names it)."""
    return f"{owner}: " if owner else ""


def show(value: Any, limit: int = 80) -> str:
    """``repr(value)``, shortened in the middle past ``limit`` characters (for error messages);
    never an error itself (an object whose repr raises is shown by its type)."""
    try:
        text = repr(value)
    except Exception:  # noqa: BLE001
        text = f"<{type(value).__name__} without a repr>"
    if len(text) <= limit:
        return text
    return text[: limit // 2] + " ... " + text[-limit // 2 + 5:]


def _range_text(lo, hi, what: str) -> str:
    if lo is None and hi is None:
        return {"a number": "any finite number", "an integer": "any integer",
                "numbers": "finite numbers"}.get(what, what)
    if hi is None:
        return f"{what} >= {_num(lo)}"
    if lo is None:
        return f"{what} <= {_num(hi)}"
    return f"{what} from {_num(lo)} to {_num(hi)}"


def _num(x) -> str:
    """A bound as written: integers whole (10000, not 1e+04), floats short (0.0001)."""
    return str(x) if isinstance(x, numbers.Integral) else f"{x:g}"


def _finite_real(value: Any) -> bool:
    """A real number (numpy's too) that is not a bool, NaN or infinite (nor too large for a
    float)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:   # an int beyond a float's range
        return False


def check_number(owner: str, name: str, value: Any, lo: float | None = None,
                 hi: float | None = None, why: str = "") -> float:
    """``value`` as a float if it is a finite real number (not a bool) in [lo, hi], else a
    :class:`ConfigError` naming the owner (agent, task, partner; an empty owner: the caller
    names it), the setting and the range (``why``: said after the range)."""
    if not _finite_real(value) or (lo is not None and value < lo) \
            or (hi is not None and value > hi):
        raise ConfigError(f"{_who(owner)}{name}={show(value)} not allowed; allowed: "
                          f"{_range_text(lo, hi, 'a number')}" + (f" ({why})" if why else ""))
    return float(value)


def check_int(owner: str, name: str, value: Any, lo: int | None = None,
              hi: int | None = None, why: str = "") -> int:
    """``value`` as an int if it is an integer (not a bool) in [lo, hi], else a ConfigError
    (``why``: said after the range)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral) \
            or (lo is not None and value < lo) or (hi is not None and value > hi):
        raise ConfigError(f"{_who(owner)}{name}={show(value)} not allowed; allowed: "
                          f"{_range_text(lo, hi, 'an integer')}" + (f" ({why})" if why else ""))
    return int(value)


def check_bool(owner: str, name: str, value: Any) -> bool:
    """``value`` if it is a bool (numpy's too), else a ConfigError (truthy strings are not)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ConfigError(f"{_who(owner)}{name}={show(value)} not allowed; allowed: True or False")
    return bool(value)


def check_choice(owner: str, name: str, value: Any, allowed: Sequence) -> Any:
    """``value`` if it is one of ``allowed``, else a ConfigError listing them."""
    try:
        ok = bool(value in allowed)
    except (TypeError, ValueError):  # an unhashable value against a set, an array's ambiguity
        ok = False
    if not ok:
        raise ConfigError(f"{_who(owner)}{name}={show(value)} not allowed; allowed: {list(allowed)}")
    return value


def _is_sequence(value: Any) -> bool:
    """A list, tuple or 1-D array (not a string, bytes or mapping)."""
    if isinstance(value, np.ndarray):
        return value.ndim == 1
    return isinstance(value, Sequence) and not isinstance(value, (str, bytes, Mapping))


def check_numbers(owner: str, name: str, value: Any, n: int, lo: float | None = None,
                  hi: float | None = None, allowed: str = "") -> tuple[float, ...]:
    """``value`` as a tuple of ``n`` floats if it is a sequence (list, tuple, 1-D array) of
    ``n`` finite real numbers in [lo, hi], else a ConfigError; ``allowed`` says what the numbers
    mean (default: "n numbers ...")."""
    what = allowed or f"{n} {_range_text(lo, hi, 'numbers')}"
    if not _is_sequence(value) or len(value) != n \
            or not all(_finite_real(v) and (lo is None or v >= lo) and (hi is None or v <= hi)
                       for v in value):
        raise ConfigError(f"{_who(owner)}{name}={show(value)} not allowed; allowed: {what}")
    return tuple(float(v) for v in value)


def check_names(owner: str, name: str, value: Any, what: str = "names",
                empty: bool = True) -> tuple[str, ...]:
    """``value`` as a tuple of distinct strings if it is a sequence of them (a lone string is
    not: it would be read letter by letter), else a ConfigError; ``empty``: whether none is
    allowed."""
    if not _is_sequence(value) or not all(isinstance(v, str) for v in value) \
            or len(set(value)) != len(value) or (not empty and not len(value)):
        raise ConfigError(f"{_who(owner)}{name}={show(value)} not allowed; allowed: a list of "
                          f"{'' if empty else 'one or more '}distinct {what}")
    return tuple(str(v) for v in value)


def check_seed(value: Any, owner: str = "") -> int | None:
    """A reset seed: None (fresh entropy) or a non-negative integer (numpy's too; not a bool,
    a float or a numeric string), returned as an int; else a ConfigError naming ``seed``."""
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral) \
            or value < 0:
        raise ConfigError(f"{_who(owner)}seed={show(value)} not allowed; allowed: None or an "
                          f"integer >= 0")
    return int(value)


def number_array(value: Any, field: str, allowed: str) -> np.ndarray:
    """``value`` (an action, say) as a float64 array of any shape, else a ValueError
    ``"<field> = <value> ...; allowed: <allowed>"`` (``field`` names the owner too, e.g.
    ``"infant_0: action field 'motors'"``).

    Numbers are anything numpy reads as integers or floats of any width (Python ints beyond 64
    bits too); values beyond float64 become inf (the caller decides about non-finite values).
    Refused: bools, complex numbers, strings, bytes, dates, objects, ragged lists, masked
    entries, tensors that need a gradient."""
    if isinstance(value, np.ma.MaskedArray) and np.ma.is_masked(value):
        raise ValueError(f"{field} = {show(value)} has masked entries; allowed: {allowed}")
    try:
        raw = np.asarray(value)
    except Exception as e:  # noqa: BLE001  (ragged lists, tensors that need grad ...)
        raise ValueError(f"{field} = {show(value)} is not an array of numbers "
                         f"({type(e).__name__}: {e}); allowed: {allowed}") from None
    if raw.dtype.kind == "O" and all(
            isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))
            for v in raw.flat):
        values = []          # Python ints beyond 64 bits (and the like) are numbers all the same
        for v in raw.flat:
            try:
                values.append(float(v))
            except OverflowError:                   # beyond float64: not finite
                values.append(math.inf if v > 0 else -math.inf)
        raw = np.array(values, dtype=np.float64).reshape(raw.shape)
    if raw.dtype.kind not in "iuf":
        raise ValueError(f"{field} = {show(value)} has {raw.dtype} values, not numbers; "
                         f"allowed: {allowed}")
    with np.errstate(over="ignore", invalid="ignore"):   # longdouble beyond float64: inf
        return raw.astype(np.float64)
