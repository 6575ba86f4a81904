"""Infos as numbers: every agent's infos as one fixed set of floats, the same keys at reset and at
every step, for clients that turn infos into tensors (TorchRL's ``PettingZooWrapper``).

The envs of this package return such infos by default; made with ``info_text=True`` they return
their text infos instead (strings, lists, nested dicts: ``expression`` by name, the reason of an
``instability``, the ``touch`` parts, a task's ``target_part``). :class:`InfoEncoder` turns the
text infos into numbers from a spec per agent (``env.info_spec(agent)``: key -> kind):

* ``"number"``: ``float(value)`` (bools 0/1);
* ``"flag"``: 1 when the key is there and true, else 0 (``instability``);
* ``"count"``: the length of a list (``touched_parts``), 0 for None;
* a tuple of strings: the index of the string in it (``expression``, ``target_part``), -1 for
  None or a string not in the tuple;
* ``"touch"``: ``key/parts``, ``key/self``, ``key/agents``, ``key/object``: how many body parts
  are touched, by the agent itself, by other agents, by objects;
* a dict sub-key -> kind: ``key/sub-key`` for each (a nested dict flattened).

A declared key missing from an info (task keys at reset) reads ``missing`` (default 0). Keys
nobody declared are dropped; with ``strict=True`` they, and strings not in their tuple, raise a
ValueError naming the agent and the key.
"""

from __future__ import annotations

from typing import Any, Mapping

__all__ = ["InfoEncoder", "INFO_KINDS", "TOUCH_COUNTS", "check_info_spec"]

#: the kinds of an info key besides a tuple of strings and a dict of sub-keys
INFO_KINDS = ("number", "flag", "count", "touch")
#: the numbers a ``"touch"`` info becomes (``touch/parts`` ...)
TOUCH_COUNTS = ("parts", "self", "agents", "object")


class InfoEncoder:
    """Text infos -> numeric infos, from ``specs`` (agent -> its spec, key -> kind)."""

    def __init__(self, specs: Mapping[str, Mapping[str, Any]], missing: float = 0.0,
                 strict: bool = False):
        self.missing = float(missing)
        self.strict = bool(strict)
        self.specs = {}
        for agent, spec in specs.items():
            check_info_spec(agent, spec)
            self.specs[agent] = dict(spec)
        # per agent a flat plan: (output key, top key, sub-key or None, kind, lookup)
        self._plans = {a: tuple(_plan(spec)) for a, spec in self.specs.items()}
        self._keys = {a: tuple(self.encode(a, {})) for a in self.specs}

    def keys(self, agent) -> tuple[str, ...]:
        """The keys of ``agent``'s numeric infos, in order."""
        return self._keys[agent]

    def encode_all(self, infos: Mapping[str, Any]) -> dict:
        """Every agent's infos encoded (an agent without a spec keeps its infos)."""
        return {a: (self.encode(a, i) if a in self.specs else i) for a, i in infos.items()}

    def encode(self, agent: str, info: Mapping[str, Any]) -> dict[str, float]:
        """``agent``'s text info as numbers (the keys of :meth:`keys`, in that order)."""
        spec = self.specs[agent]
        if not self.strict:
            return self._fast(agent, info)
        undeclared = sorted(set(info) - set(spec))
        if undeclared:
            raise ValueError(f"{agent}: info key(s) {undeclared} not declared by the env's "
                             f"info_spec (declared: {sorted(spec)})")
        out: dict[str, float] = {}
        for key, kind in spec.items():
            self._put(agent, key, kind, key in info, info.get(key), out)
        return out

    def _fast(self, agent: str, info: Mapping[str, Any]) -> dict[str, float]:
        """:meth:`encode` without the strict checks, from the agent's flat plan (the encoder
        runs at every step of every env)."""
        out: dict[str, float] = {}
        missing = self.missing
        for name, key, sub, kind, lookup in self._plans[agent]:
            value = info.get(key)
            if sub is not None:
                value = value.get(sub) if isinstance(value, Mapping) else None
            if kind == "number":
                out[name] = missing if value is None else float(value)
            elif kind == "index":
                out[name] = lookup.get(value, -1.0) if isinstance(value, str) else -1.0
            elif kind == "flag":
                out[name] = 0.0 if value is None or value is False else 1.0
            elif kind == "count":
                out[name] = 0.0 if value is None else float(len(value))
            else:   # touch
                self._put(agent, key, "touch", value is not None, value, out)
        return out

    def _put(self, agent, key, kind, present, value, out):
        strict = self.strict
        if isinstance(kind, Mapping):
            sub = value if present and isinstance(value, Mapping) else {}
            if strict and present and (not isinstance(value, Mapping) or set(sub) - set(kind)):
                raise ValueError(f"{agent}: info {key!r} = {value!r:.120} does not fit its "
                                 f"declared keys {sorted(kind)}")
            for k, sub_kind in kind.items():
                self._put(agent, f"{key}/{k}", sub_kind, k in sub, sub.get(k), out)
        elif isinstance(kind, tuple):
            idx = kind.index(value) if present and value in kind else -1
            if strict and present and value is not None and idx < 0:
                raise ValueError(f"{agent}: info {key!r} = {value!r:.120} is not one of its "
                                 f"declared values {list(kind)}")
            out[key] = float(idx)
        elif kind == "flag":
            out[key] = 1.0 if present and value is not None and value is not False else 0.0
        elif kind == "count":
            out[key] = float(len(value)) if present and value is not None else 0.0
        elif kind == "touch":
            parts = value if present and isinstance(value, Mapping) else {}
            counts = dict.fromkeys(TOUCH_COUNTS, 0.0)
            for who in parts.values():
                counts["parts"] += 1.0
                counts["self"] += float(bool(who.get("self")))
                counts["agents"] += float(bool(who.get("agents")))
                counts["object"] += float(bool(who.get("object")))
            out.update({f"{key}/{c}": n for c, n in counts.items()})
        elif not present or value is None:
            out[key] = self.missing
        else:
            try:
                out[key] = float(value)
            except (TypeError, ValueError):
                raise ValueError(f"{agent}: info {key!r} = {value!r:.120} is declared a number "
                                 "but is not one") from None


def _plan(spec: Mapping[str, Any], top: str | None = None, prefix: str = ""):
    """(output key, top key, sub-key or None, kind, lookup) per number of a spec, in order."""
    for key, kind in spec.items():
        name = prefix + key
        outer, sub = (key, None) if top is None else (top, key)
        if isinstance(kind, Mapping):
            if top is not None:
                raise TypeError(f"info_spec {name}: dicts nest one level deep")
            yield from _plan(kind, key, f"{name}/")
        elif isinstance(kind, tuple):
            yield name, outer, sub, "index", {v: float(i) for i, v in enumerate(kind)}
        else:
            yield name, outer, sub, kind, None


def check_info_spec(agent: str, spec: Mapping[str, Any], prefix: str = "") -> None:
    """A TypeError naming the agent and the key unless every kind of ``spec`` is allowed."""
    for key, kind in spec.items():
        if isinstance(kind, Mapping):
            check_info_spec(agent, kind, f"{prefix}{key}/")
        elif isinstance(kind, tuple):
            if not all(isinstance(v, str) for v in kind):
                raise TypeError(f"{agent}: info_spec {prefix}{key}: a tuple of kinds must hold "
                                f"strings, got {kind!r}")
        elif kind not in INFO_KINDS:
            raise TypeError(f"{agent}: info_spec {prefix}{key}: kind {kind!r} not allowed; "
                            f"allowed: {list(INFO_KINDS)}, a tuple of strings or a dict")
