"""``compare``: train several algorithms with several seeds and plot them together.

Every algorithm is trained with seeds 0..n-1 (``jobs`` processes at a time) into
``OUT/<algo>_seed<k>``; :func:`~mimo_social.train.plots.plot_compare` then plots the evaluation
returns of all runs together (the paper's Fig. 8) to ``OUT/compare.png`` with the numbers in
``OUT/compare.csv``. ``plot_only`` re-plots existing runs.
"""

from __future__ import annotations

import time
from pathlib import Path

from .plots import plot_compare
from .runner import train
from .tasks import ALGOS, check_algo, check_mode, check_task, task_module

__all__ = ["compare"]


def _train_quiet(kwargs):
    import warnings
    warnings.filterwarnings("ignore")
    t0 = time.perf_counter()
    train(**kwargs)
    return kwargs["out"], time.perf_counter() - t0


def compare(task: str, algos=ALGOS, seeds: int = 3, steps: int = 50_000,
            out: str | Path = "runs/compare", *, jobs: int = 1, plot_only: bool = False,
            mode: str | None = None, **train_kwargs) -> Path:
    """Train every algorithm with seeds 0..seeds-1 and plot them together; returns the PNG.
    Multi-agent tasks train in ``mode``; the plot shows the evaluation return and success rate
    averaged across agents, ``compare.csv`` has the per-agent columns too."""
    out = Path(out)
    algos = [check_algo(a) for a in algos]
    check_task(task)
    mode = check_mode(task, mode)
    if mode is not None:
        task_module(task)
        train_kwargs["mode"] = mode
    runs = [dict(task=task, algo=a, steps=steps, seed=s, out=str(out / f"{a}_seed{s}"),
                 **train_kwargs) for a in algos for s in range(int(seeds))]
    if not plot_only:
        out.mkdir(parents=True, exist_ok=True)
        if jobs <= 1:
            for kw in runs:
                train(**kw)
        else:
            import multiprocessing as mp
            from concurrent.futures import ProcessPoolExecutor
            for kw in runs:
                kw["progress"] = False
            with ProcessPoolExecutor(max_workers=jobs, mp_context=mp.get_context("spawn")) as ex:
                for path, secs in ex.map(_train_quiet, runs):
                    print(f"done {path} in {secs:.0f} s", flush=True)
    return plot_compare(out, task)
