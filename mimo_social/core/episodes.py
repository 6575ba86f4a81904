"""The one episode loop: policies act in an env until every agent is done.

``run_episode(env, policies, seed)``
    One episode of a PettingZoo ParallelEnv (``policies``: agent -> policy, one for every
    agent) or of a Gymnasium env (one agent: one policy). Returns an :class:`Episode`.
``run_episodes(env, policies, episodes, seed)``
    ``episodes`` episodes, episode ``k`` reset with seed ``seed + k``.

A policy has ``act(env, agent, obs) -> action`` and may have ``reset(env, agent, rng)`` (the
:class:`~mimo_social.partners.base.Partner` interface, so scripted controllers are policies as
they are). The ``env`` they get is the :class:`~mimo_social.core.env.MimoParallelEnv` under all
wrappers; the ``obs`` is the agent's observation from the env being stepped (a flattening
wrapper's flat one, say). ``reset`` is called after each env reset with
``np.random.default_rng(policy_seed)``: by default the episode's seed.

A Gymnasium env's agent is the ``agent`` of the :class:`~mimo_social.core.gym_adapter.
SingleAgentEnv` found under its wrappers (``"agent"`` for another Gymnasium env); the numbers of
an :class:`Episode` are keyed by agent either way.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import gymnasium as gym
import numpy as np

from ..util.checks import check_int, check_seed, show
from .gym_adapter import SingleAgentEnv

__all__ = ["Episode", "run_episode", "run_episodes"]

#: the agent name of a Gymnasium env that has no SingleAgentEnv under it
GYM_AGENT = "agent"


@dataclass
class Episode:
    """The numbers of one episode, per agent."""

    seed: int | None
    """the env reset seed"""
    returns: dict[str, float]
    """agent -> summed reward"""
    length: int
    """env steps taken"""
    last_infos: dict[str, dict]
    """agent -> its info at its last step (its reset info if it never stepped)"""
    first_success: dict[str, int | None]
    """agent -> first step (1-based) whose info had a true ``is_success``, else None"""
    steps: dict[str, int] = field(default_factory=dict)
    """agent -> steps it acted in (``length``, unless it was done before the others)"""

    def success(self, agent: str | None = None) -> bool | None:
        """``is_success`` of the agent's last info (None: not reported); ``agent`` None: the
        only (or first) agent."""
        if agent is None:
            if not self.last_infos:
                return None
            agent = next(iter(self.last_infos))
        elif agent not in self.last_infos:
            raise KeyError(f"agent {agent!r} not in this episode; agents: {list(self.last_infos)}")
        value = self.last_infos[agent].get("is_success")
        return None if value is None else bool(value)


def _call(policy, name: str):
    method = getattr(policy, name, None)
    return method if callable(method) else None


def _check_policy(agent: str, policy) -> None:
    if _call(policy, "act") is None:
        raise ValueError(f"the policy for {agent!r} ({show(policy)}) has no act(env, agent, obs) "
                         "method; allowed: an object with act(env, agent, obs) -> action and "
                         "optionally reset(env, agent, rng) (e.g. a scripted Partner; wrap a "
                         "model with predict() in such an object)")


class _Parallel:
    """A ParallelEnv seen by the loop."""

    def __init__(self, env, policies):
        self.env = env
        self.core = env.unwrapped
        agents = list(env.possible_agents)
        if not isinstance(policies, Mapping):
            raise ValueError(f"policies={show(policies)} not allowed for a ParallelEnv; allowed: "
                             f"a mapping agent -> policy for every agent of {agents}")
        missing = [a for a in agents if a not in policies]
        unknown = [a for a in policies if a not in agents]
        if missing or unknown:
            raise ValueError(
                (f"no policy for agent(s) {missing}" if missing else
                 f"policies for agent(s) {unknown} that this env does not have")
                + f"; given policies for {list(policies)}; allowed: one for every agent of "
                f"{agents}")
        for a in agents:
            _check_policy(a, policies[a])
        self.agents = agents
        self.policies = {a: policies[a] for a in agents}

    def reset(self, seed):
        return self.env.reset(seed=seed)

    def live(self) -> bool:
        return bool(self.env.agents)

    def step(self, obs):
        actions = {a: self.policies[a].act(self.core, a, obs[a]) for a in self.env.agents}
        return self.env.step(actions)


class _Gym:
    """A Gymnasium env seen by the loop: its one agent, results as dicts keyed by it."""

    def __init__(self, env, policies):
        self.env = env
        single = _single_agent_env(env)
        self.agent = single.agent if single is not None else GYM_AGENT
        self.core = single.parallel.unwrapped if single is not None else env.unwrapped
        self.agents = [self.agent]
        if isinstance(policies, Mapping):
            if len(policies) != 1 or self.agent not in policies:
                raise ValueError(f"policies for {list(policies)} not allowed for this Gymnasium "
                                 f"env; allowed: one policy, or a mapping with the one entry "
                                 f"{self.agent!r}")
            policies = policies[self.agent]
        _check_policy(self.agent, policies)
        self.policy = policies
        self.policies = {self.agent: policies}
        self.done = False

    def reset(self, seed):
        obs, info = self.env.reset(seed=seed)
        self.done = False
        return {self.agent: obs}, {self.agent: info}

    def live(self) -> bool:
        return not self.done

    def step(self, obs):
        a = self.agent
        obs, reward, terminated, truncated, info = self.env.step(
            self.policy.act(self.core, a, obs[a]))
        self.done = bool(terminated or truncated)
        return {a: obs}, {a: reward}, {a: terminated}, {a: truncated}, {a: info}


def _single_agent_env(env) -> SingleAgentEnv | None:
    """The SingleAgentEnv under a Gymnasium env's wrappers, or None."""
    seen = set()
    while env is not None and id(env) not in seen:
        if isinstance(env, SingleAgentEnv):
            return env
        seen.add(id(env))
        env = getattr(env, "env", None)
    return None


