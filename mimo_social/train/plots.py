"""Pictures of runs: a run's learning curve and several runs compared.

``plot_learning_curve(run)``
    ``learning_curve.png``: evaluation return (mean and std) and training returns against steps,
    and the success rate where the task reports one; one line per agent for multi-agent runs.
``plot_cross_age(result, path)``
    ``cross_age.png`` of :func:`~mimo_social.train.cross_age.evaluate_ages`: success rate and mean
    return (with its spread) against the infant's age, the mean action and sampled actions.
``plot_compare(out)``
    ``compare.png`` / ``compare.csv`` of every ``<algo>_seed<k>`` run below ``out`` (the paper's
    Fig. 8: over environment steps and over wall time side by side; each algorithm's mean over
    seeds with the min-max band and a thin line per seed, PPO red, SAC blue).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from .progress import PROGRESS_FIELDS, progress_agents, read_progress

__all__ = ["COLORS", "steps_axis", "plot_learning_curve", "plot_compare", "plot_fig8",
           "runs_by_group", "plot_cross_age"]

COLORS = {"ppo": "tab:red", "sac": "tab:blue", "ppo recipe": "tab:green",
          "sac recipe": "tab:purple"}



def steps_axis(ax, label: str = "environment steps") -> None:
    """Label an x axis of steps (``label``), its ticks short (``50k``, ``1.2M``) so that they
    do not run into each other on long runs."""
    from matplotlib.ticker import FuncFormatter

    def short(v, _pos):
        if abs(v) >= 1e6:
            return f"{v / 1e6:g}M"
        return f"{v / 1e3:g}k" if abs(v) >= 1e3 else f"{v:g}"
    ax.set_xlabel(label)
    ax.xaxis.set_major_formatter(FuncFormatter(short))

def _interrupted(config: dict) -> str:
    return ", interrupted" if config.get("interrupted") else ""


def plot_learning_curve(run: str | Path, path: str | Path | None = None) -> Path:
    """``learning_curve.png`` of one run (from its ``progress.csv`` and ``episodes.csv``)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    run = Path(run)
    path = Path(path) if path else run / "learning_curve.png"
    p = read_progress(run / "progress.csv")
    config = json.loads((run / "config.json").read_text()) if (run / "config.json").exists() else {}
    agents = progress_agents(p)
    if agents:
        return _plot_agents(run, path, p, config, agents)
    has_success = (np.isfinite(p["eval_success_rate"]).any()
                   or np.isfinite(p.get("eval_success_rate_stochastic", [np.nan])).any())
    fig, axes = plt.subplots(1, 2 if has_success else 1, figsize=(11 if has_success else 6.5, 4),
                             squeeze=False)
    ax = axes[0, 0]
    ep_path = run / "episodes.csv"
    if ep_path.exists():
        with open(ep_path, newline="") as f:
            eps = [(float(r["timesteps"]), float(r["return"])) for r in csv.DictReader(f)]
        if eps:
            x, y = np.array(eps).T
            ax.plot(x, y, ".", ms=2, color="0.6", alpha=0.5, label="training episodes")
    t, m, s = p["timesteps"], p["eval_return_mean"], p["eval_return_std"]
    color = COLORS.get(config.get("algo"), "tab:green")
    sampled = "eval_return_mean_stochastic" in p
    ax.plot(t, m, "-o", ms=3, color=color, label="evaluation, mean action (mean)")
    ax.fill_between(t, m - s, m + s, color=color, alpha=0.2, lw=0)
    if sampled:
        ax.plot(t, p["eval_return_mean_stochastic"], "--s", ms=3, color="black", alpha=0.7,
                label="evaluation, sampled actions (mean)")
    steps_axis(ax)
    ax.set_ylabel("episode return")
    ax.set_title(f"{config.get('task', '?')} - {config.get('algo', '?').upper()} "
                 f"(seed {config.get('seed', '?')})" + _interrupted(config))
    ax.legend(loc="best", fontsize=8)
    ax.grid(alpha=0.3)
    if has_success:
        ax = axes[0, 1]
        ax.plot(t, 100 * p["eval_success_rate"], "-o", ms=3, color=color, label="mean action")
        if sampled:
            ax.plot(t, 100 * p["eval_success_rate_stochastic"], "--s", ms=3, color="black",
                    alpha=0.7, label="sampled actions")
            ax.legend(loc="best", fontsize=8)
        ax.set_ylim(-5, 105)
        steps_axis(ax)
        ax.set_ylabel("evaluation success rate (%)")
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _plot_agents(run: Path, path: Path, p, config: dict, agents: list[str]) -> Path:
    """Learning curve of a multi-agent run: one line per agent (return; success rate)."""
    import matplotlib.pyplot as plt

    success_keys = [f"eval_success_rate_{a}" for a in agents]
    has_success = any(np.isfinite(p[k]).any() for k in success_keys if k in p)
    fig, axes = plt.subplots(1, 2 if has_success else 1, figsize=(11 if has_success else 6.5, 4),
                             squeeze=False)
    colors = {a: f"C{i}" for i, a in enumerate(agents)}
    # line style and marker per agent too: cooperative tasks give the agents the same numbers
    styles = {a: (("-", "o"), ("--", "s"), (":", "^"), ("-.", "D"))[i % 4]
              for i, a in enumerate(agents)}
    ax = axes[0, 0]
    ep_path = run / "episodes.csv"
    if ep_path.exists():
        with open(ep_path, newline="") as f:
            eps = list(csv.DictReader(f))
        for a in agents:
            xy = [(float(r["timesteps"]), float(r["return"])) for r in eps if r.get("agent") == a]
            if xy:
                x, y = np.array(xy).T
                ax.plot(x, y, ".", ms=2, color=colors[a], alpha=0.25)
    t = p["timesteps"]
    for a in agents:
        ls, mk = styles[a]
        ax.plot(t, p[f"eval_return_mean_{a}"], ls=ls, marker=mk, ms=4, color=colors[a],
                label=f"{a} (evaluation, mean action)")
        if f"eval_return_mean_{a}_stochastic" in p:
            ax.plot(t, p[f"eval_return_mean_{a}_stochastic"], ls=ls, marker="x", ms=4,
                    color=colors[a], alpha=0.45, label=f"{a} (sampled actions)")
    steps_axis(ax)
    ax.set_ylabel("episode return")
    ax.set_title(f"{config.get('task', '?')} - {config.get('algo', '?').upper()} "
                 f"{config.get('mode', '')} (seed {config.get('seed', '?')})"
                 + _interrupted(config))
    ax.legend(loc="best", fontsize=8)
    ax.grid(alpha=0.3)
    if has_success:
        ax = axes[0, 1]
        for a in agents:
            ls, mk = styles[a]
            ax.plot(t, 100 * p[f"eval_success_rate_{a}"], ls=ls, marker=mk, ms=4, color=colors[a],
                    label=f"{a} (mean action)")
            if f"eval_success_rate_{a}_stochastic" in p:
                ax.plot(t, 100 * p[f"eval_success_rate_{a}_stochastic"], ls=ls, marker="x",
                        ms=4, color=colors[a], alpha=0.45, label=f"{a} (sampled actions)")
        ax.set_ylim(-5, 105)
        steps_axis(ax)
        ax.set_ylabel("evaluation success rate (%)")
        ax.legend(loc="best", fontsize=8)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _wall_unit(seconds: float) -> tuple[str, float]:
    """The unit of a wall-time axis that ends at ``seconds``: (name, seconds per unit)."""
    if seconds < 120:
        return "s", 1.0
    if seconds < 2 * 3600:
        return "min", 60.0
    return "h", 3600.0


