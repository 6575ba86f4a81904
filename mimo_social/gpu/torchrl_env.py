"""A TorchRL env of a task's batched worlds, for multi-agent learners (``torchrl``, the ``gpu``
extra: ``torchrl==0.14.1``, ``tensordict==0.14.3``).

:class:`TorchRLEnv` is a :class:`torchrl.envs.EnvBase` over a
:class:`~mimo_social.gpu.task_env.BatchedTaskEnv` with ``batch_size = (num_envs,)`` on the
device's torch device, in TorchRL's multi-agent convention: the learners form one group
(``group``, default ``"agents"``; ``group_map = {group: learners}``) stacked on the dimension
after the worlds, and the tensordict holds::

    (group, "observation", sense)   (num_envs, n_learners, size)   float32
    (group, "action")               (num_envs, n_learners, n_controls)   in the motors' Box
    (group, "reward")               (num_envs, n_learners, 1)
    "done", "terminated", "truncated"   (num_envs, 1) bool (every agent ends together)

Resets are TorchRL's: the env does not reset a finished world by itself; ``reset`` with a
``"_reset"`` mask (what ``step_and_maybe_reset`` and the collectors send) resets those worlds,
the others keep their observation. The learners must share their spaces (the same body and
senses: both infants of high five); otherwise a ValueError names the agents.
"""

from __future__ import annotations

import numpy as np
import torch
from tensordict import TensorDict
from torchrl.data import Bounded, Categorical, Composite, Unbounded
from torchrl.envs import EnvBase

from ..expressions.faces import EXPRESSIONS
from .task_env import BatchedTaskEnv
from .vector import device_spaces

__all__ = ["TorchRLEnv"]


def _obs_spec(space, lead: tuple, device):
    """One observation key's spec: images (uint8 Boxes) bounded 0..255 as uint8, the rest
    unbounded float32."""
    shape = lead + space.shape
    if space.dtype == np.uint8:
        return Bounded(low=0, high=255, shape=shape, dtype=torch.uint8, device=device)
    return Unbounded(shape=shape, dtype=torch.float32, device=device)


