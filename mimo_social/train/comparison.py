"""``compare``: train several algorithms with several seeds and plot them together.

Every algorithm is trained with seeds 0..n-1 into ``OUT/<algo>_seed<k>``;
:func:`~mimo_social.train.plots.plot_compare` then plots the evaluation returns of all runs
together (the paper's Fig. 8; over environment steps and over wall time) to ``OUT/compare.png``
with the numbers in ``OUT/compare.csv``. ``plot_only`` re-plots existing runs.

``jobs``: runs at a time, each in its own process (``spawn`` start method; ``train`` puts each
process's torch on one thread); a run's files are the same as when the runs go one after another,
apart from its wall times. ``steps`` may be one budget for every algorithm or one per algorithm
(``{"ppo": 100_000, "sac": 20_000}``: SAC costs far more per step); ``algo_kwargs`` likewise
one set for every algorithm or one per algorithm (``{"ppo": {"n_steps": 512}, "sac": {}}``).
"""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path
from typing import Any, Mapping

from .plots import plot_compare
from .runner import train
from .tasks import (ALGOS, COMPARED_ALGOS, TrainInputError, check_algo, check_mode, check_task,
                    task_module)

__all__ = ["compare", "train_all", "finished", "parse_steps_per_algo", "value_per_algo", "kwargs_keyed_by_algo"]


def _train_quiet(kwargs, parent: int):
    """One run of :func:`train_all` in its spawned process; if ``parent`` (the pid of the
    process that started it) ends, the run saves and stops (:class:`~.interrupt.stop_with_parent`)
    and the process exits (an idle pool worker of a dead parent would otherwise spin on)."""
    import warnings

    from .interrupt import exit_code, stop_with_parent
    warnings.filterwarnings("ignore")
    t0 = time.perf_counter()
    with stop_with_parent(parent) as watch:
        train(**kwargs)
    if watch.signalled:         # saved; no one is left to hear of it: the process ends here
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(exit_code(signal.SIGTERM))
    return kwargs["out"], time.perf_counter() - t0


def value_per_algo(name: str, value, algos: list[str], per_algo: bool) -> dict:
    """``{algo: value}``: ``value`` itself for every algorithm, or (``per_algo``) its entries."""
    if not per_algo:
        return {a: value for a in algos}
    missing = [a for a in algos if a not in value]
    if missing:
        raise TrainInputError(f"{name}: no value for {', '.join(missing)} (given for "
                              f"{', '.join(value)}); give one for every algorithm compared")
    return {a: value[a] for a in algos}


def kwargs_keyed_by_algo(kwargs: Mapping[str, Any], algos=ALGOS,
                         example: str = '{"ppo": {"n_steps": 512}, "sac": {"batch_size": 128}}'
                         ) -> bool:
    """Whether ``algo_kwargs`` is keyed by algorithm (``{"ppo": {...}, "sac": {...}}``), the
    algorithms being ``algos`` (SB3's by default; the RLlib sweep passes its own)."""
    named = [k for k in kwargs if k in algos]
    if named and (len(named) < len(kwargs)
                  or not all(isinstance(kwargs[k], Mapping) for k in named)):
        raise TrainInputError(f"algo_kwargs {dict(kwargs)}: give either keyword arguments for "
                              f"every algorithm or one object per algorithm, e.g. {example}")
    return bool(named)


def parse_steps_per_algo(text: str) -> dict[str, int]:
    """``"ppo=100000,sac=20000"`` -> ``{"ppo": 100000, "sac": 20000}`` (a TrainInputError
    saying what is wrong otherwise)."""
    out = {}
    for part in (p.strip() for p in text.split(",")):
        if not part:
            continue
        algo, sep, value = part.partition("=")
        algo = algo.strip()
        try:
            check_algo(algo)
            steps = int(value)
        except (TrainInputError, ValueError):
            steps = None
        if not sep or steps is None or steps < 1:
            raise TrainInputError(f"steps per algorithm {part!r}: expected ALGO=STEPS with ALGO "
                                  f"one of {', '.join(ALGOS)} and STEPS a positive integer, e.g. "
                                  "ppo=100000,sac=20000")
        out[algo] = steps
    if not out:
        raise TrainInputError("steps per algorithm: none given, e.g. ppo=100000,sac=20000")
    return out