def _curves(ax, runs, xkey: str, xscale: float, key: str, scale: float, color, label: str,
            ls: str = "-"):
    """One algorithm on one axis: a thin line per seed, the mean over seeds (on the union of the
    runs' x values up to the shortest run's end) and the min-max band. Rows without a value are
    left out; a run or a mean with a single evaluation is a marker (its band a vertical bar),
    so that no run in the legend goes undrawn."""
    points = []
    for _, p in runs:
        if key not in p or xkey not in p:
            continue
        ok = np.isfinite(p[xkey]) & np.isfinite(p[key])
        if ok.any():
            points.append((p[xkey][ok], p[key][ok]))
    if not points:
        return
    for x, y in points:
        ax.plot(x / xscale, y * scale, color=color, alpha=0.3, lw=0.8, ls=ls,
                marker="o" if len(x) == 1 else None, ms=4)
    end = min(x[-1] for x, _ in points)
    grid = np.unique(np.concatenate([x[x <= end] for x, _ in points]))
    ys = np.array([np.interp(grid, x, y) for x, y in points]) * scale
    ax.plot(grid / xscale, np.nanmean(ys, axis=0), color=color, lw=2, label=label, ls=ls,
            marker="o", ms=3 if len(grid) > 1 else 6)
    if len(grid) == 1:            # a band of zero width is not drawn: a bar instead
        ax.vlines(grid / xscale, np.nanmin(ys, axis=0), np.nanmax(ys, axis=0), color=color,
                  alpha=0.5, lw=3)
    else:
        ax.fill_between(grid / xscale, np.nanmin(ys, axis=0), np.nanmax(ys, axis=0),
                        color=color, alpha=0.15, lw=0)


