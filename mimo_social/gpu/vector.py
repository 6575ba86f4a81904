"""A Gymnasium vector env of a task's batched worlds, for one learner.

:class:`GymVectorEnv` is a :class:`gymnasium.vector.VectorEnv` over a
:class:`~mimo_social.gpu.task_env.BatchedTaskEnv`: the single-agent reach, or a social task's
one-learner form (``high_five_v0.scripted_env()``: ``infant_0`` learns, the scripted partner
acts on the device). Autoreset: **same step** (``AutoresetMode.SAME_STEP``): a world that
finishes is reset inside the step that finished it; that step returns the new episode's
first observation in its row, and ``infos["final_obs"]`` / ``infos["final_info"]`` the
finished step's (every world's rows, ``infos["_final_obs"]`` / ``infos["_final_info"]``: which
worlds finished).

Spaces: ``single_observation_space`` is the CPU env's observation Dict for the senses the
device computes (proprioception, vestibular; touch and vision are left out) and the task's
own observations (self-body's ``target``), and
``single_action_space`` the motors' Box (the face and the voice do not move the body: not in
the batched actions). Observations, rewards and flags are torch tensors on the device, or
numpy arrays (host copies) with ``numpy=True``. Infos: the task's keys as ``(num_envs,)``
arrays, each with its ``"_key"`` mask (all True: every world has every key), and
``"instability"``.
"""

from __future__ import annotations

from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from .task_env import BatchedTaskEnv

__all__ = ["GymVectorEnv", "device_spaces"]


def device_spaces(tenv: BatchedTaskEnv, agent: str) -> tuple[spaces.Dict, spaces.Box]:
    """``agent``'s observation Dict (the senses the device computes and the task's own
    observations, in the CPU env's spaces) and its motors' action Box."""
    inner = tenv.inner
    i = tenv.agents.index(agent)
    cpu = inner.observation_space(agent)
    keys = [s.name for s in tenv.batched.senses[i]] + list(tenv.task.observed)
    obs = spaces.Dict({k: cpu[k] for k in keys})
    act = inner.action_space(agent)
    if isinstance(act, spaces.Dict):
        act = act["motors"]
    return obs, act


class GymVectorEnv(VectorEnv):
    """``num_envs`` worlds of ``env`` (a CPU env of the catalogue with one learner: reach, or
    a social task's ``scripted_env()``) on the Warp device ``device``; ``seed``: the first
    episodes' seeds (world ``w``: ``seed + w``, :class:`BatchedTaskEnv`); ``numpy``: hand out
    numpy arrays instead of torch tensors; ``nconmax`` / ``njmax`` / ``touch``:
    :class:`BatchedEnv`'s; ``reset_bank``: :class:`BatchedTaskEnv`'s. ``expressions``: the
    action a Dict of ``"motors"`` (the Box) and ``"expression"`` (``Discrete(7)``, drawn on the
    learner's face in its world: :mod:`mimo_social.gpu.faces`), for a learner whose CPU actions
    carry an expression; False (default): the motors' Box alone."""

    metadata = {"autoreset_mode": AutoresetMode.SAME_STEP, "render_modes": []}

    def __init__(self, env, num_envs: int, device: str | None = None, seed: int = 0,
                 numpy: bool = False, nconmax: int | None = None, njmax: int | None = None,
                 touch: bool = True, reset_bank: int | None = None,
                 expressions: bool = False):
        learners = list(env.possible_agents)
        if len(learners) != 1:
            raise ValueError(f"GymVectorEnv takes one learner; this env has {learners}: give "
                             f"the task's one-learner form (e.g. high_five_v0.scripted_env()), "
                             f"or use TorchRLEnv for several learners")
        self.tenv = BatchedTaskEnv(env, num_envs, device=device, seed=seed, nconmax=nconmax,
                                   njmax=njmax, touch=touch,
                                   reset_bank=reset_bank)
        self.agent = self.tenv.learners[0]
        self.num_envs = self.tenv.nworld
        self.numpy = bool(numpy)
        self.render_mode = None
        self.single_observation_space, self.single_action_space = \
            device_spaces(self.tenv, self.agent)
        if not isinstance(expressions, bool):
            raise ValueError(f"expressions={expressions!r} not allowed; allowed: True or False")
        self.expressions = expressions
        if expressions:
            self.tenv.batched.faces.require_acting(self.agent, "expressions=True",
                                                   ", or expressions=False")
            self.single_action_space = spaces.Dict({
                "motors": self.single_action_space,
                "expression": env.unwrapped.action_space(self.agent)["expression"]})
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.device_name = self.tenv.device_name
        self.spec = None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        if options:
            raise ValueError(f"reset options {sorted(options)} not allowed; allowed: None")
        obs, infos = self.tenv.reset(seed=seed)
        return self._out(obs[self.agent]), self._info(infos)

    def step(self, actions):
        expressions = None
        if self.expressions:
            if not hasattr(actions, "keys") or set(actions) != {"motors", "expression"}:
                raise ValueError(f"{self.agent}: actions must be a dict with 'motors' "
                                 f"({self.num_envs}, n) and 'expression' ({self.num_envs},) "
                                 f"(expressions=True); got "
                                 f"{sorted(actions) if hasattr(actions, 'keys') else type(actions).__name__}")
            expressions = {self.agent: actions["expression"]}
            actions = actions["motors"]
        obs, rew, term, trunc, infos = self.tenv.step({self.agent: actions},
                                                      expressions=expressions)
        final = infos.pop("_final_obs")
        final_obs = infos.pop("final_obs")
        info = self._info(infos)
        out = dict(info)
        out["final_obs"] = self._out(final_obs[self.agent])
        out["_final_obs"] = self._out(final)
        out["final_info"] = info
        out["_final_info"] = self._out(final)
        return (self._out(obs[self.agent]), self._out(rew[self.agent]), self._out(term),
                self._out(trunc), out)

    def _out(self, x):
        if isinstance(x, dict):
            return {k: self._out(v) for k, v in x.items()}
        return x.detach().cpu().numpy() if self.numpy else x

    def _info(self, infos: dict) -> dict:
        torch = self.tenv.torch
        out = {}
        for k, v in infos.items():
            v = v[self.agent] if isinstance(v, dict) else v
            out[k] = self._out(v)
            out["_" + k] = self._out(torch.ones(self.num_envs, dtype=torch.bool, device=v.device))
        return out

    def close(self, **kwargs):
        self.closed = True

