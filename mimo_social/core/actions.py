"""An agent's action read and checked: what :meth:`MimoParallelEnv.step` does before it applies
anything.

An agent's action is a ``Box`` of its motor controls, or, when expressions or the voice are on,
a ``Dict`` of

* ``"motors"``: the ``Box`` of motor controls;
* ``"expression"`` (expressions on): ``Discrete(7)``, an id of
  :data:`mimo_social.expressions.faces.EXPRESSIONS`;
* ``"voice"`` (voice on): ``Discrete(6)``, an id of :data:`mimo_social.expressions.voice.SOUNDS`;
* ``"loudness"`` (voice on): ``Box(0, 1, (1,), float32)``, 0 the kind's quietest, 1 its loudest
  (:func:`mimo_social.expressions.voice.level_db`).

Motor values beyond the Box are clipped (by the env); NaN/inf, a wrong shape, wrong keys, an id
out of range or a loudness outside [0, 1] raise a ``ValueError`` naming the agent, the field,
the value and what is allowed.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np
from gymnasium import spaces

from ..expressions.faces import EXPRESSIONS
from ..expressions.voice import SOUNDS
from ..util.checks import number_array, show
from ..util.names import reject_old_names

__all__ = ["action_space", "action_keys", "checked_action", "check_action_keys",
           "expression_id", "voice_id", "loudness_value", "motor_values"]

#: the action dtypes read as they are (the common case: no conversion)
_PLAIN_FLOATS = (np.dtype(np.float32), np.dtype(np.float64))
_INT_SCALARS = frozenset((np.int64, np.int32, np.int16, np.int8, np.uint64, np.uint32,
                          np.uint16, np.uint8))


def action_keys(config) -> frozenset | None:
    """The keys of an agent's Dict action (None: its action is the motor Box itself)."""
    keys = {"motors"}
    if config.expressions:
        keys.add("expression")
    if getattr(config, "voice", False):
        keys |= {"voice", "loudness"}
    return frozenset(keys) if len(keys) > 1 else None


def action_space(config, act) -> spaces.Space:
    """An agent's action space from its config and its actuation model."""
    motors = spaces.Box(act.control_low, act.control_high, dtype=np.float32)
    if action_keys(config) is None:
        return motors
    parts = {"motors": motors}
    if config.expressions:
        parts["expression"] = spaces.Discrete(len(EXPRESSIONS))
    if getattr(config, "voice", False):
        parts["voice"] = spaces.Discrete(len(SOUNDS))
        parts["loudness"] = spaces.Box(0.0, 1.0, (1,), np.float32)
    return spaces.Dict(parts)


def _index(agent: str, field: str, given, names: tuple[str, ...]) -> int:
    """An id 0..len(names) - 1 (an integer, also a numpy or tensor scalar or a 1-element
    array); else a ValueError naming the agent, the field, the value and what is allowed."""
    if type(given) is int or type(given) in _INT_SCALARS:      # the common cases, quickly
        if 0 <= given < len(names):
            return int(given)
    else:
        try:
            e = np.asarray(given)
            ok = e.shape in ((), (1,)) and e.dtype.kind in "iu" \
                and 0 <= int(e.reshape(())) < len(names)
        except Exception:  # noqa: BLE001  (ragged lists, tensors that need grad ...)
            ok = False
        if ok:
            return int(e.reshape(()))
    raise ValueError(f"{agent}: {field}={show(given, 120)} not allowed; allowed: an integer "
                     f"0..{len(names) - 1}: " + ", ".join(f"{k}={n}" for k, n in enumerate(names)))


def expression_id(agent: str, given) -> int:
    """The expression id of an action (:data:`EXPRESSIONS`), else a ValueError."""
    return _index(agent, "expression", given, EXPRESSIONS)


def voice_id(agent: str, given) -> int:
    """The sound kind id of an action (:data:`SOUNDS`), else a ValueError."""
    return _index(agent, "voice", given, SOUNDS)


