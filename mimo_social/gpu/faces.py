"""Facial expressions on the device: every agent's expression in every world, as the CPU env
keeps it (:meth:`mimo_social.core.world.World.set_expression`, the action's ``expression``).

An expression is an id of :data:`mimo_social.expressions.faces.EXPRESSIONS`. Where eyes are
rendered on the device, the head material's texture (``model.mat_texid``, batched per world)
points at that expression's face texture, as on the CPU, so the partners see it in the next
images; proprioception's ``face`` component reads it as a one-hot. A world starts (and is
reset) with the expressions of its CPU reset (neutral).
"""

from __future__ import annotations

import numpy as np

from ..expressions.faces import EXPRESSIONS
from ..expressions.switch import FaceTextures

__all__ = ["BatchedFaces", "RGB_ROLE", "carries_expression"]

#: the texture role of a material's colour texture (``mjtTextureRole.mjTEXROLE_RGB``)
RGB_ROLE = 1


def carries_expression(env, agent: str) -> bool:
    """Whether ``agent``'s actions in the CPU ``env`` carry an expression
    (``AgentConfig.expressions``)."""
    space = env.action_space(agent)
    return hasattr(space, "spaces") and "expression" in space.spaces


class BatchedFaces:
    """The expressions of the agents of ``env`` (a CPU :class:`MimoParallelEnv`, just reset)
    for ``nworld`` worlds; ``mat_texid``: the batched model's per-world ``mat_texid`` tensor
    ``(nworld, nmat, roles)`` (None: no eyes on the device, nothing to draw)."""

    def __init__(self, env, nworld: int, torch, device, mat_texid=None):
        w = env.world
        self._torch = torch
        self.names = list(env.possible_agents)
        #: whether each agent's actions carry an expression (AgentConfig.expressions)
        self.acting = [carries_expression(env, a) for a in self.names]
        self.materials = torch.as_tensor([a.head_material for a in w.agents], dtype=torch.int64,
                                         device=device)
        self.textures = torch.as_tensor([w.model.texture(n).id for n in FaceTextures.names],
                                        dtype=torch.int64, device=device)
        self.start = torch.as_tensor(self.shown(env), dtype=torch.int64, device=device)
        self.expression = self.start.repeat(nworld, 1)            # (nworld, n_agents)
        self._mat = mat_texid
        self._draw(None)

    @staticmethod
    def shown(env) -> np.ndarray:
        """The expression each agent of the CPU ``env`` shows now (one array: a leaf of the
        snapshot's rows)."""
        return np.array([env.world.expression_of(i) for i in range(len(env.possible_agents))],
                        np.int64)

    def require_acting(self, agent: str, what: str, other: str = "") -> None:
        """A ValueError naming ``agent`` and ``what`` asked for an expression unless its
        actions carry one (``other``: a further way out the message names)."""
        if not self.acting[self.names.index(agent)]:
            raise ValueError(f"{agent}: {what}, but this agent's actions have no expression; "
                             f"allowed: its env made with expressions on "
                             f"(AgentConfig.expressions=True){other}")

    def _draw(self, worlds) -> None:
        if self._mat is None:
            return
        tex = self.textures[self.expression].to(self._mat.dtype)       # (nworld, n_agents)
        rows = slice(None) if worlds is None else worlds
        for i in range(len(self.names)):
            self._mat[rows, self.materials[i], RGB_ROLE] = tex[rows, i]

    def set(self, expressions: dict) -> None:
        """This step's expressions: agent -> ``(nworld,)`` ids (torch or numpy); a ValueError
        naming the agent, the field and the value for an agent without expressions or an id
        out of range (then no agent's expression changes)."""
        t = self._torch
        checked = []            # every agent's ids checked before any is drawn
        for a, given in expressions.items():
            if a not in self.names:
                raise ValueError(f"expressions: unknown agent {a!r}; agents: {self.names}")
            i = self.names.index(a)
            self.require_acting(a, "expression given")
            ids = t.as_tensor(np.asarray(given) if not hasattr(given, "to") else given,
                              device=self.expression.device)
            if ids.shape != (self.expression.shape[0],) or ids.dtype.is_floating_point:
                raise ValueError(f"{a}: expression of shape {tuple(ids.shape)} and dtype "
                                 f"{ids.dtype} not allowed; allowed: ({self.expression.shape[0]},)"
                                 f" integer ids")
            bad = (ids < 0) | (ids >= len(EXPRESSIONS))
            if bool(bad.any()):
                raise ValueError(f"{a}: expression {int(ids[bad][0])} not allowed; allowed: 0 to "
                                 f"{len(EXPRESSIONS) - 1} ("
                                 + ", ".join(f"{k}={e}" for k, e in enumerate(EXPRESSIONS)) + ")")
            checked.append((i, ids.to(self.expression.dtype)))
        for i, ids in checked:
            self.expression[:, i] = ids
        self._draw(None)

    def reset(self, worlds=None, shown=None) -> None:
        """The worlds ``worlds`` (a bool mask or indices; None: all) back to the start's
        expressions, or to ``shown`` (rows of ids per agent, one per world given)."""
        rows = slice(None) if worlds is None else worlds
        if shown is None:
            self.expression[rows] = self.start
        else:
            self.expression[rows] = self._torch.as_tensor(
                shown, device=self.expression.device).to(self.expression.dtype)
        self._draw(worlds)

    def one_hot(self, i: int):
        """Agent ``i``'s expression in every world, one-hot ``(nworld, 7)`` float32."""
        t = self._torch
        return t.nn.functional.one_hot(self.expression[:, i], len(EXPRESSIONS)).to(t.float32)
