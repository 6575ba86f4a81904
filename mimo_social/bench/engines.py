"""Engines side by side: environment steps per second while training, SB3 and RLlib, 1 and 2
workers, on the same tasks with the same policy, and the scaling efficiency from 1 to 2.

:func:`run` measures every (task, engine, workers) configuration in turn with the measuring
function given for each engine (``measure[engine](task, workers, seconds) -> dict`` with at least
``steps_per_s``; :mod:`mimo_social.train.throughput` has those of SB3 and RLlib, which the
``bench engines`` command passes in: this layer does not import the training layer), then
:func:`efficiencies` gives, per task and engine, ``steps/s with n / (n x steps/s with 1)``.
:func:`markdown` / :func:`plot` write the table and the figure; the results dict is plain JSON.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable, Mapping, Sequence

from .machine import load_average, machine_info

__all__ = ["run", "efficiencies", "markdown", "plot"]

Measure = Callable[[str, int, float], dict]


def run(measure: Mapping[str, Measure], tasks: Sequence[str], workers: Sequence[int] = (1, 2),
        seconds: float = 30.0, *, command: str = "", settings: Mapping | None = None,
        log: Callable[[str], None] | None = print) -> dict:
    """Every task x engine x workers configuration, one after another (``seconds`` of timed
    training each, after a warm-up iteration); the results with the machine and the load."""
    rows = []
    load_before = load_average()
    t0 = time.time()
    for task in tasks:
        for engine, fn in measure.items():
            for n in workers:
                if log:
                    log(f"{task}: {engine} with {n} worker{'s' if n > 1 else ''} ...")
                res = dict(fn(task, n, seconds))
                res.update(task=task, engine=engine, workers=int(n), load=load_average())
                rows.append(res)
                if log:
                    log(f"  {res['steps_per_s']:.0f} env steps/s ({res['env_steps']} steps in "
                        f"{res['seconds']:.1f} s, warm-up {res['warmup_s']:.1f} s)")
    return {"rows": rows, "efficiency": efficiencies(rows), "seconds": seconds,
            "workers": list(workers), "tasks": list(tasks), "engines": list(measure),
            "settings": dict(settings or {}), "command": command, "machine": machine_info(),
            "load_before": load_before,
            "measured": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime(t0)),
            "total_s": round(time.time() - t0, 1)}


def efficiencies(rows: Sequence[dict]) -> list[dict]:
    """Per task and engine, for every worker count n > 1 measured with 1 too:
    ``steps/s(n) / (n * steps/s(1))`` (1.0: perfect scaling) and the speed-up ``steps/s(n) /
    steps/s(1)``."""
    by = {(r["task"], r["engine"], r["workers"]): r["steps_per_s"] for r in rows}
    out = []
    for (task, engine, n), sps in by.items():
        one = by.get((task, engine, 1))
        if n > 1 and one:
            out.append({"task": task, "engine": engine, "workers": n,
                        "speedup": sps / one, "efficiency": sps / (n * one)})
    return out


def markdown(results: dict) -> str:
    """The table (one row per task and engine) and the setting, as Markdown."""
    workers = results["workers"]
    eff = {(e["task"], e["engine"], e["workers"]): e for e in results["efficiency"]}
    by = {(r["task"], r["engine"], r["workers"]): r for r in results["rows"]}
    head = ["task", "engine", *[f"env steps/s, {n} worker{'s' if n > 1 else ''}" for n in workers],
            *[f"efficiency 1->{n}" for n in workers if n > 1],
            "sample / learn s per iteration (1 worker)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for task in results["tasks"]:
        for engine in results["engines"]:
            cells = [f"`{task}`", engine]
            for n in workers:
                r = by.get((task, engine, n))
                cells.append(f"**{r['steps_per_s']:.0f}**" if r else "-")
            for n in workers:
                if n > 1:
                    e = eff.get((task, engine, n))
                    cells.append(f"{e['efficiency']:.0%} ({e['speedup']:.2f}x)" if e else "-")
            r1 = by.get((task, engine, 1))
            cells.append(f"{r1['sample_s']:.2f} / {r1['learn_s']:.2f}" if r1 else "-")
            lines.append("| " + " | ".join(cells) + " |")
    m = results["machine"]
    s = results.get("settings", {})
    text = [
        f"Measured {results['measured']} on {m['cpu']} ({m['usable_cores']} usable cores), "
        f"{m['memory_gb']} GB, Python {m['python']}, MuJoCo {m['mujoco']}; load average "
        f"before: {results['load_before']}."]
    if results["rows"]:
        text += [
            f"{results['seconds']:g} s of timed training per configuration after one warm-up "
            "iteration.", "", *lines, "",
            "Setting: " + ", ".join(f"{k} {v}" for k, v in s.items()) + ". "
            "Env steps are world steps (each gives one sample per agent). Efficiency: "
            "steps/s with n workers / (n x steps/s with 1 worker)."]
    if results.get("to_success"):
        text += ["", "| task | engine | workers | wall time to success | env steps then | "
                 "best success |", "|---|---|---|---|---|---|"]
        for t in results["to_success"]:
            when = (f"**{t['wall_time_s']:.0f} s** ({t['wall_time_s'] / 60:.1f} min)"
                    if t["reached"] else f"not reached in {t['steps_budget']} steps "
                    f"({t['run_wall_time_s']:.0f} s)")
            text.append(f"| `{t['task']}` | {t['engine']} | {t['workers']} | {when} | "
                        f"{t['timesteps'] if t['reached'] else '-'} | {t['best_success']:.0%} |")
        text.append(f"(success threshold {results['to_success'][0]['threshold']:.0%}: the first "
                    "evaluation at or above it; each engine's own PPO defaults, 64x64 tanh MLP)")
    if results.get("command"):
        text += ["", "```", results["command"], "```"]
    return "\n".join(text) + "\n"


def plot(results: dict, path: str | Path) -> Path:
    """Bars of env steps/s per task (one panel each), engine x workers side by side."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    tasks, engines, workers = results["tasks"], results["engines"], results["workers"]
    by = {(r["task"], r["engine"], r["workers"]): r["steps_per_s"] for r in results["rows"]}
    fig, axes = plt.subplots(1, len(tasks), figsize=(4.8 * len(tasks), 3.8), squeeze=False)
    width = 0.8 / len(workers)
    for ax, task in zip(axes[0], tasks):
        x = np.arange(len(engines))
        for j, n in enumerate(workers):
            vals = [by.get((task, e, n), np.nan) for e in engines]
            bars = ax.bar(x + (j - (len(workers) - 1) / 2) * width, vals, width,
                          label=f"{n} worker{'s' if n > 1 else ''}", color=f"C{j}")
            for b, v in zip(bars, vals):
                if np.isfinite(v):
                    ax.annotate(f"{v:.0f}", (b.get_x() + b.get_width() / 2, v), ha="center",
                                va="bottom", fontsize=8)
        ax.set_xticks(x, engines)
        ax.set_title(task)
        ax.set_ylabel("env steps / s while training")
        ax.grid(axis="y", alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
    fig.suptitle(f"PPO training throughput ({results['machine']['usable_cores']} cores)")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
