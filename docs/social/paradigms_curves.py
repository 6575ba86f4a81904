"""The PPO learning curves of docs/social/paradigms.md (paradigms_ppo.png), issue 19.

    python docs/social/paradigms_curves.py RUNS OUT.png

RUNS holds, per paradigm (still_face, contingency, imitation), the folder ``<task>/ppo_seed0``
written by ``mimo-social compare`` (episodes.csv: every training episode's return; progress.csv:
the evaluations) and ``<task>.json`` written by ``mimo-social paradigm <task> --json`` (the
scripted and random learners' returns on the same settings, drawn as reference lines;
contingency: the live condition's shared-smile steps, which is its reward).
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np

TASKS = ("still_face", "contingency", "imitation")


def _read(path: Path) -> list[dict]:
    with open(path) as f:
        return list(csv.DictReader(f))


def _reference(task: str, data: dict) -> dict[str, float]:
    out = {}
    for r in data["learners"]:
        if r["spec"] not in ("scripted", "random", "zero"):
            continue
        s = r["summary"]
        if task == "still_face":
            out[r["spec"]] = s["return"][0]
        elif task == "contingency":
            max_steps = data["env_kwargs"].get("max_steps", 2000)
            out[r["spec"]] = s["live"]["shared_fraction"][0] * max_steps
        else:
            out[r["spec"]] = s["all"]["return"]
    return out


def main(runs: str, out: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    runs = Path(runs)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    for ax, task in zip(axes, TASKS):
        run = runs / task / "ppo_seed0"
        eps = _read(run / "episodes.csv")
        x = np.array([float(e["timesteps"]) for e in eps])
        y = np.array([float(e["return"]) for e in eps])
        ax.plot(x, y, ".", color="0.7", ms=3, label="training episode")
        k = max(1, len(y) // 15)
        if len(y) >= k:
            smooth = np.convolve(y, np.ones(k) / k, mode="valid")
            ax.plot(x[k - 1:], smooth, color="tab:blue", label=f"training, mean of {k}")
        prog = _read(run / "progress.csv")
        ax.plot([float(p["timesteps"]) for p in prog],
                [float(p["eval_return_mean"]) for p in prog], "o-", color="tab:red",
                label="evaluation (deterministic)")
        ref = runs / f"{task}.json"
        if ref.exists():
            for (name, value), style in zip(_reference(task, json.loads(ref.read_text())).items(),
                                            ("--", ":", "-.")):
                ax.axhline(value, color="k", ls=style, lw=1, label=f"{name} ({value:.3g})")
        ax.set_title(f"{task}_v0: PPO, one seed")
        ax.set_xlabel("environment steps")
        ax.set_ylabel("episode return")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=90)


if __name__ == "__main__":
    main(*sys.argv[1:3])
