"""What recording costs: the share of the env's step time spent recording with
:class:`~mimo_social.recording.Recorder`, and the file's size per simulated minute.

``mimo-social bench recording`` runs it (:mod:`mimo_social.cli.bench_recording`); the numbers go
to BENCHMARKS.md and the recorder's docstring.

Both figures are extrapolations, so a run needs a length for them. A recording starts with a
fixed part (the scene's meshes, the viewer's layout: 0.77 MB for two infants without images,
measured as the intercept of file size against run length) that a size per simulated minute
spreads over the run: under :data:`MIN_SIM_SECONDS` it is over a tenth of the smallest
configuration's 14.7 MB per minute (at 0.5 s it read as 107 MB per minute), and the costs then
rest on fewer than 30 alternating blocks of 100 steps. Shorter runs still run, but their cost
and size per minute are left out (``too_short``). The ``--eyes`` comparison takes medians of
per-round costs and needs :data:`MIN_EYE_ROUNDS` rounds of one flush interval each.
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from collections.abc import Mapping
from pathlib import Path

from ..core.random_actions import smooth_random_actions
from ..envs import free_play_v0
from ..recording import Recorder

__all__ = ["BENCH_CONFIGS", "EYE_COST_CONFIG", "EYE_COST_VARIANTS", "bench_eye_cost",
           "bench_recording", "format_eye_table", "format_table", "MIN_SIM_SECONDS",
           "MIN_EYE_ROUNDS", "MIN_EYE_SIM_SECONDS"]

#: simulated seconds a run of :func:`bench_recording` needs for a cost and a size per minute
MIN_SIM_SECONDS = 30.0
#: rounds (flush intervals) :func:`bench_eye_cost` needs for its medians of per-round costs
MIN_EYE_ROUNDS = 5
#: its simulated seconds with the default flush interval of 4 s
MIN_EYE_SIM_SECONDS = 4.0 * MIN_EYE_ROUNDS

#: the configurations of :func:`bench_recording`: env keyword arguments of ``free_play_v0``
BENCH_CONFIGS = {
    "2 infants, no images": {"n_agents": 2},
    "2 infants, touch (skin points)": {"n_agents": 2, "touch": True},
    "2 infants, 2 x 64x64 eyes each": {"n_agents": 2, "vision": {"width": 64, "height": 64}},
}


def _render_threads_cpu() -> float:
    """CPU seconds so far of Mesa's rendering threads (``llvmpipe-*``) of this process (Linux;
    else 0)."""
    total = 0
    try:
        tasks = os.listdir("/proc/self/task")
    except OSError:
        return 0.0
    for tid in tasks:
        try:
            with open(f"/proc/self/task/{tid}/comm") as f:
                if not f.read().startswith("llvmpipe"):
                    continue
            with open(f"/proc/self/task/{tid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            total += int(fields[11]) + int(fields[12])      # utime + stime, in clock ticks
        except (OSError, ValueError, IndexError):
            continue
    return total / os.sysconf("SC_CLK_TCK")


def bench_recording(configs: Mapping[str, dict] | None = None, sim_seconds: float = 60.0,
                    block: int = 100, seed: int = 0, folder: str | Path | None = None,
                    **recorder_options) -> list[dict]:
    """Cost and file size of recording, per configuration (default :data:`BENCH_CONFIGS`).

    Two envs of a configuration take the same smooth random actions (with expressions switching
    about every second), in alternating blocks of ``block`` steps: one plain, one recorded (its
    observations go to :meth:`~mimo_social.recording.Recorder.log_step`). The recording's cost
    is given as a share of the plain env's step time, three ways:

    * ``cpu_pct``: CPU time, the main thread's (env + recorder) plus Rerun's own threads
      (encoding, compressing, writing: the process's CPU time less the main thread's and Mesa's
      rendering threads', read from ``/proc``), against the plain env's main-thread CPU time;
      the most stable figure on a busy machine, and the whole price on one core;
    * ``main_cpu_pct``: the main thread's CPU time alone (what stepping feels while Rerun's
      threads have another core);
    * ``wall_pct``: wall clock, which on a loaded machine also holds waiting for a core.

    Also the wall-clock ms per step of both and the file's size in MB per simulated minute.
    """
    configs = BENCH_CONFIGS if configs is None else configs
    folder = Path(folder) if folder is not None else Path(tempfile.mkdtemp(prefix="mimo_rec_"))
    out = []
    for k, (name, kwargs) in enumerate(configs.items()):
        envs = [free_play_v0.parallel_env(max_steps=10 ** 9, **kwargs) for _ in range(2)]
        n_steps = round(sim_seconds / envs[0].dt)
        agents = envs[0].possible_agents
        acts = [smooth_random_actions(n_steps, envs[0].action_space(a)["motors"].shape[0],
                                      seed + i) for i, a in enumerate(agents)]
        path = folder / f"bench_{k}.rrd"
        obs = [env.reset(seed=seed)[0] for env in envs]
        rec = Recorder(envs[1], path, **recorder_options)
        rec.log_reset(obs[1])
        wall, cpu = [0.0, 0.0], [0.0, 0.0]
        process0, main0, render0 = time.process_time(), time.thread_time(), _render_threads_cpu()
        for start in range(0, n_steps, block):
            for e, env in enumerate(envs):
                t0, c0 = time.perf_counter(), time.thread_time()
                for s in range(start, min(n_steps, start + block)):
                    actions = {a: {"motors": acts[i][0][s], "expression": int(acts[i][1][s])}
                               for i, a in enumerate(agents)}
                    o, rewards, _, _, _ = env.step(actions)
                    if e == 1:
                        rec.log_step(actions, rewards, o)
                wall[e] += time.perf_counter() - t0
                cpu[e] += time.thread_time() - c0
        render = _render_threads_cpu() - render0
        t0, c0 = time.perf_counter(), time.thread_time()
        rec.close()
        wall[1] += time.perf_counter() - t0
        cpu[1] += time.thread_time() - c0
        # every thread but the main one and the renderer's: Rerun's (they end at close, so
        # they are counted through the process's total, which keeps the time of ended threads)
        other_threads = max(0.0, time.process_time() - process0 - (time.thread_time() - main0)
                            - render)
        for env in envs:
            env.close()
        size = path.stat().st_size
        minutes = n_steps * envs[0].dt / 60.0
        out.append({"config": name, "steps": n_steps, "sim_s": n_steps * envs[0].dt,
                    "ms_per_step": 1e3 * wall[0] / n_steps,
                    "ms_per_step_recorded": 1e3 * wall[1] / n_steps,
                    "cpu_pct": 100.0 * (cpu[1] + other_threads - cpu[0]) / cpu[0],
                    "main_cpu_pct": 100.0 * (cpu[1] - cpu[0]) / cpu[0],
                    "wall_pct": 100.0 * (wall[1] - wall[0]) / wall[0],
                    "in_recorder_pct": 100.0 * rec.overhead_s / wall[0],
                    "mb_per_sim_minute": size / 1e6 / minutes, "file_mb": size / 1e6,
                    "rerun_threads_cpu_s": other_threads, "eye_frames": rec.eye_frames,
                    "path": str(path),
                    "too_short": n_steps * envs[0].dt < MIN_SIM_SECONDS - 1e-9})
    return out


def format_table(results: list[dict]) -> str:
    """The results of :func:`bench_recording` as a Markdown table."""
    header = ("| configuration | ms/step plain | ms/step recorded | cost: CPU (all threads) | "
              "CPU (main thread) | wall clock | MB per sim. minute |")
    lines = [header, "|---|---|---|---|---|---|---|"]
    for r in results:
        head = f"| {r['config']} | {r['ms_per_step']:.3f} | {r['ms_per_step_recorded']:.3f} | "
        if r.get("too_short"):
            lines.append(head + "too short | too short | too short | too short |")
        else:
            lines.append(head + f"{r['cpu_pct']:.1f} % | {r['main_cpu_pct']:.1f} % | "
                                f"{r['wall_pct']:.1f} % | {r['mb_per_sim_minute']:.1f} |")
    if any(r.get("too_short") for r in results):
        lines.append(f"\ntoo short: under {MIN_SIM_SECONDS:g} simulated s a run gives no cost "
                     "or size per minute (the file's fixed part and a few blocks' noise would "
                     f"be the figure); give --sim-seconds >= {MIN_SIM_SECONDS:g}")
    return "\n".join(lines)


#: the env of :func:`bench_eye_cost`: 2 infants with touch and 2 x 64x64 eyes each (free play)
EYE_COST_CONFIG = {"n_agents": 2, "touch": True, "vision": {"width": 64, "height": 64}}
#: the runs of :func:`bench_eye_cost`: name -> Recorder keyword arguments (None: not recorded)
EYE_COST_VARIANTS = {
    "plain step": None,
    "recorded, no eyes": {"eyes": False},
    "recorded, eyes (default: 25 Hz)": {},
    "recorded, eyes every frame (100 Hz)": {"eye_every_k_steps": 1},
}


def bench_eye_cost(sim_seconds: float = 40.0, rounds: int | None = None, seed: int = 0,
                   variants: Mapping[str, dict | None] | None = None,
                   config: Mapping | None = None, folder: str | Path | None = None,
                   flush_every_s: float = 4.0, turn: int = 50) -> list[dict]:
    """Side by side in one run: the plain step and the same env recorded without and with eyes
    (default :data:`EYE_COST_VARIANTS`, env :data:`EYE_COST_CONFIG`).

    One env per variant, all taking the same smooth random actions. A round is one flush
    interval (``flush_every_s`` simulated seconds, so that every round of a recorded env holds
    one flush) of every env, run in turns of ``turn`` steps (the order rotating each round), so
    that the envs of a round meet the same load of the machine; ``rounds`` rounds (default:
    ``sim_seconds`` split into flush intervals). Per variant: the medians over the rounds of the wall-clock and the
    stepping thread's CPU ms per step, and of the cost against the plain step in the same round
    (``main_cpu_pct``: stepping thread's CPU time, which a busy machine hardly changes;
    ``wall_pct``); the eye encoder's CPU ms per step (its worker thread) and its share of the
    plain step (``encoder_pct``); the eye frames logged. Rerun's own threads are not counted.
    """
    variants = EYE_COST_VARIANTS if variants is None else variants
    names = list(variants)
    config = dict(EYE_COST_CONFIG if config is None else config)
    folder = Path(folder) if folder is not None else Path(tempfile.mkdtemp(prefix="mimo_rec_"))
    envs = [free_play_v0.parallel_env(max_steps=10 ** 9, **config) for _ in names]
    dt = envs[0].dt
    block = max(1, round(flush_every_s / dt))
    rounds = rounds if rounds is not None else max(1, round(sim_seconds / (block * dt)))
    n_steps = block * rounds
    agents = envs[0].possible_agents
    acts = [smooth_random_actions(n_steps, envs[0].action_space(a)["motors"].shape[0], seed + i)
            for i, a in enumerate(agents)]
    recs, wall, cpu = [], [[] for _ in names], [[] for _ in names]
    try:
        for k, (env, options) in enumerate(zip(envs, variants.values())):
            obs = env.reset(seed=seed)[0]
            rec = None
            if options is not None:
                rec = Recorder(env, folder / f"eyes_{k}.rrd", flush_every_s=flush_every_s,
                               **options)
                rec.log_reset(obs)
            recs.append(rec)
        for r in range(rounds):
            w_round, c_round = [0.0] * len(names), [0.0] * len(names)
            for first in range(r * block, (r + 1) * block, turn):
                for k in [(r + j) % len(names) for j in range(len(names))]:
                    env, rec = envs[k], recs[k]
                    t0, c0 = time.perf_counter(), time.thread_time()
                    for s in range(first, min(first + turn, (r + 1) * block)):
                        actions = {a: {"motors": acts[i][0][s],
                                       "expression": int(acts[i][1][s])}
                                   for i, a in enumerate(agents)}
                        o, rewards, _, _, _ = env.step(actions)
                        if rec is not None:
                            rec.log_step(actions, rewards, o)
                    w_round[k] += time.perf_counter() - t0
                    c_round[k] += time.thread_time() - c0
            for k in range(len(names)):
                wall[k].append(1e3 * w_round[k] / block)
                cpu[k].append(1e3 * c_round[k] / block)
        for rec in recs:
            if rec is not None:
                rec.close()
    finally:
        for rec in recs:
            if rec is not None:
                rec.close()
        for env in envs:
            env.close()
    base = next(k for k, o in enumerate(variants.values()) if o is None)
    med = statistics.median
    out = []
    for k, name in enumerate(names):
        rec = recs[k]
        eyes = getattr(rec, "_eyes", None)
        enc_ms = 1e3 * eyes.encode_cpu_s / n_steps if eyes is not None else 0.0
        out.append({
            "variant": name, "steps": n_steps, "rounds": rounds, "sim_s": n_steps * dt,
            "ms_per_step": med(wall[k]), "cpu_ms_per_step": med(cpu[k]),
            "main_cpu_pct": 100.0 * med([c / b - 1.0 for c, b in zip(cpu[k], cpu[base])]),
            "round_cpu_pct": [100.0 * (c / b - 1.0) for c, b in zip(cpu[k], cpu[base])],
            "wall_pct": 100.0 * med([w / b - 1.0 for w, b in zip(wall[k], wall[base])]),
            "encoder_ms_per_step": enc_ms,
            "encoder_pct": 100.0 * enc_ms / med(cpu[base]),
            "eye_frames": rec.eye_frames if rec is not None else 0,
            "path": str(rec.path) if rec is not None else None,
            "too_short": rounds < MIN_EYE_ROUNDS})
    return out


def format_eye_table(results: list[dict]) -> str:
    """The results of :func:`bench_eye_cost` as a Markdown table."""
    lines = ["| run | ms/step (wall) | ms/step (stepping thread CPU) | cost: stepping thread CPU "
             "| cost: wall clock | eye encoder thread (CPU) | eye frame pairs |",
             "|---|---|---|---|---|---|---|"]
    for r in results:
        plain = r["eye_frames"] == 0 and r["main_cpu_pct"] == 0.0
        cost = "-" if plain else f"{r['main_cpu_pct']:.1f} %"
        wall = "-" if plain else f"{r['wall_pct']:.1f} %"
        if r.get("too_short") and not plain:
            cost = wall = "too short"
        enc = (f"{r['encoder_ms_per_step']:.3f} ms ({r['encoder_pct']:.1f} %)"
               if r["encoder_ms_per_step"] else "-")
        lines.append(f"| {r['variant']} | {r['ms_per_step']:.3f} | {r['cpu_ms_per_step']:.3f} | "
                     f"{cost} | {wall} | {enc} | {r['eye_frames']} |")
    if any(r.get("too_short") for r in results):
        lines.append(f"\ntoo short: {results[0]['rounds']} round(s); the costs are medians of "
                     f"per-round costs and need {MIN_EYE_ROUNDS} rounds of one flush interval "
                     f"(4 simulated s by default): give --sim-seconds >= {MIN_EYE_SIM_SECONDS:g}")
    return "\n".join(lines)
