"""Cross-age evaluation: a trained run's policy with its infant at each of several ages.

``evaluate_ages(run, [1, 3, 6, 9, 12], episodes=10)`` reloads the run's model (as
:func:`~mimo_social.train.evaluation.evaluate` does: ``model="best"`` or a path for another, the
``vecnormalize.pkl`` beside it) and, for each age, builds the run's env afresh with the run's
env kwargs and ``age_months`` set to that age, then runs the same ``episodes`` seeded episodes
(seeds ``seed, seed + 1, ...``) with the deterministic policy (the mean action) and with the
stochastic one (sampled actions, torch seeded with ``seed``, on another fresh env). It writes to
``out`` (default: the run's folder):

* ``cross_age.csv``: one row per age (:data:`FIELDS`: mean return, its spread, mean length and
  success rate of each policy; success NaN where the task reports none);
* ``cross_age.md``: the same as a markdown table (also returned, and printed by
  ``mimo-social eval RUN --ages ...``);
* ``cross_age.png``: success rate and mean return against age, both policies
  (:func:`~mimo_social.train.plots.plot_cross_age`);
* ``cross_age.json``: everything, every episode's return and length included.

Before any episode runs every age's env is built and reset once: the observation and action
spaces do not depend on age except the touch skin's size (its points per body part differ a
little by age), so an age whose spaces differ from the model's is a TrainInputError naming the
age and the observation key; an env that cannot reset at an age is one naming the age and the
env's own message. One-learner runs of a one-agent task (``--engine sb3``).
"""

from __future__ import annotations

import csv
import json
import math
import time
from pathlib import Path
from typing import Any, Mapping, Sequence


from .envs import make_env, run_observation
from .evaluation import check_outputs
from .growth import check_ages
from .rollouts import evaluate_policy, load_vecnormalize, vecnormalize_path
from .tasks import TrainInputError, algo_class

__all__ = ["evaluate_ages", "FIELDS", "cross_age_markdown", "space_mismatch"]

#: the columns of ``cross_age.csv``
FIELDS = ("age_months", "episodes", "return_mean", "return_std", "length_mean", "success_rate",
          "return_mean_stochastic", "return_std_stochastic", "length_mean_stochastic",
          "success_rate_stochastic")


def _shapes(space) -> dict[str, tuple]:
    """``{key: shape}`` of a (possibly nested) Dict space, keys joined by ``/``; ``{"": shape}``
    for any other space."""
    subs = getattr(space, "spaces", None)
    if isinstance(subs, Mapping):
        out = {}
        for key, sub in subs.items():
            out.update({(f"{key}/{k}" if k else str(key)): v for k, v in _shapes(sub).items()})
        return out
    return {"": tuple(getattr(space, "shape", None) or ())}


def space_mismatch(env, reference, model_space, age: float) -> str | None:
    """Why the learner's env ``env`` (at ``age`` months) cannot take the model (observation
    space ``model_space``): None when its observation has the model's shapes; else a text naming
    the age and the observation key(s) whose size differs from ``reference``'s (the env the run
    was built with)."""
    if _shapes(env.observation_space) == _shapes(model_space):
        return None   # (the bounds may differ by age: joint ranges grow; the policy takes shapes)
    agent = env.unwrapped.parallel.possible_agents[0]
    got = _shapes(env.unwrapped.parallel.observation_space(agent))
    ref = _shapes(reference.unwrapped.parallel.observation_space(agent))
    keys = [k for k in sorted(set(got) | set(ref)) if got.get(k) != ref.get(k)]
    what = "; ".join(f"observation key {k!r}: shape {got.get(k)} at this age, {ref.get(k)} in the "
                     "run's env" for k in keys) or (
        f"observation {env.observation_space} at this age, {model_space} in the model")
    return (f"age {age:g} months: the observation does not fit the model ({what}); allowed: "
            "ages whose observation matches the model's (the touch skin's points per body part "
            "differ a little by age: try nearby ages, or train without touch)")


def _load(run: Path, config: dict, model: str):
    path = {"final": run / "model.zip", "best": run / "best_model.zip"}.get(model, Path(model))
    if not path.exists():
        raise FileNotFoundError(f"model {path} not found (--model final, best or a .zip path)")
    policy = algo_class(config["algo"]).load(str(path), device="cpu")
    stats = vecnormalize_path(path)
    return path, policy, stats, load_vecnormalize(stats)


def _age_envs(task: str, obs: dict, kw: dict, ages: Sequence[float], policy, seed: int):
    """Every age's env, built afresh and reset once (spaces checked against the model's)."""
    reference = make_env(task, **obs, **kw)
    envs: dict[float, Any] = {}
    try:
        for a in ages:
            try:
                env = make_env(task, **obs, **{**kw, "age_months": a})
            except Exception as e:   # the env's own error names the option and what is allowed
                raise TrainInputError(f"age {a:g} months: {task} cannot be made at this age: "
                                      f"{e}") from None
            envs[a] = env
            why = space_mismatch(env, reference, policy.observation_space, a)
            if why is None and _shapes(env.action_space) != _shapes(policy.action_space):
                why = (f"age {a:g} months: the action space {env.action_space} differs from the "
                       f"model's {policy.action_space}; allowed: ages with the model's actions")
            if why:
                raise TrainInputError(why)
            try:
                env.reset(seed=seed)
            except Exception as e:
                raise TrainInputError(f"age {a:g} months: {task} cannot reset at this age: "
                                      f"{type(e).__name__}: {e}") from None
    except BaseException:
        for env in envs.values():
            env.close()
        raise
    finally:
        reference.close()
    return envs


