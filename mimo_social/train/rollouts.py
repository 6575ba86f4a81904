"""Episodes with trained policies and their numbers (training's evaluations and ``eval``).

``evaluate_policy(model, env, episodes, seed)``
    One learner on a Gymnasium env: ``episodes`` episodes seeded ``seed, seed+1, ...``.
``evaluate_agents(policies, env, episodes, seed)``
    Every agent of a flat ParallelEnv acting with its own policy: per-agent returns and success
    rates (``is_success`` of the agent's info on its last step) and their means across agents.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

__all__ = ["run_gym_episode", "evaluate_policy", "run_episode", "evaluate_agents"]


def run_gym_episode(model, env, seed: int | None, deterministic: bool = True, on_step=None):
    """One episode; returns (return, length, success or None)."""
    obs, info = env.reset(seed=seed)
    if on_step is not None:
        on_step(None, None, info, reset=True)
    total, length, success = 0.0, 0, None
    while True:
        action, _ = model.predict(obs, deterministic=deterministic)
        obs, reward, terminated, truncated, info = env.step(action)
        total += float(reward)
        length += 1
        if on_step is not None:
            on_step(action, reward, info, reset=False)
        if terminated or truncated:
            if "is_success" in info:
                success = bool(info["is_success"])
            return total, length, success


def evaluate_policy(model, env, episodes: int, seed: int, deterministic: bool = True,
                    on_step=None) -> dict:
    """``episodes`` episodes of one learner (seeds ``seed, seed+1, ...``): returns, lengths,
    their means and the success rate (NaN when the task reports none)."""
    returns, lengths, successes = [], [], []
    for k in range(episodes):
        r, n, s = run_gym_episode(model, env, seed + k, deterministic, on_step)
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
    obs, infos = env.reset(seed=seed)
    if on_step is not None:
        on_step(None, None, obs, reset=True)
    out = {a: [0.0, 0, None] for a in env.possible_agents}
    while env.agents:
        actions = {a: policies[a].predict(obs[a], deterministic=deterministic)[0]
                   for a in env.agents}
        obs, rewards, terms, truncs, infos = env.step(actions)
        for a, r in rewards.items():
            out[a][0] += float(r)
            out[a][1] += 1
            if terms.get(a) or truncs.get(a):
                s = infos.get(a, {}).get("is_success")
                out[a][2] = None if s is None else bool(s)
        if on_step is not None:
            on_step(actions, rewards, obs, reset=False)
    return {a: tuple(v) for a, v in out.items()}


def evaluate_agents(policies: Mapping[str, Any], env, episodes: int, seed: int,
                    deterministic: bool = True, on_step=None) -> dict:
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

