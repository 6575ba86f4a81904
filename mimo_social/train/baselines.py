"""``baselines``: how well random, zero, scripted and trained policies do on a task.

``baselines(task, episodes=30, seed=0, runs=[...])`` runs every policy on the same seeded
episodes (seeds ``seed .. seed+episodes-1``) of the task's one-learner Gymnasium env (the
catalogue's Gymnasium id; for a social task its learner, the partner scripted):

* ``random``: actions sampled from the agent's action space, the space seeded with the
  episode's seed (the same actions every time);
* ``zero``: the resting action (:func:`~mimo_social.partners.base.zero_action`);
* ``scripted``: the catalogue's controller of the task (``entry.controller``), a
  :class:`~mimo_social.partners.base.Partner` driving the agent through its own action (reset
  after every env reset with a generator seeded by the episode's seed); skipped, with a note,
  where the task has none;
* each trained run directory (``mimo-social train``): its final ``model.zip`` (or
  ``best_model.zip``), deterministic, on the flat observations it was trained on; and the same
  episodes again with its actions sampled (``res["policies"][i]["stochastic"]``, the table's
  last column), torch seeded with each episode's seed.

Every episode runs in the core's episode loop (:func:`mimo_social.core.episodes.run_episode`).

Per policy: success rate (``is_success`` of the last step's info; n/a where the task reports
none), return mean and std, episode length, and steps to success: the first step whose info says
``is_success``, averaged over the successful episodes. :func:`markdown_table` writes the table.
SB3 and torch are imported only when a run directory is given.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from ..core.episodes import run_episode
from ..envs.catalog import entry
from ..partners.base import zero_action
from .envs import make_env, run_observation
from .rollouts import ModelPolicy, load_vecnormalize, vecnormalize_path
from .tasks import TrainInputError, algo_class, check_task

__all__ = ["baselines", "markdown_table", "write_json"]


class _Random:
    """Actions sampled from the agent's action space, seeded per episode."""

    name, kind, wrapped = "random", "random", False

    def __init__(self, space):
        import copy
        self.space = copy.deepcopy(space)

    def reset(self, env, agent: str, rng: np.random.Generator) -> None:
        # the space seeded with the episode's seed: ``rng`` is ``default_rng(seed)`` (see
        # :func:`_episode`), whose seed sequence holds that seed as its entropy
        self.space.seed(int(rng.bit_generator.seed_seq.entropy))

    def act(self, env, agent: str, obs):
        return self.space.sample()


class _Zero:
    name, kind, wrapped = "zero", "zero", False

    def __init__(self, space):
        self.action = zero_action(space)

    def act(self, env, agent: str, obs):
        return self.action


class _Scripted:
    """The task's controller, driving the only learner through its action (a Partner)."""

    kind, wrapped = "scripted", False

    def __init__(self, controller_cls):
        self.controller = controller_cls()
        self.name = f"scripted ({type(self.controller).__name__})"

    def reset(self, env, agent: str, rng: np.random.Generator) -> None:
        self.controller.reset(env, agent, rng)

    def act(self, env, agent: str, obs):
        return self.controller.act(env, agent, obs)


class _Trained(ModelPolicy):
    """A trained run's policy, deterministic (or sampling, torch seeded with the episode's
    seed), on the observations of :func:`make_env` it was trained on (flat, or images and a
    vector)."""

    kind, wrapped = "trained", True

    def reset(self, env, agent: str, rng: np.random.Generator) -> None:
        super().reset(env, agent, rng)   # (a recurrent model: a fresh state)
        if not self.deterministic:
            import torch
            torch.manual_seed(int(rng.bit_generator.seed_seq.entropy))

    def __init__(self, run: Path, config: dict, model: str):
        path = {"final": run / "model.zip", "best": run / "best_model.zip"}.get(model, Path(model))
        if not path.exists():
            raise FileNotFoundError(f"model {path} not found (model: final, best or a .zip path)")
        super().__init__(algo_class(config["algo"]).load(str(path), device="cpu"),
                         normalize=load_vecnormalize(vecnormalize_path(path)))
        self.name = f"{run.name} ({config['algo'].upper()})"
        self.run, self.path, self.algo = str(run), str(path), config["algo"]


