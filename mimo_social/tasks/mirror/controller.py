"""``MirrorController``: the scripted solution of the mirror task (an oracle baseline).

reads:
    each step, from the world: the face the other agent shows now (``env.world.expression_of``;
    duck-typed, any env whose world tells the faces)
acts:
    shows that face through its own ``expression`` action; its motors (if any) at rest; it writes no
    state
timing:
    it reads the partner's face before the partner acts on the same step, so it copies with a lag of
    one control step: it misses one step per change of the partner's face (about 99 % of the steps
    matched with the default ``ExpressionShow``, a new face every 1-2 s)

``MirrorController(face=...)`` with a fixed ``face`` (a name of
:data:`~mimo_social.expressions.faces.EXPRESSIONS` or an id) is the "always the same face" hack
instead: it ignores the partner (``MirrorController(face="neutral")`` is the zero action).
Measured success on ``mirror_v0``: see the task's table.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from ...expressions.faces import EXPRESSIONS
from ...partners.base import Partner, agent_index, zero_action

__all__ = ["MirrorController"]


class MirrorController(Partner):
    """Show the face the partner shows (see the module table); ``partner``: the other agent's
    name (default: the first other agent of the env); ``face``: a fixed face instead (a hack
    policy that ignores the partner)."""

    def __init__(self, partner: str | None = None, face: str | int | None = None):
        if partner is not None and not isinstance(partner, str):
            raise ValueError(f"MirrorController: partner={partner!r}; allowed: None or an "
                             "agent's name")
        if face is not None:
            if isinstance(face, str) and face in EXPRESSIONS:
                face = EXPRESSIONS.index(face)
            elif not (isinstance(face, (int, np.integer)) and not isinstance(face, bool)
                      and 0 <= face < len(EXPRESSIONS)):
                raise ValueError(f"MirrorController: face={face!r}; allowed: None, names "
                                 f"{list(EXPRESSIONS)} or ids 0..{len(EXPRESSIONS) - 1}")
            face = int(face)
        self.partner = partner
        self.face = face
        self._action = None

    def __repr__(self):
        return f"MirrorController(partner={self.partner!r}, face={self.face!r})"

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        space = env.action_space(agent)
        if not (isinstance(space, spaces.Dict) and "expression" in space.spaces):
            raise ValueError(f"MirrorController acts through the expression, but {agent}'s "
                             f"action space has none ({space}); build the env with "
                             "expressions=True")
        names = list(env.possible_agents)
        me = agent_index(env, agent)
        if self.partner is None:
            others = [k for k in range(len(names)) if k != me]
            if not others:
                raise ValueError(f"MirrorController: {agent} has no partner in this env")
            self._other = others[0]
        elif self.partner in names and self.partner != agent:
            self._other = names.index(self.partner)
        else:
            raise ValueError(f"MirrorController: partner={self.partner!r} for {agent}; "
                             f"allowed: {[n for n in names if n != agent]}")
        self._action = zero_action(space)

    def act(self, env, agent, observation):
        if self._action is None:
            raise RuntimeError("MirrorController.act() before reset(); reset the env first")
        face = self.face if self.face is not None else env.world.expression_of(self._other)
        return {"motors": self._action["motors"].copy(), "expression": np.int64(face)}
