"""Training recipes: for each task, how to train a learner for it, shipped as data (issue 30).

A recipe is everything ``mimo-social train`` needs besides the seed and the output directory:
the algorithm, the budget, the mode of a social task and any of :func:`~.runner.train`'s options
(env keyword arguments, SB3 keyword arguments over the shipped hyperparameters, the
observation, a curriculum, a behaviour-cloning warm start, an intrinsic bonus). One TOML file per
task, ``mimo_social/train/recipes/<task>.toml``::

    description = "reach: PPO with SB3's defaults, one env"
    algo = "ppo"
    steps = 600000
    mode = "scripted"            # a social task: one learner, the partner scripted
    status = "2/2 seeds at 100 % (docs/baselines.md)"   # what was measured, where
    model = "final"              # or "best": the model judged (best_model.zip: best evaluation)
    [train]                      # train()'s keyword arguments
    n_envs = 1
    curriculum = "selfbody"

Every key is checked before anything runs (:func:`load_recipe`; ``[train]`` keys against
``train``'s own, with the closest one named). :func:`check_recipe` is the issue's test of a
recipe: train it with each seed (runs already there are reused), then run every final model (or,
with ``model = "best"``, each run's ``best_model.zip``: the best mean evaluation return during
training, early stopping by evaluation) on
the same ``episodes`` seeded episodes, deterministically and with sampled actions, beside the
task's scripted controller, random and zero (:func:`~.baselines.baselines`); a seed passes when
its success rate reaches ``share`` (0.8) of the scripted controller's. It writes
``OUT/recipe.md`` and ``OUT/recipe.json``.
"""

from __future__ import annotations

import difflib
import inspect
import json
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

from .tasks import ALL_TASKS, TrainInputError, check_algo, check_mode, check_task

__all__ = ["Recipe", "DIRECTORY", "shipped_recipes", "load_recipe", "recipe_runs",
           "check_recipe", "recipe_markdown", "PASS_SHARE", "validate_recipe"]

#: where the shipped recipes live (package data)
DIRECTORY = Path(__file__).parent / "recipes"
TOP_KEYS = ("task", "description", "algo", "steps", "mode", "status", "model", "train")
#: the model a recipe is judged by: the final one, or the best evaluated during training
MODELS = ("final", "best")
#: ``train`` keywords a recipe does not set (the command's own, or the top-level keys)
NOT_RECIPE = ("task", "algo", "steps", "seed", "out", "progress", "verbose", "mode", "recipe")
#: a seed passes when its success reaches this share of the scripted controller's (issue 30)
PASS_SHARE = 0.8


@dataclass(frozen=True)
class Recipe:
    name: str
    task: str
    algo: str
    steps: int
    mode: str | None
    train: dict = field(default_factory=dict)
    description: str = ""
    status: str = ""
    source: str = ""
    model: str = "final"

    def train_kwargs(self, seed: int, out: str | Path, steps: int | None = None,
                     progress: bool = True) -> dict:
        """``train``'s keyword arguments for one seed (``steps``: another budget)."""
        kw = dict(task=self.task, algo=self.algo, steps=int(steps or self.steps), seed=int(seed),
                  out=str(out), progress=progress, recipe=self.name, **self.train)
        if self.mode is not None:
            kw["mode"] = self.mode
        return kw


def shipped_recipes() -> list[str]:
    """The names of the shipped recipes (``recipes/<task>.toml``)."""
    return sorted(p.stem for p in DIRECTORY.glob("*.toml"))


def _train_keys() -> list[str]:
    from .runner import train
    return [k for k in inspect.signature(train).parameters if k not in NOT_RECIPE]