def group_name(config: dict) -> str:
    """The curve a run belongs to: its algorithm, ``"<algo> recipe"`` for a recipe's run."""
    return config["algo"] + (" recipe" if config.get("recipe") else "")


def _label(group: str) -> str:
    algo, _, rest = group.partition(" ")
    return f"{algo.upper()} {rest}".strip()


def runs_by_group(out: str | Path) -> dict[str, list]:
    """Every ``*_seed*`` run below ``out`` with a ``progress.csv``: ``{group: [(config,
    progress), ...]}`` (:func:`group_name`)."""
    by: dict[str, list] = {}
    for run in sorted(Path(out).glob("*_seed*")):
        if not (run / "progress.csv").exists():
            continue
        config = json.loads((run / "config.json").read_text())
        by.setdefault(group_name(config), []).append((config, read_progress(run / "progress.csv")))
    return by


def plot_compare(out: str | Path, task: str | None = None) -> Path:
    """``compare.png`` / ``compare.csv`` from every ``<algo>_seed<k>`` run below ``out``.

    The figure has the evaluation return (and, where the task reports one, the success rate)
    against environment steps (left) and against each run's wall time (right; left out when a
    run's ``progress.csv`` has no wall times): per algorithm a thin line per seed, the mean over
    seeds and the min-max band (a run evaluated once: a point; a mean of one point: a point
    with the min-max as a vertical bar)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    by_algo = runs_by_group(out)
    if not by_algo:
        raise FileNotFoundError(f"no runs with a progress.csv below {out}")
    all_runs = [p for runs in by_algo.values() for _, p in runs]
    has_success = any(np.isfinite(p[k]).any() for p in all_runs
                      for k in ("eval_success_rate", "eval_success_rate_stochastic") if k in p)
    has_wall = all("wall_time_s" in p and np.isfinite(p["wall_time_s"]).all() for p in all_runs)
    xaxes = [("timesteps", 1.0, "environment steps")]
    if has_wall:
        unit, secs = _wall_unit(max(p["wall_time_s"][-1] for p in all_runs))
        xaxes.append(("wall_time_s", secs, f"wall time ({unit})"))
    ys = [("eval_return_mean", 1.0, "episode return")]
    if has_success:
        ys.append(("eval_success_rate", 100.0, "success (%)"))
    fig, axes = plt.subplots(len(ys), len(xaxes), figsize=(5.5 * len(xaxes), 4 * len(ys)),
                             squeeze=False)
    rows = []
    fields = ["algo", "seed", *(f for f in PROGRESS_FIELDS if any(f in p for p in all_runs))]
    for p in all_runs:
        fields += [k for k in p if k not in fields]
    for algo, runs in sorted(by_algo.items()):
        color = COLORS.get(algo, None)
        for i, (key, scale, _) in enumerate(ys):
            for j, (xkey, xscale, _) in enumerate(xaxes):
                _curves(axes[i, j], runs, xkey, xscale, key, scale, color,
                        f"{_label(algo)} ({len(runs)} seeds), mean action")
                _curves(axes[i, j], runs, xkey, xscale, key + "_stochastic", scale, color,
                        f"{_label(algo)}, sampled actions", ls="--")
        for config, p in runs:
            for k in range(len(p["timesteps"])):
                rows.append({"algo": algo, "seed": config["seed"],
                             **{name: p[name][k] for name in p}})
    first = next(iter(by_algo.values()))[0][0]
    task = task or first["task"]
    if first.get("mode"):
        task = f"{task} ({first['mode']}, mean over agents)"
    fig.suptitle(task)
    for i, (key, _, ylabel) in enumerate(ys):
        what = "evaluation return" if key == "eval_return_mean" else "evaluation success rate"
        for j, (_, _, xlabel) in enumerate(xaxes):
            ax = axes[i, j]
            ax.set_title(f"{what} (mean over seeds, min-max band; dashed: sampled actions)"
                         if (i, j) == (0, 0) else what, fontsize=9)
            ax.set_xlabel(xlabel)
            if xlabel == "environment steps":
                steps_axis(ax)
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
            if key == "eval_success_rate":
                ax.set_ylim(-5, 105)
    axes[0, 0].legend(loc="best", fontsize=8)
    fig.tight_layout()
    png = out / "compare.png"
    fig.savefig(png, dpi=110)
    plt.close(fig)
    with open(out / "compare.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
    return png


def plot_fig8(out: str | Path, tasks, png: str | Path | None = None,
              log_steps: bool = False) -> Path:
    """The paper's Fig. 8 from ``OUT/<task>/<group>_seed<k>`` runs: a row per task, the
    evaluation return against environment steps (left) and wall time (right); per algorithm (and
    recipe) a thin line per seed, the mean over seeds (solid: mean action; dashed: sampled
    actions) and the min-max band. ``log_steps``: both x axes logarithmic (budgets that differ
    tenfold side by side)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    groups = {t: runs_by_group(out / t) for t in tasks if (out / t).is_dir()}
    groups = {t: g for t, g in groups.items() if g}
    if not groups:
        raise FileNotFoundError(f"no runs with a progress.csv below {out}/<task>")
    fig, axes = plt.subplots(len(groups), 2, figsize=(11, 3.6 * len(groups)), squeeze=False)
    for i, (task, by) in enumerate(groups.items()):
        runs = [r for rs in by.values() for r in rs]
        unit, secs = _wall_unit(max(p["wall_time_s"][-1] for _, p in runs))
        for j, (xkey, xscale, xlabel) in enumerate((("timesteps", 1.0, "environment steps"),
                                                    ("wall_time_s", secs, f"wall time ({unit})"))):
            ax = axes[i, j]
            for group, rs in sorted(by.items()):
                color = COLORS.get(group)
                _curves(ax, rs, xkey, xscale, "eval_return_mean", 1.0, color,
                        f"{_label(group)} ({len(rs)} seeds)")
                _curves(ax, rs, xkey, xscale, "eval_return_mean_stochastic", 1.0, color,
                        None, ls="--")
            ax.set_title(f"{task}: evaluation return", fontsize=10)
            ax.set_xlabel(xlabel)
            if log_steps:
                ax.set_xscale("log")
            if j == 0:
                steps_axis(ax)
            ax.set_ylabel("episode return")
            ax.grid(alpha=0.3)
        axes[i, 0].legend(loc="best", fontsize=8)
    fig.suptitle("mean over seeds and min-max band; solid: mean action, dashed: sampled actions",
                 fontsize=10)
    fig.tight_layout()
    png = Path(png) if png else out / "fig8.png"
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return png