class TorchRLEnv(EnvBase):
    """``num_envs`` worlds of ``env`` (a CPU env of the catalogue: the ParallelEnv, every agent
    learning, or a one-learner form) on the Warp device ``device``; ``seed``: the first
    episodes' seeds and ``reset_bank`` (:class:`BatchedTaskEnv`); ``group``: the learners'
    group name; ``expressions``: the learners choose their expression too, ``(group,
    "expression")`` a ``Categorical(7)`` beside ``(group, "action")`` (every learner's CPU
    actions must carry one)."""

    def __init__(self, env, num_envs: int, device: str | None = None, seed: int = 0,
                 group: str = "agents", nconmax: int | None = None, njmax: int | None = None,
                 touch: bool = True, reset_bank: int | None = None,
                 expressions: bool = False):
        tenv = BatchedTaskEnv(env, num_envs, device=device, seed=seed, nconmax=nconmax,
                              njmax=njmax, touch=touch,
                              reset_bank=reset_bank)
        if not isinstance(group, str) or not group:
            raise ValueError(f"group={group!r} not allowed; allowed: a non-empty string")
        if not isinstance(expressions, bool):
            raise ValueError(f"expressions={expressions!r} not allowed; allowed: True or False")
        for a in tenv.learners if expressions else ():
            tenv.batched.faces.require_acting(a, "expressions=True", ", or expressions=False")
        dev = tenv.batched.qpos.device
        super().__init__(device=dev, batch_size=torch.Size([tenv.nworld]))
        self.tenv = tenv
        self.expressions = expressions
        self.group = group
        self.learners = list(tenv.learners)
        self.group_map = {group: self.learners}
        spaces = [device_spaces(tenv, a) for a in self.learners]
        first = spaces[0]
        for a, (o, act) in zip(self.learners, spaces):
            if o != first[0] or act != first[1]:
                raise ValueError(f"TorchRLEnv stacks the learners in one group: {a}'s spaces "
                                 f"differ from {self.learners[0]}'s ({o}, {act} against "
                                 f"{first[0]}, {first[1]}); allowed: learners with the same "
                                 f"body and senses")
        n, k = tenv.nworld, len(self.learners)
        obs_space, act_space = first
        self._keys = list(obs_space.spaces)
        obs = Composite({key: _obs_spec(sp, (n, k), dev)
                         for key, sp in obs_space.spaces.items()}, shape=(n, k), device=dev)
        inner = Composite({"observation": obs}, shape=(n, k), device=dev)
        self.observation_spec = Composite({group: inner}, shape=(n,), device=dev)
        shape = (n, k) + act_space.shape
        as_t = lambda x: torch.as_tensor(np.broadcast_to(x, shape).copy(),  # noqa: E731
                                         dtype=torch.float32, device=dev)
        acts = {"action": Bounded(low=as_t(act_space.low), high=as_t(act_space.high),
                                  shape=shape, dtype=torch.float32, device=dev)}
        if expressions:
            acts["expression"] = Categorical(len(EXPRESSIONS), shape=(n, k), dtype=torch.int64,
                                             device=dev)
        self.action_spec = Composite({group: Composite(acts, shape=(n, k), device=dev)},
                                     shape=(n,), device=dev)
        self.reward_spec = Composite({group: Composite({"reward": Unbounded(
            shape=(n, k, 1), dtype=torch.float32, device=dev)}, shape=(n, k), device=dev)},
            shape=(n,), device=dev)
        flag = lambda: Categorical(2, shape=(n, 1), dtype=torch.bool, device=dev)  # noqa: E731
        self.done_spec = Composite({"done": flag(), "terminated": flag(), "truncated": flag()},
                                   shape=(n,), device=dev)
        self._last = None
        self._next_seed = None

    def _obs_td(self, obs: dict) -> TensorDict:
        n, k = self.tenv.nworld, len(self.learners)
        o = {key: torch.stack([obs[a][key] for a in self.learners], dim=1)
             for key in self._keys}
        return TensorDict(o, batch_size=(n, k), device=self.device)

    def _reset(self, tensordict=None, **kwargs):
        mask = None
        if tensordict is not None and "_reset" in tensordict.keys():
            mask = tensordict.get("_reset").reshape(self.tenv.nworld)
        if mask is None or self._last is None:
            obs, _ = self.tenv.reset(seed=self._next_seed)
            self._next_seed = None
            td = self._obs_td(obs)
        else:
            obs, _ = self.tenv.reset(worlds=mask)
            fresh = self._obs_td(obs)
            td = self._last.clone()
            for key in self._keys:
                td[key][mask] = fresh[key][mask]
        self._last = td
        n = self.tenv.nworld
        z = torch.zeros((n, 1), dtype=torch.bool, device=self.device)
        return TensorDict({self.group: TensorDict({"observation": td.clone()},
                                                  batch_size=td.batch_size),
                           "done": z, "terminated": z.clone(), "truncated": z.clone()},
                          batch_size=(n,), device=self.device)

    def _step(self, tensordict):
        u = tensordict.get((self.group, "action"))
        actions = {a: u[:, j] for j, a in enumerate(self.learners)}
        faces = None
        if self.expressions:
            e = tensordict.get((self.group, "expression"))
            faces = {a: e[:, j] for j, a in enumerate(self.learners)}
        obs, rew, term, trunc, _ = self.tenv.step(actions, autoreset=False, expressions=faces)
        td = self._obs_td(obs)
        self._last = td
        n = self.tenv.nworld
        r = torch.stack([rew[a] for a in self.learners], dim=1)[..., None].to(torch.float32)
        return TensorDict({self.group: TensorDict({"observation": td.clone(), "reward": r},
                                                  batch_size=td.batch_size),
                           "done": (term | trunc)[:, None], "terminated": term[:, None],
                           "truncated": trunc[:, None]}, batch_size=(n,), device=self.device)

    def _set_seed(self, seed: int | None):
        """The next full reset starts every world's seeds over from ``seed``."""
        self._next_seed = None if seed is None else int(seed)
        return seed