def _load_run(run: str | Path, task: str) -> dict:
    run = Path(run)
    if not (run / "config.json").exists():
        raise FileNotFoundError(f"{run}/config.json not found: give a directory written by "
                                "'mimo-social train'")
    config = json.loads((run / "config.json").read_text())
    if config.get("task") != task:
        raise TrainInputError(f"run {run} was trained on {config.get('task')!r}, not {task!r}")
    if config.get("mode") not in (None, "scripted"):
        raise TrainInputError(f"run {run} trained every agent (--mode {config['mode']}); the "
                              "baselines run one learner: give a one-agent or a --mode "
                              "scripted run")
    return config


def _env_kwargs(configs: Sequence[dict], runs: Sequence[str],
                env_kwargs: Mapping[str, Any] | None) -> tuple[dict, list[str]]:
    """The env keyword arguments every policy runs with, and notes where a run differs."""
    if env_kwargs is not None:
        kw = dict(env_kwargs)
    else:
        kws = [dict(c.get("env_kwargs", {})) for c in configs]
        if any(k != kws[0] for k in kws[1:]):
            raise TrainInputError("the runs were trained with different env kwargs ("
                                  + "; ".join(f"{r}: {k}" for r, k in zip(runs, kws))
                                  + "); give the env kwargs to evaluate all policies with")
        kw = kws[0] if kws else {}
    notes = [f"{r} was trained with env kwargs {c.get('env_kwargs', {})}; evaluated with {kw}"
             for r, c in zip(runs, configs) if dict(c.get("env_kwargs", {})) != kw]
    return kw, notes


def _episode(policy, env, base, seed: int) -> tuple[float, int, bool | None, int | None]:
    """One episode of the core loop on the flat ``env`` (a trained policy) or on ``base``, the
    SingleAgentEnv, the policy reset with ``default_rng(seed)``: (return, length, success on
    the last step or None, first success step)."""
    ep = run_episode(env if policy.wrapped else base, policy, seed, policy_rng=seed)
    a = base.agent
    return ep.returns[a], ep.length, ep.success(a), ep.first_success[a]


def _summary(policy, episodes: list[tuple]) -> dict:
    returns = [e[0] for e in episodes]
    lengths = [e[1] for e in episodes]
    reported = [e[2] for e in episodes if e[2] is not None]
    to_success = [e[3] for e in episodes if e[2] and e[3] is not None]
    res = {"policy": policy.name, "kind": policy.kind, "episodes": len(episodes),
           "success_rate": float(np.mean(reported)) if reported else float("nan"),
           "successes": int(sum(reported)) if reported else None,
           "return_mean": float(np.mean(returns)), "return_std": float(np.std(returns)),
           "length_mean": float(np.mean(lengths)),
           "steps_to_success_mean": float(np.mean(to_success)) if to_success else float("nan"),
           "returns": returns, "lengths": lengths,
           "success": [e[2] for e in episodes], "first_success_step": [e[3] for e in episodes]}
    if policy.kind == "trained":
        res.update({"run": policy.run, "model": policy.path, "algo": policy.algo})
    return res


