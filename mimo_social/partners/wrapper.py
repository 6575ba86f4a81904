"""``ScriptedPartners(env, {"infant_1": ExpressionShow()})``: some agents driven by scripts
(an adult partner is ``caregiver_0``: :mod:`mimo_social.util.names`).

A PettingZoo ParallelEnv around a :class:`~mimo_social.core.env.MimoParallelEnv` whose
agents are only the learners; every scripted agent's action is filled in by its
:class:`~mimo_social.partners.base.Partner` each step. With one learner left, the result can be
wrapped by :class:`~mimo_social.core.gym_adapter.SingleAgentEnv` for Gymnasium / SB3. Each learner's
info gets ``partner_rewards`` (the scripted agents' rewards of the step), so a cooperative task
can be judged from both sides.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
from pettingzoo import ParallelEnv

from ..core.wrappers import ParallelWrapper
from ..util.checks import check_seed
from ..util.names import reject_old_names
from .base import Partner

__all__ = ["ScriptedPartners"]


class ScriptedPartners(ParallelWrapper):
    def __init__(self, env: ParallelEnv, partners: Mapping[str, Partner]):
        super().__init__(env)
        if not isinstance(partners, Mapping) or not partners:
            raise ValueError("partners must be a non-empty mapping agent -> Partner, got "
                             f"{partners!r}")
        unknown = [a for a in partners if a not in env.possible_agents]
        if unknown:
            reject_old_names(unknown, env.possible_agents)
            raise ValueError(f"scripted agent(s) {unknown} are not agents of this env; "
                             f"agents: {env.possible_agents}")
        for a, p in partners.items():
            if not callable(getattr(p, "act", None)) or not callable(getattr(p, "reset", None)):
                raise TypeError(f"partner for {a!r} must have reset(env, agent, rng) and "
                                f"act(env, agent, observation); got {p!r}")
        learners = [a for a in env.possible_agents if a not in partners]
        if not learners:
            raise ValueError("every agent is scripted: leave at least one learner")
        self.partners = dict(partners)
        self.possible_agents = learners
        self._partner_obs: dict[str, Any] = {}

    @property
    def agents(self):
        return [a for a in self.env.agents if a not in self.partners]

    def observation_space(self, agent):
        self._check(agent)
        return self.env.observation_space(agent)

    def action_space(self, agent):
        self._check(agent)
        return self.env.action_space(agent)

    def info_spec(self, agent) -> dict:
        """The env's info keys of a learner (:meth:`MimoParallelEnv.info_spec`) plus
        ``partner_rewards``: one number per scripted agent, so numeric views of the infos
        (:class:`mimo_social.core.wrappers.NumericInfos`) keep them."""
        self._check(agent)
        return {**self.env.info_spec(agent),
                "partner_rewards": {name: "number" for name in self.partners}}

    def info_keys(self, agent) -> tuple[str, ...]:
        """The keys of a learner's numeric infos (the env's default): the env's, then
        ``partner_rewards/<scripted agent>`` (0 at reset)."""
        self._check(agent)
        return (*self.env.info_keys(agent), *(f"partner_rewards/{n}" for n in self.partners))

    def _with_partner_rewards(self, infos: dict, rewards: Mapping[str, float]) -> dict:
        """The learners' infos with the scripted agents' rewards of the step: one dict
        ``partner_rewards`` in text infos, ``partner_rewards/<agent>`` numbers in numeric ones
        (the same keys at reset, 0 there)."""
        if getattr(self.env.unwrapped, "info_text", True):
            given = {a: float(rewards[a]) for a in self.partners if a in rewards}
            return {a: dict(info, partner_rewards=given) for a, info in infos.items()}
        flat = {f"partner_rewards/{n}": float(rewards.get(n, 0.0)) for n in self.partners}
        return {a: {**info, **flat} for a, info in infos.items()}

    def _check(self, agent):
        if agent not in self.possible_agents:
            reject_old_names(agent, self.env.possible_agents)
            raise KeyError(f"unknown agent {agent!r}; learners of this env: {self.possible_agents}"
                           f" (scripted: {list(self.partners)})")

    def _split(self, d: Mapping[str, Any]) -> dict:
        return {a: v for a, v in d.items() if a not in self.partners}

    def reset(self, seed: int | None = None, options: dict | None = None):
        seed = check_seed(seed, "reset")
        obs, infos = self.env.reset(seed=seed, options=options)
        # the partners' generators come from the last seeded reset's sequence: an unseeded reset
        # continues it (reproducible, and a pickled copy continues exactly as the original)
        if seed is not None or self.__dict__.get("_seeds") is None:
            self._seeds = np.random.SeedSequence(seed)
        rngs = [np.random.default_rng(s) for s in self._seeds.spawn(len(self.partners))]
        inner = self.env.unwrapped
        for (name, partner), rng in zip(self.partners.items(), rngs):
            partner.reset(inner, name, rng)
        self._partner_obs = {a: obs[a] for a in self.partners if a in obs}
        infos = self._split(infos)
        if not getattr(self.env.unwrapped, "info_text", True):
            infos = self._with_partner_rewards(infos, {})
        return self._split(obs), infos

    def step(self, actions: Mapping[str, Any]):
        if not isinstance(actions, Mapping):
            raise ValueError(f"actions must be a dict agent -> action, got {type(actions).__name__}")
        if self.__dict__.get("_seeds") is None:   # the partners are set up by this reset
            raise RuntimeError("step() called before reset(); call reset(seed=...) first")
        scripted = [a for a in actions if a in self.partners]
        if scripted:
            raise ValueError(f"actions given for scripted agent(s) {scripted}; their partners "
                             f"act for them. Learners: {self.possible_agents}")
        inner = self.env.unwrapped
        full = dict(actions)
        for name, partner in self.partners.items():
            if name in self.env.agents:
                full[name] = partner.act(inner, name, self._partner_obs.get(name))
        obs, rewards, terms, truncs, infos = self.env.step(full)
        self._partner_obs = {a: obs[a] for a in self.partners if a in obs}
        infos = self._with_partner_rewards(self._split(infos), rewards)
        return (self._split(obs), self._split(rewards), self._split(terms), self._split(truncs),
                infos)
