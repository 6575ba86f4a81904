"""``ExpressionShow``: a scripted partner that shows facial expressions, one after another.

It keeps its motors at rest (zero commands: the spring-damper motors give no torque, muscles no
activation) and changes its face at random moments: each expression is held for a time drawn
uniformly from ``hold_s`` seconds, and the next one is drawn at random among the others (never
the same twice in a row). It acts only through its agent's action space, so the agent must have
expressions on (a ``Dict(motors, expression)`` action).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
from gymnasium import spaces

from ..expressions.faces import EXPRESSIONS
from ..util.checks import ConfigError, check_numbers, show
from .base import Partner, zero_action

__all__ = ["ExpressionShow", "expression_ids", "hold_range"]


def hold_range(hold_s, who: str) -> tuple[float, float]:
    """Validate a ``(min, max)`` hold time in seconds."""
    allowed = "(min, max) seconds, 0 < min <= max <= 3600"
    lo, hi = check_numbers(who, "hold_s", hold_s, 2, 0.0, 3600.0, allowed)
    if not 0.0 < lo <= hi:
        raise ConfigError(f"{who}: hold_s={show(hold_s)} not allowed; allowed: {allowed}")
    return lo, hi


def expression_ids(expressions: Sequence | None, who: str = "ExpressionShow") -> np.ndarray:
    """Ids of ``expressions`` (names from :data:`EXPRESSIONS` or ids); ``None``: all seven."""
    allowed = f"names {list(EXPRESSIONS)} or ids 0..{len(EXPRESSIONS) - 1}"
    if expressions is None:
        return np.arange(len(EXPRESSIONS))
    if isinstance(expressions, (str, bytes)) or not isinstance(expressions, Sequence):
        raise ConfigError(f"{who}: expressions={show(expressions)} not allowed; allowed: a list "
                          f"of {allowed}")
    ids = []
    for e in expressions:
        if isinstance(e, str) and e in EXPRESSIONS:
            ids.append(EXPRESSIONS.index(e))
        elif (isinstance(e, (int, np.integer)) and not isinstance(e, bool)
              and 0 <= e < len(EXPRESSIONS)):
            ids.append(int(e))
        else:
            raise ConfigError(f"{who}: expressions={show(expressions)}: unknown expression "
                              f"{show(e)}; allowed: {allowed}")
    ids = sorted(set(ids))
    if len(ids) < 2:
        raise ValueError(f"{who}: expressions={expressions!r} gives {len(ids)} distinct "
                         "expression(s); at least 2 are needed (it never shows one twice in a row)")
    return np.array(ids)


class ExpressionShow(Partner):
    """Shows expressions (by default all seven) for random times drawn from ``hold_s`` seconds.

    ``current``: the id of the expression shown (index into :data:`EXPRESSIONS`),
    ``current_name`` its name; both are set at ``reset`` (the first expression is drawn at
    random, not neutral by rule) and change only in ``act``.
    """

    def __init__(self, hold_s=(1.0, 2.0), expressions: Sequence | None = None):
        self.hold_s = hold_range(hold_s, "ExpressionShow")
        self.expressions = expression_ids(expressions)
        self.current: int | None = None
        self._left = 0
        self._action = None

    @property
    def current_name(self) -> str | None:
        return None if self.current is None else EXPRESSIONS[self.current]

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        space = env.action_space(agent)
        if not (isinstance(space, spaces.Dict) and "expression" in space.spaces):
            raise ValueError(f"ExpressionShow acts through the expression, but {agent}'s action "
                             f"space has none ({space}); build the env with expressions=True")
        self._dt = float(env.dt)
        self._action = zero_action(space)
        self.current = int(rng.choice(self.expressions))
        self._left = self._hold_steps()

    def _hold_steps(self) -> int:
        return max(1, int(round(self.rng.uniform(*self.hold_s) / self._dt)))

    def act(self, env, agent, observation):
        if self._action is None:
            raise RuntimeError("ExpressionShow.act() before reset(); reset the env first")
        if self._left <= 0:
            others = self.expressions[self.expressions != self.current]
            self.current = int(self.rng.choice(others))
            self._left = self._hold_steps()
        self._left -= 1
        return {"motors": self._action["motors"].copy(), "expression": np.int64(self.current)}

    def __repr__(self) -> str:
        names = [EXPRESSIONS[i] for i in self.expressions]
        return f"ExpressionShow(hold_s={self.hold_s}, expressions={names})"
