"""Soak: long runs that look for what grows (``mimo-social bench soak``).

Two phases in one process, each driven by smooth random actions
(:func:`mimo_social.core.random_actions.random_action_block`) and reset with a new seed at the
end of every episode:

* ``touch``: free play with touch (default 1e6 steps);
* ``vision+recording``: free play with two 64x64 eyes, every episode recorded by a
  :class:`~mimo_social.recording.RecordingParallelEnv` to its own ``.rrd`` file in a temporary
  folder (so the recordings are many: one per ``episode_steps``; the closed files are deleted as
  it goes unless ``keep_recordings``), default 1e5 steps.

An ended episode is followed at once by a reset (as vector envs do in training), so a recording
is open at every sample; ``recordings`` counts the files opened.

Every ``sample_every`` steps (and at the start and end of each phase) it samples the process's
resident memory (``VmRSS`` of ``/proc/self/status``, MB), its OS threads (``/proc/self/task``)
and open file descriptors (``/proc/self/fd``). :func:`soak` returns per phase the steps per
second and the growth of each per 100k steps: the slope of a least-squares line through the
samples after the warm-up (the first ``warmup`` share of the phase's steps, when caches and
pools fill; at least :data:`WARMUP_EPISODES` episodes, the first recordings' rotation), times
1e5. :func:`write_outputs` writes the samples as ``soak.csv``, the figures as ``soak.json`` and
the three curves against steps as ``soak.png``.

What a growth figure can resolve: resident memory jitters by about :data:`RSS_JITTER_MB` in a
process that does not grow (allocator pages taken and given back; measured here after the
warm-up: up to 0.7 MB), so a line fitted over ``W`` steps after the warm-up resolves about
``RSS_JITTER_MB * 1e5 / W`` MB per 100k steps (``resolution_mb_per_100k``). A phase needs at
least :data:`MIN_FIT_STEPS` steps after its warm-up (5 MB per 100k: a leak of 50 bytes a step)
for its growth to mean anything (:func:`min_phase_steps`: 22,223 steps with the defaults); a
shorter phase still runs (its steps per second are measured) but its growth figures are
``None`` and the summary says "too short" with the minimum. (Extrapolated from 400 steps, the
first episode's allocations read as "+1670 MB per 100k steps".)
"""

from __future__ import annotations

import csv
import importlib.util
import json
import math
import os
import shutil
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..core.random_actions import random_action_block
from ..envs import free_play_v0
from ..util.checks import check_int, check_number

__all__ = ["PHASES", "METRICS", "process_sample", "soak", "write_outputs", "format_summary",
           "min_phase_steps", "warmup_steps", "short_phases", "MIN_FIT_STEPS", "RSS_JITTER_MB",
           "WARMUP_EPISODES"]

#: the phases of a soak, in the order they run
PHASES = ("touch", "vision+recording")
#: what is sampled: (key, label with unit)
METRICS = (("rss_mb", "resident memory (MB)"), ("threads", "OS threads"),
           ("fds", "open file descriptors"))
#: MB: how much the resident memory of a process that does not grow moves between samples
RSS_JITTER_MB = 1.0
#: steps after the warm-up a growth figure needs: it then resolves RSS_JITTER_MB * 1e5 /
#: MIN_FIT_STEPS = 5 MB per 100k steps
MIN_FIT_STEPS = 20_000
#: the warm-up covers at least this many episodes (the first reset and recording rotation)
WARMUP_EPISODES = 2
CSV_FIELDS = ("phase", "step", "total_step", "wall_s", "rss_mb", "threads", "fds",
              "steps_per_s", "recordings")


def process_sample() -> dict[str, float]:
    """This process's resident memory (MB), OS threads and open file descriptors, read from
    ``/proc/self`` (NaN each where it cannot be read, e.g. not on Linux)."""
    out = {"rss_mb": math.nan, "threads": math.nan, "fds": math.nan}
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    out["rss_mb"] = int(line.split()[1]) / 1024.0    # kB
                    break
    except (OSError, ValueError, IndexError):
        pass
    for key, folder in (("threads", "/proc/self/task"), ("fds", "/proc/self/fd")):
        try:
            out[key] = float(len(os.listdir(folder)))
        except OSError:
            pass
    return out