def _view(env, policies):
    if isinstance(env, gym.Env):
        return _Gym(env, policies)
    if hasattr(env, "possible_agents"):
        return _Parallel(env, policies)
    raise ValueError(f"env={show(env)} not allowed; allowed: a PettingZoo ParallelEnv (with "
                     "possible_agents) or a Gymnasium env")


def _check_hook(name: str, hook) -> None:
    if hook is not None and not callable(hook):
        raise ValueError(f"{name}={show(hook)} not allowed; allowed: None or a function")


def _episode(view, seed, policy_seed, on_step, on_reset) -> Episode:
    obs, infos = view.reset(seed)
    for a, policy in view.policies.items():
        reset = _call(policy, "reset")
        if reset is not None:
            reset(view.core, a, np.random.default_rng(policy_seed))
    if on_reset is not None:
        on_reset(view.env, obs, infos)
    returns = dict.fromkeys(view.agents, 0.0)
    steps = dict.fromkeys(view.agents, 0)
    last = {a: infos.get(a, {}) for a in view.agents}
    first: dict[str, int | None] = dict.fromkeys(view.agents)
    length = 0
    while view.live():
        obs, rewards, terms, truncs, infos = view.step(obs)
        length += 1
        for a, r in rewards.items():
            returns[a] = returns.get(a, 0.0) + float(r)
            steps[a] = steps.get(a, 0) + 1
        for a, info in infos.items():
            last[a] = info
            if first.get(a) is None and info.get("is_success"):
                first[a] = length
        if on_step is not None:
            on_step(view.env, obs, rewards, terms, truncs, infos)
    return Episode(seed=seed, returns=returns, length=length, last_infos=last,
                   first_success=first, steps=steps)


def run_episode(env, policies, seed: int | None = None, *, policy_rng: Any = None,
                on_step: Callable | None = None, on_reset: Callable | None = None) -> Episode:
    """One episode: ``env.reset(seed=seed)``, each policy reset, then steps until every agent is
    done (a ParallelEnv: ``env.agents`` empty; a Gymnasium env: terminated or truncated).

    ``policies``: a mapping agent -> policy for a ParallelEnv (every agent of
    ``env.possible_agents``), one policy (or a one-entry mapping) for a Gymnasium env.
    ``policy_rng``: the seed of the policies' reset generator (anything ``np.random.default_rng``
    takes; default: ``seed``). ``on_step(env, obs, rewards, terminations, truncations, infos)``
    after each step and ``on_reset(env, obs, infos)`` after the reset and the policies' resets:
    ``env`` is the env given, the rest dicts keyed by agent (a Gymnasium env's too)."""
    view = _view(env, policies)
    _check_hook("on_step", on_step)
    _check_hook("on_reset", on_reset)
    seed = check_seed(seed, "run_episode")
    return _episode(view, seed, seed if policy_rng is None else policy_rng, on_step, on_reset)


def _progress(progress, total: int):
    if progress is None or progress is False:
        return None
    if progress is not True and not isinstance(progress, str):
        raise ValueError(f"progress={show(progress)} not allowed; allowed: None, False, True or "
                         "a description (a string)")
    from tqdm import tqdm
    return tqdm(total=total, unit="episode", dynamic_ncols=True,
                desc=progress if isinstance(progress, str) else None)


def run_episodes(env, policies, episodes: int, seed: int = 0, *,
                 policy_seeds: Sequence[Any] | None = None, on_step: Callable | None = None,
                 on_reset: Callable | None = None, progress: bool | str | None = None
                 ) -> list[Episode]:
    """``episodes`` episodes of :func:`run_episode`, episode ``k`` reset with seed ``seed + k``
    and its policies with ``np.random.default_rng(policy_seeds[k])`` (default: ``seed + k``).
    ``progress``: True or a description for a bar over the episodes (None or False: none)."""
    episodes = check_int("run_episodes", "episodes", episodes, 1)
    seed = check_seed(seed, "run_episodes")
    if seed is None:
        raise ValueError("run_episodes: seed=None not allowed; allowed: an integer >= 0 (episode "
                         "k is reset with seed + k)")
    if policy_seeds is not None:
        if isinstance(policy_seeds, (str, bytes, Mapping)) \
                or not isinstance(policy_seeds, (Sequence, np.ndarray)) \
                or len(policy_seeds) != episodes:
            raise ValueError(f"run_episodes: policy_seeds={show(policy_seeds)} not allowed; "
                             f"allowed: None or a sequence of {episodes} seeds (one per episode)")
    view = _view(env, policies)
    _check_hook("on_step", on_step)
    _check_hook("on_reset", on_reset)
    bar = _progress(progress, episodes)
    out = []
    try:
        for k in range(episodes):
            policy_seed = seed + k if policy_seeds is None else policy_seeds[k]
            out.append(_episode(view, seed + k, policy_seed, on_step, on_reset))
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return out