def _training_mark(ax, trained: dict) -> None:
    """Shade the ages a run trained over (a growth range) or mark the one it trained at."""
    if trained.get("range"):
        low, high = trained["range"]
        ax.axvspan(low, high, color="tab:orange", alpha=0.12,
                   label=f"trained over ({trained.get('label') or f'{low:g}-{high:g}'})")
    else:
        age = trained.get("age")
        ax.axvline(18.0 if age is None else float(age), color="tab:orange", ls=":", lw=1.5,
                   label="trained at" + (" (the published 18-month body)" if age is None
                                         else f" {float(age):g} months"))


def plot_cross_age(result: dict, path: str | Path) -> Path:
    """Success rate (%) and mean return (+- std) against age (months), the deterministic and
    the stochastic policy, from :func:`~mimo_social.train.cross_age.evaluate_ages`' result."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = sorted(result["rows"], key=lambda r: r["age_months"])
    x = np.array([r["age_months"] for r in rows])
    col = lambda key: np.array([r[key] for r in rows], float)  # noqa: E731
    fig, (ax_s, ax_r) = plt.subplots(1, 2, figsize=(11, 4))
    styles = (("", "mean action (deterministic)", "-o", "tab:red"),
              ("_stochastic", "sampled actions (stochastic)", "--s", "black"))
    success = False
    for suffix, label, fmt, color in styles:
        rate = col("success_rate" + suffix)
        if np.isfinite(rate).any():
            success = True
            ax_s.plot(x, 100 * rate, fmt, ms=5, color=color, label=label)
        m, s = col("return_mean" + suffix), col("return_std" + suffix)
        ax_r.plot(x, m, fmt, ms=5, color=color, label=label)
        ax_r.fill_between(x, m - s, m + s, color=color, alpha=0.12, lw=0)
    trained = result.get("training_ages") or {}
    pad = max(0.5, 0.04 * float(x.max() - x.min()))
    for ax in (ax_s, ax_r):
        _training_mark(ax, trained)
        ax.set_xlim(float(x.min()) - pad, float(x.max()) + pad)
        ax.set_xlabel("infant age (months)")
        ax.set_xticks(x)
        ax.set_xticklabels([f"{v:g}" for v in x])
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    ax_s.set_ylim(-5, 105)
    ax_s.set_ylabel("success rate (%)")
    if not success:
        ax_s.text(0.5, 0.5, f"{result.get('task', 'this task')} reports no success",
                  transform=ax_s.transAxes, ha="center", va="center", color="0.4")
    ax_r.set_ylabel(f"episode return (mean +- std, {result.get('episodes', '?')} episodes)")
    model = Path(str(result.get("model", "?")))
    fig.suptitle(f"{result.get('task', '?')} - {str(result.get('algo', '?')).upper()}, "
                 f"{model.parent.name}/{model.name}: across ages", fontsize=11)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
