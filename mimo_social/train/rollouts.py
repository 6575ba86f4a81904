"""Episodes with trained policies and their numbers (training's evaluations and ``eval``).

``evaluate_policy(model, env, episodes, seed)``
    One learner on a Gymnasium env: ``episodes`` episodes seeded ``seed, seed+1, ...``.
``evaluate_agents(policies, env, episodes, seed)``
    Every agent of a flat ParallelEnv acting with its own policy: per-agent returns and success
    rates (``is_success`` of the agent's info on its last step) and their means across agents.

The episodes run in the core's episode loop (:mod:`mimo_social.core.episodes`), the models
acting through :class:`ModelPolicy`: a recurrent model (``--algo recurrent_ppo``, an LSTM) gets
its state back at every step of an episode and a fresh one at every episode's start
(:class:`PolicyState`); a run's ``vecnormalize.pkl`` (``--normalize-reward``) is applied to the
observations only where it normalised them (:func:`load_vecnormalize`); rewards and returns
are always the env's own.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..core.episodes import run_episode as _run_episode

__all__ = ["run_gym_episode", "evaluate_policy", "run_episode", "evaluate_agents", "ModelPolicy",
           "PolicyState", "is_recurrent", "load_vecnormalize", "vecnormalize_path"]


def is_recurrent(model) -> bool:
    """Whether ``model`` keeps a state across steps (sb3-contrib's recurrent policies: their
    ``policy`` has ``lstm_hidden_state_shape``)."""
    return getattr(getattr(model, "policy", None), "lstm_hidden_state_shape", None) is not None


class PolicyState:
    """A model's actions over one episode at a time: ``predict(obs, deterministic)`` -> action.
    A recurrent model gets back the LSTM state it returned at the previous step, and
    ``episode_start=True`` with a fresh (zero) state at the first step after :meth:`reset`;
    any other model (``predict(obs, deterministic)``) is called as it is. ``normalize``: an
    object with ``normalize_obs(obs)`` applied to the observations first (a run's
    :func:`load_vecnormalize`; None: none)."""

    def __init__(self, model, normalize=None):
        self.model, self.normalize = model, normalize
        self.recurrent = is_recurrent(model)
        self.reset()

    def reset(self) -> None:
        """A new episode: forget the state."""
        self.state, self.start = None, True

    def predict(self, obs, deterministic: bool = True):
        if self.normalize is not None:
            obs = self.normalize.normalize_obs(obs)
        if not self.recurrent:
            return self.model.predict(obs, deterministic=deterministic)[0]
        action, self.state = self.model.predict(obs, state=self.state,
                                                episode_start=np.array([self.start]),
                                                deterministic=deterministic)
        self.start = False
        return action


def vecnormalize_path(model_path) -> Path:
    """The ``VecNormalize`` statistics saved with a model: ``model.zip`` ->
    ``vecnormalize.pkl``, ``best_model.zip`` -> ``best_vecnormalize.pkl``,
    ``checkpoints/model_<n>_steps.zip`` -> ``checkpoints/vecnormalize_<n>_steps.pkl``."""
    model_path = Path(model_path)
    stem = model_path.name[:-4] if model_path.name.endswith(".zip") else model_path.name
    return model_path.with_name(stem.replace("model", "vecnormalize", 1) + ".pkl")


def load_vecnormalize(path):
    """The ``VecNormalize`` statistics pickled by a run (``--normalize-reward``), frozen
    (``training=False``), for :class:`PolicyState`'s ``normalize``; None when its
    observations were not normalised (``norm_obs=False``: the statistics change no action) or
    there is no such file. The rewards are never normalised here: evaluations report the env's
    own returns."""
    path = Path(path)
    if not path.is_file():
        return None
    import pickle
    with open(path, "rb") as f:
        vec = pickle.load(f)
    vec.training, vec.norm_reward = False, False
    return vec if getattr(vec, "norm_obs", False) else None


class ModelPolicy:
    """A model with SB3's ``predict(obs, deterministic) -> (action, state)`` as a policy of the
    core episode loop (:func:`mimo_social.core.episodes.run_episode`), acting on the observations
    of the env stepped; a recurrent model's LSTM state carried across the steps of an episode,
    fresh at each reset (:class:`PolicyState`). ``actions``: a dict that gets each action, keyed
    by agent. ``normalize``: see :class:`PolicyState`."""

    def __init__(self, model, deterministic: bool = True, actions: dict | None = None,
                 normalize=None):
        self.model, self.deterministic, self.actions = model, deterministic, actions
        self.memory = PolicyState(model, normalize)

    def reset(self, env, agent: str, rng) -> None:
        self.memory.reset()

    def act(self, env, agent: str, obs):
        action = self.memory.predict(obs, self.deterministic)
        if self.actions is not None:
            self.actions[agent] = action
        return action


def _only(d: Mapping[str, Any]):
    """The value of a one-entry dict (a Gymnasium env's numbers keyed by its agent)."""
    return next(iter(d.values()))


def run_gym_episode(model, env, seed: int | None, deterministic: bool = True, on_step=None,
                    normalize=None):
    """One episode; returns (return, length, success or None). ``normalize``: see
    :class:`PolicyState`."""
    actions: dict = {}
    hooks = {}
    if on_step is not None:   # the one agent's action, reward and info
        hooks["on_reset"] = lambda _env, obs, infos: on_step(None, None, _only(infos), reset=True)
        hooks["on_step"] = lambda _env, obs, rewards, terms, truncs, infos: on_step(
            _only(actions), _only(rewards), _only(infos), reset=False)
    ep = _run_episode(env, ModelPolicy(model, deterministic, actions, normalize), seed, **hooks)
    agent = next(iter(ep.returns))
    return ep.returns[agent], ep.length, ep.success(agent)


def evaluate_policy(model, env, episodes: int, seed: int, deterministic: bool = True,
                    on_step=None, on_episode=None, normalize=None) -> dict:
    """``episodes`` episodes of one learner (seeds ``seed, seed+1, ...``): returns, lengths,
    their means and the success rate (NaN when the task reports none). ``on_episode()`` after
    each episode (e.g. a progress bar's update). ``normalize``: see :class:`PolicyState`."""
    returns, lengths, successes = [], [], []
    for k in range(episodes):
        r, n, s = run_gym_episode(model, env, seed + k, deterministic, on_step, normalize)
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
                on_step=None, normalize: Mapping[str, Any] | None = None
                ) -> dict[str, tuple[float, int, bool | None]]:
    """One episode of a (flat) ParallelEnv; each agent acts with ``policies[agent]`` (its own
    :class:`ModelPolicy`, so a recurrent model keeps one state per agent). ``normalize``:
    agent -> :class:`PolicyState`'s ``normalize``. Returns ``{agent: (return, length, success
    or None)}``."""
    actions: dict = {}
    hooks = {}
    if on_step is not None:
        hooks["on_reset"] = lambda _env, obs, infos: on_step(None, None, obs, reset=True)

        def after_step(_env, obs, rewards, terms, truncs, infos):
            acted = dict(actions)
            actions.clear()
            on_step(acted, rewards, obs, reset=False)
        hooks["on_step"] = after_step
    models = {a: ModelPolicy(policies[a], deterministic, actions, (normalize or {}).get(a))
              for a in env.possible_agents if a in policies}
    ep = _run_episode(env, models, seed, **hooks)
    return {a: (ep.returns[a], ep.steps[a], ep.success(a) if ep.steps[a] else None)
            for a in env.possible_agents}


def evaluate_agents(policies: Mapping[str, Any], env, episodes: int, seed: int,
                    deterministic: bool = True, on_step=None, on_episode=None,
                    normalize: Mapping[str, Any] | None = None) -> dict:
    """``episodes`` episodes (seeds ``seed, seed+1, ...``): per-agent and across-agent numbers.

    ``res["agents"][agent]`` has ``returns, lengths, return_mean, return_std, length_mean,
    success_rate``; ``res`` itself the same averaged across agents (``returns[k]``: the agents'
    mean return in episode ``k``; ``success_rate``: mean of the agents' rates). ``normalize``:
    as :func:`run_episode`'s."""
    agents = list(env.possible_agents)
    per = {a: {"returns": [], "lengths": [], "successes": []} for a in agents}
    for k in range(int(episodes)):
        for a, (r, n, s) in run_episode(policies, env, seed + k, deterministic, on_step,
                                        normalize).items():
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