def baselines(task: str, episodes: int = 30, seed: int = 0, runs: Sequence[str | Path] = (), *,
              model: str = "final", env_kwargs: Mapping[str, Any] | None = None,
              progress: bool = True) -> dict:
    """Random, zero, scripted and each trained run on the same seeded episodes of ``task``.

    ``env_kwargs``: for every policy (default: those the runs were trained with, which must then
    agree; none without runs). Returns ``task, episodes, seeds, env_kwargs, dt, notes`` and
    ``policies``: one summary per policy (see the module docstring; per-episode lists too)."""
    check_task(task)
    e = entry(task)
    episodes, seed = int(episodes), int(seed)
    if episodes < 1:
        raise TrainInputError(f"episodes={episodes}; allowed: a positive integer")
    runs = [str(r) for r in runs]
    configs = [_load_run(r, task) for r in runs]
    kw, notes = _env_kwargs(configs, runs, env_kwargs)
    layouts = [run_observation(c) for c in configs]
    if any(x != layouts[0] for x in layouts[1:]):
        raise TrainInputError("the runs were trained on different observation layouts ("
                              + "; ".join(f"{r}: {x}" for r, x in zip(runs, layouts))
                              + "); compare runs of one layout at a time")
    env = make_env(task, **(layouts[0] if layouts else {"flat": True}), **kw)
    base = env.unwrapped
    policies: list = [_Random(base.action_space), _Zero(base.action_space)]
    if e.controller is None:
        notes.append(f"{task} has no scripted controller yet (catalogue entry: controller=None)")
    else:
        policies.append(_Scripted(e.controller))
    if runs:
        import torch
        torch.set_num_threads(1)
        for r, c in zip(runs, configs):
            p = _Trained(Path(r), c, model)
            if p.model.observation_space.shape != env.observation_space.shape:
                raise TrainInputError(f"run {r}: its policy observes {p.model.observation_space}"
                                      f", the env gives {env.observation_space}")
            policies.append(p)
    from tqdm import tqdm
    results = []
    trained = sum(p.kind == "trained" for p in policies)
    try:
        with tqdm(total=episodes * (len(policies) + trained), unit="episode",
                  disable=not progress, dynamic_ncols=True) as bar:
            for policy in policies:
                bar.set_description(policy.name)
                eps = []
                for k in range(episodes):
                    eps.append(_episode(policy, env, base, seed + k))
                    bar.update(1)
                results.append(_summary(policy, eps))
                if policy.kind == "trained":   # the same episodes, actions sampled
                    bar.set_description(f"{policy.name}, sampled")
                    policy.deterministic = False
                    eps = []
                    for k in range(episodes):
                        eps.append(_episode(policy, env, base, seed + k))
                        bar.update(1)
                    policy.deterministic = True
                    sampled = _summary(policy, eps)
                    results[-1]["stochastic"] = {k: v for k, v in sampled.items()
                                                 if k not in ("policy", "kind", "run", "model",
                                                              "algo")}
    finally:
        env.close()
    return {"task": task, "episodes": episodes, "seeds": [seed, seed + episodes - 1],
            "env_kwargs": kw, "dt": float(base.parallel.unwrapped.dt),
            "max_steps": int(base.parallel.unwrapped.max_steps), "notes": notes,
            "policies": results}


def _fmt_success(r: dict) -> str:
    if math.isnan(r["success_rate"]):
        return "n/a"
    return f"{r['success_rate']:.0%} ({r['successes']}/{r['episodes']})"


def _fmt_steps(r: dict) -> str:
    if math.isnan(r["steps_to_success_mean"]):
        return "-"
    return f"{r['steps_to_success_mean']:.0f}"


def markdown_table(res: dict) -> str:
    """The results as a short header, a markdown table and the notes."""
    lo, hi = res["seeds"]
    lines = [f"{res['task']}: {res['episodes']} episodes per policy, seeds {lo}..{hi}; one step "
             f"= {res['dt']:g} s, at most {res['max_steps']} steps"
             + (f"; env kwargs {res['env_kwargs']}" if res["env_kwargs"] else ""),
             "",
             "| policy | episodes | success | return | length | steps to success "
             "| success, sampled actions |",
             "|---|---|---|---|---|---|---|"]
    for r in res["policies"]:
        sampled = _fmt_success(r["stochastic"]) if "stochastic" in r else "-"
        lines.append(f"| {r['policy']} | {r['episodes']} | {_fmt_success(r)} | "
                     f"{r['return_mean']:.4g} +- {r['return_std']:.3g} | {r['length_mean']:.0f} | "
                     f"{_fmt_steps(r)} | {sampled} |")
    if any("stochastic" in r for r in res["policies"]):
        lines += ["", "trained policies: success, return, length and steps to success of the "
                  "mean action (deterministic); the last column samples the actions "
                  "(stochastic, as in training; torch seeded with each episode's seed)"]
    if res["notes"]:
        lines.append("")
        lines += [f"note: {n}" for n in res["notes"]]
    return "\n".join(lines) + "\n"


def _clean(value):
    """JSON without NaN (null instead) and with plain Python numbers."""
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return None if math.isnan(value) else float(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value


def write_json(res: dict, path: str | Path) -> Path:
    """The results as JSON (NaN written as null)."""
    path = Path(path)
    path.write_text(json.dumps(_clean(res), indent=2))
    return path
