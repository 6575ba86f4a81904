"""Stacked bar charts of a benchmark report's components: the paper's grid (its Fig. 6) and
the tasks, bodies and infants in one world (its Fig. 7)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .configs import COMPONENTS, MIMO_REFERENCE, TARGETS
from .report import by_name

__all__ = ["COLOURS", "PANELS", "plot_report"]


COLOURS = {"physics": "#4C72B0", "actuation": "#DD8452", "touch": "#DA8BC3",
           "vision": "#64B5CD", "proprioception": "#55A868", "vestibular": "#C44E52",
           "recording": "#8C8C8C", "task": "#8172B3", "other": "#937860"}

#: (figure, panel title, [(configuration, bar label)]): the paper's Fig. 6 and Fig. 7.
PANELS = (
    ("grid", "vision (touch x1)", (("v64", "64²"), ("v128", "128²"), ("default", "256²"),
                                   ("v512", "512²"))),
    ("grid", "touch density (vision 256²)", (("t0.25", "x0.25"), ("t0.5", "x0.5"),
                                             ("default", "x1"), ("t2", "x2"))),
    ("grid", "without", (("no_vision", "no vision"), ("physics_only", "physics\nonly"))),
    ("tasks", "tasks (defaults)", (("free_play", "free_play"), ("high_five", "high_five"),
                                   ("reach", "reach"))),
    ("tasks", "bodies (vision 256², touch x1)", (("default", "mitten,\nspring-d."),
                                                  ("five_fingers", "five\nfingers"),
                                                  ("muscle", "muscle"))),
    ("tasks", "infants in one world (vision 64², touch x1)",
     (("agents_1", "1"), ("agents_2", "2"), ("agents_4", "4"), ("agents_8", "8"))),
)


def _panels(report) -> dict[str, list]:
    """Panels of each figure with the measured bars; unplaced results go to an extra panel."""
    res = by_name(report)
    figs: dict[str, list] = {"grid": [], "tasks": []}
    placed = set()
    for fig, title, bars in PANELS:
        present = [(res[n], label) for n, label in bars if n in res]
        # a panel whose only bar is shown elsewhere (default) says nothing new
        if present and not all(r["name"] == "default" for r, _ in present):
            figs[fig].append((title, present))
            placed.update(r["name"] for r, _ in present)
    rest = [(r, r["name"]) for r in report["results"] if r["name"] not in placed]
    if rest:
        figs["tasks"].append(("other", rest))
    return figs


def _draw_panel(ax, title, bars, scaling=False):
    x = np.arange(len(bars))
    bottom = np.zeros(len(bars))
    for comp in COMPONENTS:
        h = np.array([r["components"].get(comp, 0.0) for r, _ in bars])
        ax.bar(x, h, 0.65, bottom=bottom, label=comp,
               color=COLOURS.get(comp))        # a sense with no colour here: the next default
        bottom += h
    for xi, (r, _) in zip(x, bars):
        label = f"{r['real_s_per_sim_s']:.3f}"
        if scaling and r["n_agents"] > 1:
            label += f"\n{r['real_s_per_sim_s'] / r['n_agents']:.3f}/inf."
        ax.text(xi, r["real_s_per_sim_s"], label, ha="center", va="bottom", fontsize=7)
    if scaling:
        one = next((r for r, _ in bars if r["name"] == "agents_1"), None)
        if one is not None:
            lin = [one["real_s_per_sim_s"] * r["n_agents"] for r, _ in bars]
            ax.plot(x, lin, "k--", marker="_", markersize=14, linewidth=0.8,
                    label="linear (N x 1 infant)")
    ax.set_xticks(x)
    ax.set_xticklabels([label for _, label in bars], fontsize=8)
    ax.set_title(title, fontsize=9)
    return float(bottom.max()) if len(bottom) else 0.0


def _figure(report, panels, title, path, aim=True, share=True):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    widths = [max(2, len(bars)) for _, bars in panels]
    fig = Figure(figsize=(max(6.0, 1.0 * sum(widths) + 1.5) + 1.8, 5.2), dpi=120)
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(panels), sharey=False, squeeze=False,
                        gridspec_kw={"width_ratios": widths})[0]
    tops = [_draw_panel(ax, ptitle, bars, scaling=ptitle.startswith("infants"))
            for ax, (ptitle, bars) in zip(axes, panels)]
    for i, ax in enumerate(axes):
        top = max(tops) if share else tops[i]
        ax.set_ylim(0, max(top * 1.2, TARGETS["default_max"] * 1.15 if aim else 0.0,
                           MIMO_REFERENCE["without_vision"] * 1.15))
        if aim:
            ax.axhline(TARGETS["default_max"], color="#B22222", linestyle="--", linewidth=0.9,
                       label=f"aim for default: {TARGETS['default_max']}")
        ax.axhline(MIMO_REFERENCE["without_vision"], color="0.25", linestyle=":", linewidth=1,
                   label=f"original MIMo,\nwithout vision: {MIMO_REFERENCE['without_vision']}")
        ax.axhline(MIMO_REFERENCE["physics_only"], color="0.55", linestyle=":", linewidth=1,
                   label=f"original MIMo,\nphysics only: {MIMO_REFERENCE['physics_only']}")
        if i and share:
            ax.tick_params(labelleft=False)
        ax.grid(axis="y", linewidth=0.3, alpha=0.6)
    axes[0].set_ylabel("real s per simulated s")
    found = {}
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            found.setdefault(lab, h)
    # components top of the stack first, then the reference lines
    labels = [c for c in reversed(COMPONENTS) if c in found]
    labels += [lab for lab in found if lab not in COMPONENTS]
    fig.legend([found[lab] for lab in labels], labels, loc="center right", fontsize=7,
               frameon=False)
    m = report["machine"]
    fig.suptitle(f"{title}\n{m['cpu']}, {m.get('usable_cores') or m['cores']} cores, MuJoCo "
                 f"{m['mujoco']}, MUJOCO_GL={m['mujoco_gl']} (software rendering)\n"
                 f"original MIMo, default configuration, here: ~{MIMO_REFERENCE['default']:g} "
                 "real s / sim s (off the scale)", fontsize=9)
    fig.tight_layout(rect=(0, 0, 1 - 1.6 / fig.get_figwidth(), 1))
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)


def plot_report(report, path: str | os.PathLike) -> list[Path]:
    """Stacked bar charts of the components: the paper's grid (Fig. 6) at ``path``, tasks,
    bodies and scaling (Fig. 7) at ``<stem>_tasks_scaling.png`` beside it (whichever has bars
    comes first at ``path`` when only one has). Returns the paths written."""
    path = Path(path)
    figs = _panels(report)
    jobs = [("grid", "The paper's grid: one infant, two objects, every sense, recorded"),
            ("tasks", "Tasks, bodies, infants in one world")]
    jobs = [(k, t) for k, t in jobs if figs[k]]
    written = []
    for i, (key, title) in enumerate(jobs):
        out = path if i == 0 else path.with_name(f"{path.stem}_tasks_scaling{path.suffix}")
        _figure(report, figs[key], title, out, aim=key == "grid", share=key == "grid")
        written.append(out)
    return written