def _unknown(key: str, allowed: Sequence[str], where: str) -> TrainInputError:
    close = difflib.get_close_matches(key, allowed, n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return TrainInputError(f"{where}: unknown key {key!r}{hint}; allowed: {', '.join(allowed)}")


def load_recipe(spec: str | Path) -> Recipe:
    """A shipped recipe by task name, or a ``.toml`` file; every key checked."""
    path = Path(spec)
    if str(spec) in ALL_TASKS or (path.suffix != ".toml" and not path.exists()):
        if str(spec) not in shipped_recipes():
            raise TrainInputError(f"recipe {str(spec)!r}: no such shipped recipe; shipped: "
                                  f"{', '.join(shipped_recipes())} (or give a .toml file)")
        path = DIRECTORY / f"{spec}.toml"
    if not path.is_file():
        raise TrainInputError(f"recipe {str(spec)!r}: no such file")
    where = f"recipe {path}"
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as e:
        raise TrainInputError(f"{where}: not valid TOML: {e}") from None
    for key in raw:
        if key not in TOP_KEYS:
            raise _unknown(key, TOP_KEYS, where)
    task = raw.get("task", path.stem)
    try:
        check_task(task)
    except TrainInputError as e:
        raise TrainInputError(f"{where}: {e} (the file's name or its 'task' key)") from None
    for key in ("algo", "steps"):
        if key not in raw:
            raise TrainInputError(f"{where}: no {key!r}; a recipe names its algorithm and its "
                                  "budget (steps)")
    steps = raw["steps"]
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        raise TrainInputError(f"{where}: steps={steps!r}; allowed: a positive integer")
    try:
        algo = check_algo(raw["algo"])
        mode = check_mode(task, raw.get("mode"))
    except TrainInputError as e:
        raise TrainInputError(f"{where}: {e}") from None
    model = raw.get("model", "final")
    if model not in MODELS:
        raise TrainInputError(f"{where}: model={model!r}; allowed: {', '.join(MODELS)} (the "
                              "final model, or best_model.zip: the best mean evaluation return "
                              "during training)")
    train = raw.get("train", {})
    if not isinstance(train, dict):
        raise TrainInputError(f"{where}: [train] must be a table of train()'s keyword arguments")
    allowed = _train_keys()
    for key in train:
        if key not in allowed:
            raise _unknown(key, allowed, f"{where} [train]")
    return Recipe(name=path.stem if path.parent == DIRECTORY else str(path), task=task,
                  algo=algo, steps=steps, mode=mode, train=dict(train),
                  description=str(raw.get("description", "")), status=str(raw.get("status", "")),
                  source=str(path), model=model)


def validate_recipe(recipe: Recipe) -> None:
    """The checks ``train`` makes before anything runs that need no env: the hyperparameters
    (shipped and the recipe's), the warm start's settings, the curriculum file."""
    from .curriculum import load_curriculum
    from .demonstrations import check_bc
    from .hyperparams import resolve
    t = recipe.train
    where = f"recipe {recipe.name}"
    try:
        resolve(recipe.task, recipe.algo, t.get("algo_kwargs"), mode=recipe.mode,
                steps=recipe.steps)
        check_bc(recipe.task, recipe.algo, recipe.mode, t.get("bc_episodes", 0),
                 t.get("bc_epochs", 20), t.get("bc_kwargs"))
        if t.get("curriculum") is not None:
            load_curriculum(t["curriculum"], recipe.task)
        from .growth import parse_growth
        parse_growth(t.get("growth"))
    except TrainInputError as e:
        raise TrainInputError(f"{where}: {e}") from None


def recipe_runs(recipe: Recipe, seeds: Sequence[int], out: str | Path,
                steps: int | None = None, progress: bool = True) -> list[dict]:
    """``train``'s keyword arguments for every seed, into ``OUT/seed<k>``."""
    return [recipe.train_kwargs(s, Path(out) / f"seed{s}", steps, progress) for s in seeds]


def _wall(run: Path) -> float:
    config = json.loads((run / "config.json").read_text())
    return float(config.get("wall_time_s", float("nan")))


def warm_start_steps(run: Path) -> int:
    """The environment steps a run's warm start took before RL (the controller's episodes and
    DAgger's plays, ``config.json["bc"]``; 0 without one): part of a recipe's budget."""
    bc = json.loads((Path(run) / "config.json").read_text()).get("bc") or {}
    return int(bc.get("samples", 0)) + sum(int(d["pairs_added"]) for d in bc.get("dagger", ()))


def check_recipe(spec: str | Path, seeds: Sequence[int] = (0, 1), out: str | Path = "runs/recipe",
                 *, jobs: int = 1, episodes: int = 30, eval_seed: int = 1000,
                 steps: int | None = None, share: float = PASS_SHARE,
                 model: str | None = None, progress: bool = True) -> dict:
    """Train the recipe with every seed (runs already in ``OUT/seed<k>`` reused), evaluate the
    final models beside the scripted controller and write ``OUT/recipe.md`` and ``.json``;
    returns what it wrote. ``model``: ``final`` or ``best`` (default: the recipe's own)."""
    from .baselines import baselines
    from .comparison import finished, train_all

    recipe = load_recipe(spec)
    validate_recipe(recipe)
    seeds = [int(s) for s in seeds]
    if not seeds:
        raise TrainInputError("seeds: none given; allowed: one or more integers")
    out = Path(out)
    runs = recipe_runs(recipe, seeds, out, steps, progress)
    for run in runs:
        there = Path(run["out"]) / "config.json"
        if there.exists() and not finished(run) and (Path(run["out"]) / "model.zip").exists():
            raise TrainInputError(f"{run['out']} holds another run (or an interrupted one) than "
                                  f"recipe {recipe.name} with seed {run['seed']} and "
                                  f"{run['steps']} steps; give another --out")
    out.mkdir(parents=True, exist_ok=True)
    train_all(runs, jobs, f"recipe {recipe.name}", progress, skip_finished=True)
    model = model or recipe.model
    if model not in MODELS:
        raise TrainInputError(f"model={model!r}; allowed: {', '.join(MODELS)}")
    res = baselines(recipe.task, episodes, eval_seed, [r["out"] for r in runs], model=model,
                    progress=progress)
    scripted = next((p for p in res["policies"] if p["kind"] == "scripted"), None)
    target = share * scripted["success_rate"] if scripted else float("nan")
    rows = []
    for run, p in zip(runs, (p for p in res["policies"] if p["kind"] == "trained")):
        det, sampled = p["success_rate"], p["stochastic"]["success_rate"]
        rows.append({"seed": run["seed"], "steps": run["steps"], "wall_time_s": _wall(
            Path(run["out"])), "warm_start_steps": warm_start_steps(Path(run["out"])),
            "success": det, "success_sampled": sampled,
            "return": p["return_mean"], "return_sampled": p["stochastic"]["return_mean"],
            "passes": bool(det >= target), "passes_sampled": bool(sampled >= target)})
    result = {"recipe": recipe.name, "task": recipe.task, "algo": recipe.algo, "model": model,
              "mode": recipe.mode, "train": recipe.train, "episodes": episodes,
              "eval_seeds": res["seeds"], "scripted_success": scripted["success_rate"]
              if scripted else None, "target": target, "share": share, "seeds": rows,
              "passes": bool(rows) and all(r["passes"] for r in rows),
              "passes_sampled": bool(rows) and all(r["passes_sampled"] for r in rows),
              "baselines": res}
    from .baselines import markdown_table, write_json
    (out / "recipe.md").write_text(recipe_markdown(result) + "\n" + markdown_table(res))
    write_json(result, out / "recipe.json")
    return result


def _pct(x: float) -> str:
    return "n/a" if x is None or math.isnan(x) else f"{x:.0%}"


def recipe_markdown(result: Mapping[str, Any]) -> str:
    """The verdict and one row per seed (markdown)."""
    verdict = {(True, True): "passes (mean action and sampled actions)",
               (True, False): "passes with the mean action only",
               (False, True): "passes with sampled actions only",
               (False, False): "does not pass"}[(result["passes"], result["passes_sampled"])]
    lines = [f"Recipe `{result['recipe']}` ({result['task']}, {result['algo'].upper()}"
             + (f", mode {result['mode']}" if result["mode"] else "")
             + f", {result.get('model', 'final')} model): {verdict}. "
             f"Target: {_pct(result['target'])} success ({result['share']:.0%} of the scripted "
             f"controller's {_pct(result['scripted_success'])}), {result['episodes']} episodes "
             f"(seeds {result['eval_seeds'][0]}..{result['eval_seeds'][1]}).", "",
             "| seed | steps (RL + warm start) | wall time | success, mean action | "
             "success, sampled | return, mean action | return, sampled |",
             "|---|---|---|---|---|---|---|"]
    for r in result["seeds"]:
        ws = int(r.get("warm_start_steps", 0))
        lines.append(f"| {r['seed']} | {r['steps']:,}" + (f" + {ws:,}" if ws else "")
                     + f" | {r['wall_time_s'] / 60:.0f} min | "
                     f"{_pct(r['success'])} | {_pct(r['success_sampled'])} | "
                     f"{r['return']:.1f} | {r['return_sampled']:.1f} |")
    return "\n".join(lines) + "\n"
