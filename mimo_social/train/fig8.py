"""``fig8``: the paper's Fig. 8 in one call: PPO and SAC with SB3's defaults on reach, stand-up,
self-body and catch, several seeds, and (``recipes=True``) the shipped recipes beside them.

Every run goes to ``OUT/<task>/<algo>_seed<k>`` (a recipe's to ``OUT/<task>/recipe_seed<k>``),
one env each and no worker process (``jobs`` runs train at a time, each in its own process), so
that seeds and algorithms compete for the machine alike; runs already finished are reused, so an
interrupted reproduction goes on where it stopped. Then, per task, ``compare.png`` /
``compare.csv`` (:func:`~.plots.plot_compare`: return and success over steps and wall time) and
the final models on the same seeded episodes beside random, zero and scripted
(:func:`~.baselines.baselines`, ``baselines.md`` / ``.json``); over all tasks ``fig8.png``
(:func:`~.plots.plot_fig8`) and ``fig8.md``, a table per task with the budgets and the machine.

The budgets (:data:`FIG8_STEPS`) are what this project's 2-core machine affords: SAC makes a
gradient step per environment step and trains at a tenth to a twentieth of PPO's speed here, so
it gets a fifteenth to a twentieth of PPO's steps (docs/baselines.md). Five seeds of both
algorithms on the four tasks take about two and a half hours of one core here.
"""

from __future__ import annotations

import json
import platform
from pathlib import Path
from typing import Mapping, Sequence

from .tasks import TrainInputError

__all__ = ["FIG8_TASKS", "FIG8_STEPS", "fig8", "redraw"]

#: the paper's four learning tasks (its Fig. 8 a-d)
FIG8_TASKS = ("reach", "standup", "selfbody", "catch")
#: environment steps per algorithm and task (see the module docstring)
FIG8_STEPS = {"reach": {"ppo": 150_000, "sac": 10_000},
              "standup": {"ppo": 100_000, "sac": 5_000},
              "selfbody": {"ppo": 100_000, "sac": 5_000},
              "catch": {"ppo": 100_000, "sac": 5_000}}
ALGOS = ("ppo", "sac")


def _runs(tasks, seeds: int, steps, out: Path, eval_episodes: int, recipes: bool,
          recipe_steps: int | None) -> list[dict]:
    from .recipes import load_recipe, validate_recipe
    runs = []
    for task in tasks:
        for algo in ALGOS:
            runs += [dict(task=task, algo=algo, steps=int(steps[task][algo]), seed=s,
                          out=str(out / task / f"{algo}_seed{s}"), n_envs=1, n_cpus=0,
                          eval_episodes=eval_episodes) for s in range(seeds)]
        if recipes:
            r = load_recipe(task)
            validate_recipe(r)
            runs += [r.train_kwargs(s, out / task / f"recipe_seed{s}", recipe_steps)
                     for s in range(seeds)]
    return runs


def _machine() -> str:
    import os
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}"


def _final_table(runs: list[dict]) -> str:
    """Each run's last evaluation (its progress.csv), a markdown table."""
    import csv
    lines = ["| run | steps | wall time | evaluation episodes | success, mean action | "
             "success, sampled | return, mean action |", "|---|---|---|---|---|---|---|"]
    for r in runs:
        run = Path(r["out"])
        if not (run / "progress.csv").exists():
            continue
        with open(run / "progress.csv") as f:
            last = list(csv.DictReader(f))[-1]
        pct = {k: (f"{float(last[k]):.0%}" if last.get(k) not in (None, "", "nan") else "n/a")
               for k in ("eval_success_rate", "eval_success_rate_stochastic")}
        lines.append(f"| {run.name} | {int(float(last['timesteps'])):,} | "
                     f"{float(last['wall_time_s']) / 60:.1f} min | {last.get('eval_episodes', '')} "
                     f"| {pct['eval_success_rate']} | {pct['eval_success_rate_stochastic']} | "
                     f"{float(last['eval_return_mean']):.1f} |")
    return "\n".join(lines) + "\n"