def _row(age: float, episodes: int, det: dict, sto: dict) -> dict:
    row = {"age_months": age, "episodes": episodes}
    for res, suffix in ((det, ""), (sto, "_stochastic")):
        for key in ("return_mean", "return_std", "length_mean", "success_rate"):
            row[key + suffix] = float(res[key])
    return row


def _pct(x: float) -> str:
    return "n/a" if math.isnan(x) else f"{x:.0%}"


def cross_age_markdown(result: Mapping[str, Any]) -> str:
    """The cross-age table (markdown): one row per age, both policies."""
    lines = [f"Cross-age evaluation of `{result['run']}` ({result['task']}, "
             f"{result['algo'].upper()}, {Path(result['model']).name}): {result['episodes']} "
             f"episodes per age and policy, seeds {result['seed']}-"
             f"{result['seed'] + result['episodes'] - 1}.", "",
             "| age (months) | success, mean action | success, sampled | return, mean action | "
             "return, sampled | length, mean action | length, sampled |",
             "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['age_months']:g} | {_pct(r['success_rate'])} | "
                     f"{_pct(r['success_rate_stochastic'])} | {r['return_mean']:.4g} +- "
                     f"{r['return_std']:.3g} | {r['return_mean_stochastic']:.4g} +- "
                     f"{r['return_std_stochastic']:.3g} | {r['length_mean']:.0f} | "
                     f"{r['length_mean_stochastic']:.0f} |")
    return "\n".join(lines) + "\n"


def _write_csv(path: Path, rows: list[dict]) -> None:
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        for row in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()
                        if k in FIELDS})


def _training_ages(config: Mapping[str, Any]) -> dict:
    """What the run trained at, for the figure: a growth range or one age (None: the
    published 18-month body)."""
    growth = config.get("growth")
    if isinstance(growth, Mapping) and growth.get("ages"):
        return {"range": [float(x) for x in growth["ages"]], "label": growth.get("spec", "")}
    return {"age": (config.get("env_kwargs") or {}).get("age_months")}


def evaluate_ages(run: str | Path, ages, episodes: int = 10, *, model: str = "final",
                  seed: int = 0, out: str | Path | None = None,
                  env_kwargs: Mapping[str, Any] | None = None, progress: bool = False) -> dict:
    """Run ``episodes`` seeded episodes of each policy at each age (``ages``: months 0-33, a
    list or ``"1,3,6"``) and write the cross-age table and figure (module docstring). Returns
    ``{"rows": [...], "csv", "md", "png", "json", "markdown", ...}``."""
    ages = check_ages(ages, "ages")
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise TrainInputError(f"episodes={episodes!r}; allowed: an integer >= 1")
    run = Path(run)
    if not (run / "config.json").exists():
        raise FileNotFoundError(f"{run}/config.json not found: give a directory written by "
                                "'mimo-social train'")
    config = json.loads((run / "config.json").read_text())
    if config.get("mode") is not None or config.get("engine", "sb3") != "sb3":
        raise TrainInputError(f"{run}: a {config.get('engine', 'sb3')} run of --mode "
                              f"{config.get('mode')}; --ages is for one-learner runs of a "
                              "one-agent task trained with --engine sb3")
    if env_kwargs and "age_months" in env_kwargs:
        raise TrainInputError("env_kwargs age_months: the ages come from --ages; allowed: the "
                              "other env options")
    out = Path(out) if out is not None else run
    check_outputs(frames=out)        # a folder that can be written, before anything is loaded
    import torch
    torch.set_num_threads(1)
    path, policy, stats, normalize = _load(run, config, model)
    kw = {k: v for k, v in dict(config.get("env_kwargs", {})).items() if k != "age_months"}
    kw.update(env_kwargs or {})
    obs = run_observation(config)
    task = config["task"]
    envs = _age_envs(task, obs, kw, ages, policy, seed)
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=2 * episodes * len(ages), unit="episode", desc=f"ages {run.name}",
                   dynamic_ncols=True)
    tick = None if bar is None else (lambda: bar.update(1))
    t0 = time.perf_counter()
    rows, per_age = [], {}
    try:
        for a in ages:
            det = evaluate_policy(policy, envs[a], episodes, seed, True, on_episode=tick,
                                  normalize=normalize)
            envs.pop(a).close()
            fresh = make_env(task, **obs, **{**kw, "age_months": a})
            try:
                with torch.random.fork_rng(devices=[]):
                    torch.manual_seed(seed)
                    sto = evaluate_policy(policy, fresh, episodes, seed, False, on_episode=tick,
                                          normalize=normalize)
            finally:
                fresh.close()
            rows.append(_row(a, episodes, det, sto))
            per_age[f"{a:g}"] = {"deterministic": {k: det[k] for k in ("returns", "lengths")},
                                 "stochastic": {k: sto[k] for k in ("returns", "lengths")}}
    finally:
        for env in envs.values():
            env.close()
        if bar is not None:
            bar.close()
    out.mkdir(parents=True, exist_ok=True)
    result = {"run": str(run), "task": task, "algo": config["algo"], "model": str(path),
              "vecnormalize": str(stats) if stats.is_file() else None, "episodes": episodes,
              "seed": seed, "ages": ages, "env_kwargs": kw, "rows": rows, "episodes_by_age":
              per_age, "training_ages": _training_ages(config),
              "wall_time_s": round(time.perf_counter() - t0, 2)}
    result["markdown"] = cross_age_markdown(result)
    files = {k: out / f"cross_age.{k}" for k in ("csv", "md", "png", "json")}
    _write_csv(files["csv"], rows)
    files["md"].write_text(result["markdown"])
    from .plots import plot_cross_age
    plot_cross_age(result, files["png"])
    result.update({k: str(p) for k, p in files.items()})
    files["json"].write_text(json.dumps(result, indent=2, default=float))
    return result