def warmup_steps(n_steps: int, episode_steps: int, warmup: float) -> float:
    """The steps of a phase of ``n_steps`` left out of the growth fit: the ``warmup`` share of
    them, at least :data:`WARMUP_EPISODES` episodes of ``episode_steps``."""
    return max(warmup * n_steps, WARMUP_EPISODES * episode_steps)


def min_phase_steps(episode_steps: int = 1000, warmup: float = 0.1) -> int:
    """The fewest steps of a phase whose growth figures mean something: its warm-up
    (:func:`warmup_steps`) and then :data:`MIN_FIT_STEPS`."""
    by_share = math.ceil(MIN_FIT_STEPS / (1.0 - warmup))
    return max(by_share, WARMUP_EPISODES * episode_steps + MIN_FIT_STEPS)


def short_phases(steps: int, vision_steps: int, episode_steps: int = 1000,
                 warmup: float = 0.1) -> dict[str, int]:
    """``{phase: its steps}`` of the phases that run (steps > 0) but too few steps for a growth
    figure (fewer than :func:`min_phase_steps`)."""
    least = min_phase_steps(episode_steps, warmup)
    return {p: n for p, n in zip(PHASES, (steps, vision_steps)) if 0 < n < least}


def growth_per_100k(steps, values, warmup_step: float = 0.0) -> float:
    """Slope of the least-squares line through ``(steps, values)`` with ``step >= warmup_step``,
    per 100k steps (NaN with fewer than two such samples or a NaN value)."""
    s = np.asarray(steps, float)
    v = np.asarray(values, float)
    keep = s >= warmup_step
    s, v = s[keep], v[keep]
    if len(s) < 2 or np.ptp(s) == 0 or not np.isfinite(v).all():
        return math.nan
    return float(np.polyfit(s, v, 1)[0] * 1e5)


def _phase_env(phase: str, episode_steps: int, vision_size: int):
    if phase == "touch":
        return free_play_v0.parallel_env(n_agents=1, touch=True, max_steps=episode_steps)
    return free_play_v0.parallel_env(n_agents=1, max_steps=episode_steps,
                                     vision={"width": vision_size, "height": vision_size})


def _run_phase(phase: str, n_steps: int, seed: int, sample_every: int, episode_steps: int,
               vision_size: int, folder: Path, keep_recordings: bool, on_steps: Callable,
               total_offset: int, rows: list) -> dict:
    from ..recording import RecordingParallelEnv

    env = _phase_env(phase, episode_steps, vision_size)
    recorder = None
    if phase != "touch":
        recorder = env = RecordingParallelEnv(env, folder / "ep{episode:06d}.rrd",
                                              every_k_episodes=1)
    episode = 0                                       # episodes ended so far
    env.reset(seed=seed)
    t_start = time.perf_counter()
    last_t, last_step = t_start, 0

    def sample(step):
        nonlocal last_t, last_step
        now = time.perf_counter()
        rate = (step - last_step) / (now - last_t) if step > last_step else math.nan
        last_t, last_step = now, step
        rows.append({"phase": phase, "step": step, "total_step": total_offset + step,
                     "wall_s": round(now - t_start, 3), **process_sample(),
                     "steps_per_s": rate,
                     "recordings": len(recorder.paths) if recorder is not None else 0})

    sample(0)
    done, chunk = 0, 0
    try:
        while done < n_steps:
            n = min(sample_every, n_steps - done)
            block_seed = int(np.random.SeedSequence([seed, chunk]).generate_state(1)[0])
            for k, actions in enumerate(random_action_block(env, n, block_seed), 1):
                env.step({a: actions[a] for a in env.agents})
                if not env.agents:              # reset at once, as vector envs do in training
                    episode += 1
                    env.reset(seed=seed + episode)
                    if recorder is not None and not keep_recordings:
                        for p in recorder.paths[:-1]:     # closed ones: only the last is open
                            if p.exists():
                                p.unlink()
                if k % 1000 == 0:
                    on_steps(1000)
            done += n
            chunk += 1
            on_steps(n % 1000)
            sample(done)
    finally:
        env.close()
    wall = time.perf_counter() - t_start
    return {"steps": n_steps, "wall_s": wall, "steps_per_s": n_steps / wall if wall > 0 else 0.0,
            "episodes": episode,                      # ended ones
            "recordings": len(recorder.paths) if recorder is not None else 0}