def fig8(out: str | Path = "runs/fig8", seeds: int = 5, tasks: Sequence[str] = FIG8_TASKS, *,
         steps: Mapping[str, Mapping[str, int]] | None = None, jobs: int = 1,
         eval_episodes: int = 3, recipes: bool = False, recipe_steps: int | None = None,
         episodes: int = 10, eval_seed: int = 1000, plot_only: bool = False,
         progress: bool = True) -> Path:
    """Train (unless ``plot_only``), plot and tabulate; returns ``OUT/fig8.png``. ``steps``:
    ``{task: {"ppo": n, "sac": m}}`` over :data:`FIG8_STEPS`; ``episodes``: the final models'
    evaluation episodes per policy (seeds ``eval_seed ..``; 0: no such table, each run's last
    evaluation during training instead)."""
    from .baselines import baselines, markdown_table, write_json
    from .comparison import finished, train_all
    from .plots import plot_compare, plot_fig8

    tasks = list(tasks)
    bad = [t for t in tasks if t not in FIG8_TASKS]
    if bad or not tasks:
        raise TrainInputError(f"tasks {bad or tasks}: allowed: {', '.join(FIG8_TASKS)} (the "
                              "paper's four)")
    seeds, jobs = int(seeds), int(jobs)
    if seeds < 1 or jobs < 1:
        raise TrainInputError(f"seeds={seeds}, jobs={jobs}; allowed: positive integers")
    budget = {t: {**FIG8_STEPS[t], **dict((steps or {}).get(t, {}))} for t in tasks}
    out = Path(out)
    runs = _runs(tasks, seeds, budget, out, int(eval_episodes), recipes, recipe_steps)
    if not plot_only:
        out.mkdir(parents=True, exist_ok=True)
        train_all(runs, jobs, "fig8", progress, skip_finished=True)
    lines = ["# The paper's Fig. 8 on this machine", "",
             f"Machine: {_machine()}. {seeds} seeds per algorithm; SB3 defaults, one env per "
             "run, " + (f"{jobs} runs at a time" if jobs > 1 else "one run at a time") + ".", "",
             f"![Fig. 8]({(out / 'fig8.png').name})", ""]
    for task in tasks:
        ours = [r for r in runs if r["task"] == task]
        done = [r for r in ours if finished(r)]
        missing = [Path(r["out"]).name for r in ours if r not in done]
        if not done:
            continue
        plot_compare(out / task, task)
        table = _final_table(done)
        if episodes > 0:
            res = baselines(task, episodes, eval_seed, [r["out"] for r in done],
                            progress=progress)
            write_json(res, out / task / "baselines.json")
            table = markdown_table(res)
            (out / task / "baselines.md").write_text(table)
        b = budget[task]
        lines += [f"## {task}", "", f"Budget: PPO {b['ppo']:,}, SAC {b['sac']:,} environment "
                  "steps" + (f"; recipe {recipe_steps or 'its own budget'}" if recipes else "")
                  + f". Curves: `{task}/compare.png`.", "", table]
        if missing:   # interrupted, another budget, or not trained yet: not in the table
            lines += ["Not in the table (not trained yet, interrupted or another budget): "
                      f"{', '.join(missing)}.", ""]
    png = plot_fig8(out, tasks)
    (out / "fig8.md").write_text("\n".join(lines) + "\n")
    (out / "fig8.json").write_text(json.dumps({"seeds": seeds, "steps": budget,
                                               "recipes": recipes, "machine": _machine()},
                                              indent=1))
    return png


def _split_compare(csv: Path, task_dir: Path) -> None:
    """``compare.csv`` (a row per evaluation of every run) back into one ``<group>_seed<k>``
    folder per run with its ``progress.csv`` and the ``config.json`` fields the plots read."""
    import csv as csvlib
    with csv.open() as f:
        rows = list(csvlib.DictReader(f))
    runs: dict[tuple[str, str], list[dict]] = {}
    for row in rows:
        runs.setdefault((row["algo"], row["seed"]), []).append(row)
    for (group, seed), rs in runs.items():
        algo, _, recipe = group.partition(" ")
        run = task_dir / f"{'recipe' if recipe else algo}_seed{seed}"
        run.mkdir(parents=True, exist_ok=True)
        fields = [k for k in rs[0] if k not in ("algo", "seed")]
        lines = [",".join(fields)] + [",".join(r[k] for k in fields) for r in rs]
        (run / "progress.csv").write_text("\n".join(lines) + "\n")
        config = {"algo": algo, "seed": int(seed), **({"recipe": task_dir.name} if recipe else {})}
        (run / "config.json").write_text(json.dumps(config))


def redraw(figure_dir: str | Path, recipe_runs: str | Path | None = None,
           png: str | Path | None = None, tasks: Sequence[str] = FIG8_TASKS) -> Path:
    """Fig. 8 drawn again from what a reproduction leaves in the documentation, without its
    models: each task's ``FIGURE_DIR/<task>/compare.csv`` (PPO and SAC, every evaluation of
    every seed) and, with ``recipe_runs``, the recipe runs under ``RECIPE_RUNS/<task>/seed<k>``
    (their ``config.json`` and ``progress.csv``, as ``mimo-social recipe`` writes them; they
    replace any recipe rows of ``compare.csv``). Steps on a log axis when a recipe's budget is
    over five times the learners'. Returns the PNG (default ``FIGURE_DIR/fig8.png``)."""
    import shutil
    import tempfile
    from .plots import plot_fig8

    figure_dir = Path(figure_dir)
    found = [t for t in tasks if (figure_dir / t / "compare.csv").exists()]
    if not found:
        raise TrainInputError(f"{figure_dir}: no <task>/compare.csv for any of {list(tasks)}; "
                              "allowed: a folder that `mimo-social fig8` wrote")
    longest = {}
    with tempfile.TemporaryDirectory() as tmp:
        for task in found:
            _split_compare(figure_dir / task / "compare.csv", Path(tmp) / task)
            ours = [r for r in (sorted(Path(recipe_runs).glob(f"{task}/seed*"))
                                if recipe_runs else []) if (r / "progress.csv").exists()]
            for old in sorted((Path(tmp) / task).glob("recipe_seed*")) if ours else []:
                shutil.rmtree(old)
            for run in ours:
                dest = Path(tmp) / task / f"recipe_{run.name}"
                dest.mkdir(parents=True, exist_ok=True)
                shutil.copy(run / "progress.csv", dest / "progress.csv")
                config = json.loads((run / "config.json").read_text())
                config.setdefault("recipe", task)
                (dest / "config.json").write_text(json.dumps(config))
                longest[task] = max(longest.get(task, 0), int(config.get("steps", 0)))
        log = any(n > 5 * max(FIG8_STEPS[t].values()) for t, n in longest.items())
        return plot_fig8(tmp, found, png or figure_dir / "fig8.png", log_steps=log)