def loudness_value(agent: str, given) -> float:
    """The loudness of an action: one finite number in [0, 1] (a scalar or a 1-element array),
    else a ValueError naming the agent, the field, the value and what is allowed."""
    allowed = "one number in [0, 1] (0: the kind's quietest, 1: its loudest)"
    v = number_array(given, f"{agent}: action field 'loudness'", allowed)
    if v.size != 1 or not np.isfinite(v).all() or not 0.0 <= float(v.ravel()[0]) <= 1.0:
        raise ValueError(f"{agent}: loudness={show(given, 120)} not allowed; allowed: {allowed}")
    return float(v.ravel()[0])


def checked_action(agent: str, config, act, action):
    """``(expression id or None, (voice id, loudness) or None, motors)`` of an agent's action,
    checked (nothing applied); a ValueError names the agent, the field, the value and what is
    allowed."""
    keys = action_keys(config)
    if keys is None:
        return None, None, motor_values(agent, act, action)
    if not (type(action) is dict and action.keys() == keys) and (
            not isinstance(action, Mapping) or set(action) != keys):
        order = [k for k in ("motors", "expression", "voice", "loudness") if k in keys]
        names = ", ".join(repr(k) for k in order[:-1]) + f" and {order[-1]!r}"
        on = " and ".join(w for w, k in (("expressions are", "expression"), ("voice is", "voice"))
                          if k in keys)
        raise ValueError(f"{agent}: action must be a dict with keys {names} ({on} on), "
                         f"got {show(action, 120)}")
    expression = expression_id(agent, action["expression"]) if "expression" in keys else None
    sound = None
    if "voice" in keys:
        sound = (voice_id(agent, action["voice"]), loudness_value(agent, action["loudness"]))
    return expression, sound, motor_values(agent, act, action["motors"])


def check_action_keys(actions, live: list, known: Mapping, possible: list) -> None:
    """A ValueError unless ``actions`` is a mapping with an action for every live agent
    (actions for agents that ended are allowed and ignored)."""
    if not isinstance(actions, Mapping):
        raise ValueError(f"actions must be a dict agent -> action, got {type(actions).__name__}")
    unknown = [a for a in actions if a not in known]
    if unknown:
        reject_old_names(unknown, possible)
        raise ValueError(f"actions for unknown agent(s) {unknown}; agents: {possible}")
    missing = [a for a in live if a not in actions]
    if missing:
        raise ValueError(f"no action for live agent(s) {missing}; every live agent of "
                         f"{live} needs one")


def motor_values(agent: str, act, motors) -> np.ndarray:
    """The motor commands as a float array of the right shape, finite; else a ValueError
    naming the agent, the field, the value and what is allowed.

    Accepted: anything numpy reads as an array of shape ``(n_controls,)`` of integers or
    floats of any width (Python numbers too, ints beyond 64 bits included) whose values are
    finite in float64. Refused: bools, complex numbers, strings, bytes, dates, masked
    entries, tensors that need a gradient, NaN/inf and values beyond float64.

    What learners send, a float32 or float64 numpy array of the right shape, is checked for
    finite values only (and read, never copied: the caller's array is not written to); the
    rest, and every message, takes the general path."""
    if (type(motors) is np.ndarray and motors.dtype in _PLAIN_FLOATS
            and motors.shape == act.control_low.shape and np.isfinite(motors).all()):
        return motors
    lo = f"{act.control_low.min():g}" if act.n_controls else "-1"
    hi = f"{act.control_high.max():g}" if act.n_controls else "1"
    allowed = (f"allowed: {act.n_controls} finite numbers in [{lo}, {hi}] (motors "
               f"{list(act.control_names)[:4]}{' ...' if act.n_controls > 4 else ''})")
    field = f"{agent}: action field 'motors'"
    u = number_array(motors, field, allowed[len("allowed: "):])
    if u.shape != (act.n_controls,):
        raise ValueError(f"{field} has shape {u.shape}; expected ({act.n_controls},) "
                         f"for motors {act.control_names}")
    if not np.isfinite(u).all():
        bad = [act.control_names[k] for k in np.flatnonzero(~np.isfinite(u))]
        raise ValueError(f"{field} has NaN/inf (or values beyond float64) for {bad}; "
                         f"values must be finite, in [{lo}, {hi}]")
    return u