def soak(steps: int = 1_000_000, vision_steps: int = 100_000, *, seed: int = 0,
         sample_every: int = 10_000, episode_steps: int = 1000, vision_size: int = 64,
         warmup: float = 0.1, folder: str | Path | None = None, keep_recordings: bool = False,
         progress: bool = True) -> dict:
    """Run both phases (``steps`` of touch, ``vision_steps`` of vision + recording; a phase with
    0 steps is skipped) and return ``{"settings", "phases": {phase: figures}, "samples"}``.

    Each phase is sampled every ``min(sample_every, steps // 20)`` steps (at least 20 samples
    a phase); its figures are ``steps``, ``wall_s``, ``steps_per_s``, ``episodes``,
    ``recordings``, the first and last sample, ``warmup_steps``, ``min_steps``,
    ``resolution_mb_per_100k`` and ``growth_per_100k[metric]`` (see the module docstring; the
    warm-up is the first ``warmup`` share of the phase's steps, at least
    :data:`WARMUP_EPISODES` episodes; ``None`` each when the phase has fewer than
    ``min_steps``). Recordings go to ``folder`` (default: a temporary folder, removed at the
    end).
    """
    steps = check_int("soak", "steps", steps, lo=0)
    vision_steps = check_int("soak", "vision_steps", vision_steps, lo=0)
    seed = check_int("soak", "seed", seed, lo=0)
    sample_every = check_int("soak", "sample_every", sample_every, lo=1)
    episode_steps = check_int("soak", "episode_steps", episode_steps, lo=1)
    vision_size = check_int("soak", "vision_size", vision_size, lo=1)
    warmup = check_number("soak", "warmup", warmup, lo=0.0, hi=0.9)
    if steps + vision_steps == 0:
        raise ValueError("soak: steps=0 and vision_steps=0; give at least one phase some steps")
    own_folder = folder is None
    folder = Path(tempfile.mkdtemp(prefix="mimo_soak_")) if own_folder else Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=steps + vision_steps, unit="step", desc="soak", dynamic_ncols=True)
    rows: list[dict] = []
    phases: dict[str, Any] = {}
    offset = 0
    try:
        for phase, n in zip(PHASES, (steps, vision_steps)):
            if n == 0:
                continue
            if bar is not None:
                bar.set_description(f"soak: {phase}")
            every = max(1, min(sample_every, n // 20))
            first = len(rows)
            res = _run_phase(phase, n, seed, every, episode_steps, vision_size, folder,
                             keep_recordings, bar.update if bar is not None else (lambda k: None),
                             offset, rows)
            mine = rows[first:]
            warm = warmup_steps(n, episode_steps, warmup)
            least = min_phase_steps(episode_steps, warmup)
            res["sample_every"] = every
            res["first"] = {k: mine[0][k] for k, _ in METRICS}
            res["last"] = {k: mine[-1][k] for k, _ in METRICS}
            res["warmup_steps"] = int(math.ceil(warm))
            res["min_steps"] = least
            res["resolution_mb_per_100k"] = (round(RSS_JITTER_MB * 1e5 / (n - warm), 3)
                                             if n >= least else None)
            res["growth_per_100k"] = {
                k: round(growth_per_100k([r["step"] for r in mine], [r[k] for r in mine],
                                         warm), 3) + 0.0 if n >= least else None
                for k, _ in METRICS}                                 # + 0.0: no "-0.0"
            phases[phase] = res
            offset += n
    finally:
        if bar is not None:
            bar.close()
        if own_folder and not keep_recordings:
            shutil.rmtree(folder, ignore_errors=True)
    settings = {"steps": steps, "vision_steps": vision_steps, "seed": seed,
                "sample_every": sample_every, "episode_steps": episode_steps,
                "vision_size": vision_size, "warmup": warmup,
                "recordings_folder": None if own_folder and not keep_recordings else str(folder)}
    return {"settings": settings, "phases": phases, "samples": rows}


def format_summary(result: dict) -> str:
    """The figures as a small text table: per phase steps/s and growth per 100k steps."""
    lines = [f"{'phase':<18} {'steps':>9} {'steps/s':>8} {'recs':>5}  "
             f"{'RSS MB (first->last)':>21} {'MB/100k':>8} {'threads/100k':>12} "
             f"{'fds/100k':>9}"]
    for phase, r in result["phases"].items():
        g = r["growth_per_100k"]
        rss = f"{r['first']['rss_mb']:.0f} -> {r['last']['rss_mb']:.0f}"
        head = (f"{phase:<18} {r['steps']:>9} {r['steps_per_s']:>8.0f} "
                f"{r['recordings']:>5}  {rss:>21} ")
        if g["rss_mb"] is None:
            lines.append(head + f"too short for a growth figure: give it at least "
                                f"{r['min_steps']} steps")
        else:
            lines.append(head + f"{g['rss_mb']:>8.2f} {g['threads']:>12.2f} {g['fds']:>9.2f}"
                         f"  (+-{r['resolution_mb_per_100k']:.2f} MB/100k)")
        lines.append(f"{'':<18} threads {r['first']['threads']:.0f} -> "
                     f"{r['last']['threads']:.0f}, fds {r['first']['fds']:.0f} -> "
                     f"{r['last']['fds']:.0f}")
    return "\n".join(lines)


def write_outputs(result: dict, out: str | Path, command: str | None = None) -> dict[str, Path]:
    """``soak.csv`` (the samples), ``soak.json`` (settings and figures) and ``soak.png`` (the
    three metrics against steps, one column per phase; left out without matplotlib) in
    ``out``; returns the paths written."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"csv": out / "soak.csv", "json": out / "soak.json"}
    with open(paths["csv"], "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_FIELDS)
        w.writeheader()
        for r in result["samples"]:
            w.writerow({k: r[k] for k in CSV_FIELDS})
    summary = {"settings": result["settings"], "phases": result["phases"]}
    if command:
        summary["command"] = command
    paths["json"].write_text(json.dumps(summary, indent=2, default=float))
    if importlib.util.find_spec("matplotlib") is None:
        return paths
    paths["png"] = out / "soak.png"
    plot(result, paths["png"])
    return paths


def plot(result: dict, path: str | Path) -> None:
    """The three metrics against the phase's steps, one column per phase, with the fitted line
    after the warm-up and its growth per 100k steps in the title."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter

    def short(x, _pos=None):           # 250000 -> 250k, 1000000 -> 1M
        if abs(x) >= 1e6:
            return f"{x / 1e6:g}M"
        return f"{x / 1e3:g}k" if abs(x) >= 1e3 else f"{x:g}"

    phases = list(result["phases"])
    fig = Figure(figsize=(5.0 * len(phases), 7.5), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(METRICS), len(phases), squeeze=False)
    warm = result["settings"]["warmup"]
    for j, phase in enumerate(phases):
        r = result["phases"][phase]
        rows = [s for s in result["samples"] if s["phase"] == phase]
        x = np.array([s["step"] for s in rows], float)
        for i, (key, label) in enumerate(METRICS):
            ax = axes[i, j]
            y = np.array([s[key] for s in rows], float)
            ax.plot(x, y, "o-", ms=3, lw=1, color="#4C72B0")
            g = r["growth_per_100k"][key]
            keep = x >= r["warmup_steps"]
            if g is not None and np.isfinite(g) and keep.sum() >= 2:
                k, c = np.polyfit(x[keep], y[keep], 1)
                ax.plot(x[keep], k * x[keep] + c, "--", color="#C44E52", lw=1)
            growth = (f"growth {g:+.2f} per 100k steps" if g is not None else
                      f"too short for a growth figure (min {r['min_steps']} steps)")
            ax.set_title(f"{phase}: {label}\n{growth}", fontsize=9)
            ax.set_ylabel(label, fontsize=8)
            ax.tick_params(labelsize=7)
            ax.xaxis.set_major_formatter(FuncFormatter(short))
            if np.isfinite(y).any() and np.nanmax(y) - np.nanmin(y) < 1e-9:
                ax.set_ylim(np.nanmin(y) - 1, np.nanmax(y) + 1)   # flat: show it flat
            if i == len(METRICS) - 1:
                ax.set_xlabel(f"steps ({r['steps_per_s']:.0f} steps/s, "
                              f"{r['recordings']} recordings)" if phase != "touch"
                              else f"steps ({r['steps_per_s']:.0f} steps/s)", fontsize=8)
    fig.suptitle("mimo-social bench soak: growth after a warm-up of "
                 f"{warm:.0%} of each phase's steps (at least {WARMUP_EPISODES} episodes)",
                 fontsize=10)
    fig.savefig(str(path), dpi=110)