def finished(run: Mapping[str, Any]) -> bool:
    """Whether the run ``train(**run)`` would make is already there: ``model.zip`` and a
    ``config.json`` of the same task, algorithm, steps, seed and recipe, not interrupted."""
    out = Path(run["out"])
    if not (out / "model.zip").exists() or not (out / "config.json").exists():
        return False
    import json
    config = json.loads((out / "config.json").read_text())
    return ("wall_time_s" in config and not config.get("interrupted")
            and all(config.get(k) == run.get(k) for k in ("task", "algo", "steps", "seed",
                                                           "recipe")))


def train_all(runs: list[dict], jobs: int = 1, desc: str = "train",
              progress: bool = True, skip_finished: bool = False) -> None:
    """Train every run (``train``'s keyword arguments each): one after another with ``jobs=1``,
    else up to ``jobs`` at a time, each in its own spawned process (one bar over the runs), which
    saves its run and stops if this process ends (killed by SIGTERM, say).
    ``skip_finished``: leave out runs already there (:func:`finished`)."""
    if skip_finished:
        runs = [kw for kw in runs if not finished(kw)]
    if int(jobs) <= 1:
        for kw in runs:
            if train(**kw).get("interrupted"):   # Ctrl-C / SIGTERM: the run saved, stop here
                print(f"{desc}: interrupted in {kw['out']}; the runs after it not started",
                      file=sys.stderr)
                return
        return
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    from tqdm import tqdm
    runs = [{**kw, "progress": False} for kw in runs]   # (one bar over the runs instead)
    with ProcessPoolExecutor(max_workers=int(jobs), mp_context=mp.get_context("spawn")) as ex, \
            tqdm(total=len(runs), unit="run", desc=desc, disable=not progress,
                 dynamic_ncols=True) as bar:
        for path, secs in ex.map(_train_quiet, runs, [os.getpid()] * len(runs)):
            bar.write(f"done {path} in {secs:.0f} s")
            bar.update(1)


def compare(task: str, algos=COMPARED_ALGOS, seeds: int = 3,
            steps: int | Mapping[str, int] = 50_000,
            out: str | Path = "runs/compare", *, jobs: int = 1, plot_only: bool = False,
            mode: str | None = None, algo_kwargs: Mapping[str, Any] | None = None,
            **train_kwargs) -> Path:
    """Train every algorithm with seeds 0..seeds-1 and plot them together; returns the PNG.
    ``steps`` and ``algo_kwargs``: one for every algorithm or a mapping algo -> its own (see the
    module docstring). Multi-agent tasks train in ``mode``; the plot shows the evaluation return
    and success rate averaged across agents, ``compare.csv`` has the per-agent columns too."""
    out = Path(out)
    algos = [check_algo(a) for a in algos]
    check_task(task)
    mode = check_mode(task, mode)
    if mode is not None:
        task_module(task)
        train_kwargs["mode"] = mode
    jobs = int(jobs)
    if jobs < 1:
        raise TrainInputError(f"jobs={jobs}; allowed: a positive integer")
    steps = value_per_algo("steps", steps, algos, isinstance(steps, Mapping))
    algo_kwargs = dict(algo_kwargs or {})
    kwargs = value_per_algo("algo_kwargs", algo_kwargs, algos,
                            kwargs_keyed_by_algo(algo_kwargs))
    runs = [dict(task=task, algo=a, steps=steps[a], seed=s, out=str(out / f"{a}_seed{s}"),
                 algo_kwargs=kwargs[a], **train_kwargs) for a in algos for s in range(int(seeds))]
    if not plot_only:
        from .hyperparams import resolve
        for a in algos:   # every algorithm's keyword arguments checked before any run starts
            resolve(task, a, kwargs[a], mode=mode, steps=steps[a])
        out.mkdir(parents=True, exist_ok=True)
        train_all(runs, jobs, f"compare {task}", train_kwargs.get("progress", True))
    return plot_compare(out, task)
