"""Episodes with trained policies and their numbers (training's evaluations and ``eval``).

``evaluate_policy(model, env, episodes, seed)``
    One learner on a Gymnasium env: ``episodes`` episodes seeded ``seed, seed+1, ...``.
``evaluate_agents(policies, env, episodes, seed)``
    Every agent of a flat ParallelEnv acting with its own policy: per-agent returns and success
    rates (``is_success`` of the agent's info on its last step) and their means across agents.

The episodes run in the core's episode loop (:mod:`mimo_social.core.episodes`), the models
acting through :class:`ModelPolicy`.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from ..core.episodes import run_episode as _run_episode

__all__ = ["run_gym_episode", "evaluate_policy", "run_episode", "evaluate_agents", "ModelPolicy"]


class ModelPolicy:
    """A model with SB3's ``predict(obs, deterministic) -> (action, state)`` as a policy of the
    core episode loop (:func:`mimo_social.core.episodes.run_episode`), acting on the observations
    of the env stepped. ``actions``: a dict that gets each action, keyed by agent."""

    def __init__(self, model, deterministic: bool = True, actions: dict | None = None):
        self.model, self.deterministic, self.actions = model, deterministic, actions

    def act(self, env, agent: str, obs):
        action = self.model.predict(obs, deterministic=self.deterministic)[0]
        if self.actions is not None:
            self.actions[agent] = action
        return action


def _only(d: Mapping[str, Any]):
    """The value of a one-entry dict (a Gymnasium env's numbers keyed by its agent)."""
    return next(iter(d.values()))


def run_gym_episode(model, env, seed: int | None, deterministic: bool = True, on_step=None):
    """One episode; returns (return, length, success or None)."""
    actions: dict = {}
    hooks = {}
    if on_step is not None:   # the one agent's action, reward and info
        hooks["on_reset"] = lambda _env, obs, infos: on_step(None, None, _only(infos), reset=True)
        hooks["on_step"] = lambda _env, obs, rewards, terms, truncs, infos: on_step(
            _only(actions), _only(rewards), _only(infos), reset=False)
    ep = _run_episode(env, ModelPolicy(model, deterministic, actions), seed, **hooks)
    agent = next(iter(ep.returns))
    return ep.returns[agent], ep.length, ep.success(agent)


def evaluate_policy(model, env, episodes: int, seed: int, deterministic: bool = True,
                    on_step=None, on_episode=None) -> dict:
    """``episodes`` episodes of one learner (seeds ``seed, seed+1, ...``): returns, lengths,
    their means and the success rate (NaN when the task reports none). ``on_episode()`` after
    each episode (e.g. a progress bar's update)."""
    returns, lengths, successes = [], [], []
    for k in range(episodes):
        r, n, s = run_gym_episode(model, env, seed + k, deterministic, on_step)
        if on_episode is not None:
            on_episode()
        returns.append(r)
        lengths.append(n)
        if s is not None:
            successes.append(s)
    return {"returns": returns, "lengths": lengths,
            "return_mean": float(np.mean(returns)), "return_std": float(np.std(returns)),
            "length_mean": float(np.mean(lengths)),
            "success_rate": float(np.mean(successes)) if successes else float("nan")}


def run_episode(policies: Mapping[str, Any], env, seed: int | None, deterministic: bool = True,
                on_step=None) -> dict[str, tuple[float, int, bool | None]]:
    """One episode of a (flat) ParallelEnv; each agent acts with ``policies[agent]``.
    Returns ``{agent: (return, length, success or None)}``."""
    actions: dict = {}
    hooks = {}
    if on_step is not None:
        hooks["on_reset"] = lambda _env, obs, infos: on_step(None, None, obs, reset=True)

        def after_step(_env, obs, rewards, terms, truncs, infos):
            acted = dict(actions)
            actions.clear()
            on_step(acted, rewards, obs, reset=False)
        hooks["on_step"] = after_step
    models = {a: ModelPolicy(policies[a], deterministic, actions)
              for a in env.possible_agents if a in policies}
    ep = _run_episode(env, models, seed, **hooks)
    return {a: (ep.returns[a], ep.steps[a], ep.success(a) if ep.steps[a] else None)
            for a in env.possible_agents}


def evaluate_agents(policies: Mapping[str, Any], env, episodes: int, seed: int,
                    deterministic: bool = True, on_step=None, on_episode=None) -> dict:
    """``episodes`` episodes (seeds ``seed, seed+1, ...``): per-agent and across-agent numbers.

    ``res["agents"][agent]`` has ``returns, lengths, return_mean, return_std, length_mean,
    success_rate``; ``res`` itself the same averaged across agents (``returns[k]``: the agents'
    mean return in episode ``k``; ``success_rate``: mean of the agents' rates)."""
    agents = list(env.possible_agents)
    per = {a: {"returns": [], "lengths": [], "successes": []} for a in agents}
    for k in range(int(episodes)):
        for a, (r, n, s) in run_episode(policies, env, seed + k, deterministic, on_step).items():
            per[a]["returns"].append(r)
            per[a]["lengths"].append(n)
            if s is not None:
                per[a]["successes"].append(s)
        if on_episode is not None:
            on_episode()
    res_agents = {}
    for a, d in per.items():
        res_agents[a] = {"returns": d["returns"], "lengths": d["lengths"],
                         "return_mean": float(np.mean(d["returns"])),
                         "return_std": float(np.std(d["returns"])),
                         "length_mean": float(np.mean(d["lengths"])),
                         "success_rate": (float(np.mean(d["successes"])) if d["successes"]
                                          else float("nan"))}
    mean_returns = np.mean([per[a]["returns"] for a in agents], axis=0)
    rates = [res_agents[a]["success_rate"] for a in agents]
    rates = [r for r in rates if not math.isnan(r)]
    return {"agents": res_agents, "returns": [float(x) for x in mean_returns],
            "return_mean": float(np.mean(mean_returns)), "return_std": float(np.std(mean_returns)),
            "length_mean": float(np.mean([res_agents[a]["length_mean"] for a in agents])),
            "success_rate": float(np.mean(rates)) if rates else float("nan")}

