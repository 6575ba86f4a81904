"""``compare --engine rllib``: seeds x algorithms as Ray Tune trials, then the compare plot.

``compare_rllib(task, algos=("ppo",), seeds=3, steps=50_000, out="runs/compare", *, mode=None,
address=None, num_cpus=None, num_env_runners=1, num_envs_per_runner=1, num_cpus_per_learner=1,
num_gpus_per_learner=0, max_concurrent=None, plot_only=False, algo_kwargs=None,
**train_kwargs) -> Path``

Every (algorithm, seed) pair is one Tune trial (a grid search over ``algo`` and ``seed``) that
runs :func:`~mimo_social.train.rllib.runner.train_rllib` into ``OUT/<algo>_seed<k>``: the same
run directory as the SB3 path's (``config.json``, ``progress.csv`` with per-agent columns,
``episodes.csv``, ``learning_curve.png``, checkpoints), so
:func:`~mimo_social.train.plots.plot_compare` draws ``OUT/compare.png`` / ``OUT/compare.csv``
from them as it does for ``compare`` with SB3 (each algorithm's mean over seeds with the min-max
band, over environment steps and over wall time).

Resources and parallelism
    A trial reserves a placement group of one bundle for its learner (``num_cpus_per_learner``
    CPUs, ``num_gpus_per_learner`` GPUs) and one CPU bundle per env runner; the runners the
    algorithm starts are placed in it. Tune runs as many trials at once as the cluster's free
    resources hold (``max_concurrent`` caps it): on a cluster, trials spread over the nodes.
    ``num_env_runners=0`` samples in the trial's own process (one CPU a trial).

Ray
    ``address`` (``"auto"`` or ``HOST:PORT``) joins a running cluster; without one a local Ray
    starts with ``num_cpus`` (default: all the machine's). Ray is shut down at the end only if
    this call started it. On a multi-node cluster ``out`` must be a path every node can write
    (a shared file system): each trial writes its run directory on the node that runs it.
    Tune's own bookkeeping goes to ``OUT/_tune``.

``steps`` and ``algo_kwargs``: one for every algorithm or one per algorithm, as in
:func:`mimo_social.train.compare`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from ..comparison import kwargs_keyed_by_algo, value_per_algo
from ..plots import plot_compare
from ..tasks import TrainInputError, check_mode, check_task
from .config import RLLIB_ALGOS, check_algo

__all__ = ["compare_rllib", "trial_resources"]


def trial_resources(num_env_runners: int = 1, num_cpus_per_learner: float = 1,
                    num_gpus_per_learner: float = 0) -> list[dict]:
    """The placement-group bundles of one trial: the learner's (the trial's own process), then
    one CPU per env runner."""
    learner = {"CPU": float(num_cpus_per_learner)}
    if num_gpus_per_learner:
        learner["GPU"] = float(num_gpus_per_learner)
    return [learner] + [{"CPU": 1.0} for _ in range(int(num_env_runners))]


def _trial(config: dict) -> None:
    """One Tune trial: one training run into its run directory, then its last evaluation as the
    trial's result."""
    import math
    import time
    import warnings

    from ray import tune

    from .runner import train_rllib

    warnings.filterwarnings("ignore")
    kwargs = dict(config["runs"][f"{config['algo']}_seed{config['seed']}"])
    started = time.time()
    res = train_rllib(**kwargs)
    last = res["last_eval"]
    metrics = {"run": kwargs["out"], "started": started, "ended": time.time(),
               "timesteps": int(res["timesteps"]), "wall_time_s": float(res["wall_time_s"]),
               "eval_return_mean": float(last["eval_return_mean"])}
    if not math.isnan(last["eval_success_rate"]):
        metrics["eval_success_rate"] = float(last["eval_success_rate"])
    tune.report(metrics)


def compare_rllib(task: str, algos=("ppo",), seeds: int = 3,
                  steps: int | Mapping[str, int] = 50_000, out: str | Path = "runs/compare", *,
                  mode: str | None = None, address: str | None = None,
                  num_cpus: int | None = None, num_env_runners: int = 1,
                  num_envs_per_runner: int = 1, num_cpus_per_learner: float = 1,
                  num_gpus_per_learner: float = 0, max_concurrent: int | None = None,
                  plot_only: bool = False, algo_kwargs: Mapping[str, Any] | None = None,
                  **train_kwargs) -> Path:
    """Train every algorithm with seeds 0..seeds-1 as Tune trials and plot them together;
    returns the PNG (see the module docstring)."""
    out = Path(out).resolve()
    algos = [check_algo(a) for a in algos]
    check_task(task)
    mode = check_mode(task, mode)
    if int(seeds) < 1:
        raise TrainInputError(f"seeds={seeds}; allowed: a positive integer")
    if max_concurrent is not None and int(max_concurrent) < 1:
        raise TrainInputError(f"max_concurrent={max_concurrent}; allowed: a positive integer")
    steps = value_per_algo("steps", steps, algos, isinstance(steps, Mapping))
    algo_kwargs = dict(algo_kwargs or {})
    kwargs = value_per_algo("algo_kwargs", algo_kwargs, algos,
                            kwargs_keyed_by_algo(algo_kwargs, RLLIB_ALGOS,
                                                 '{"ppo": {"num_epochs": 5}, "appo": {}}'))
    runs = {f"{a}_seed{s}": dict(task=task, algo=a, steps=steps[a], seed=s,
                                 out=str(out / f"{a}_seed{s}"), mode=mode,
                                 algo_kwargs=kwargs[a], progress=False,
                                 num_env_runners=num_env_runners,
                                 num_envs_per_runner=num_envs_per_runner,
                                 num_cpus_per_learner=num_cpus_per_learner,
                                 num_gpus_per_learner=num_gpus_per_learner, **train_kwargs)
            for a in algos for s in range(int(seeds))}
    if not plot_only:
        out.mkdir(parents=True, exist_ok=True)
        _run_trials(runs, algos, int(seeds), out, address, num_cpus, max_concurrent,
                    trial_resources(num_env_runners, num_cpus_per_learner, num_gpus_per_learner))
    return plot_compare(out, task)


def _run_trials(runs: dict, algos: list[str], seeds: int, out: Path, address, num_cpus,
                max_concurrent, bundles: list[dict]) -> None:
    import ray
    from ray import tune

    from .runner import init_ray

    started = init_ray(address, num_cpus)
    try:
        trainable = tune.with_resources(_trial, tune.PlacementGroupFactory(bundles))
        tuner = tune.Tuner(
            trainable,
            param_space={"algo": tune.grid_search(algos), "seed": tune.grid_search(range(seeds)),
                         "runs": runs},
            tune_config=tune.TuneConfig(max_concurrent_trials=max_concurrent),
            run_config=tune.RunConfig(name="trials", storage_path=str(out / "_tune"),
                                      verbose=0,
                                      failure_config=tune.FailureConfig(max_failures=0)))
        results = tuner.fit()
        failed = [f"{r.config['algo']}_seed{r.config['seed']}: "
                  f"{str(r.error).strip().splitlines()[-1] if str(r.error).strip() else r.error!r}"
                  for r in results if r.error is not None]
        if failed:
            raise RuntimeError(f"{len(failed)} of {len(results)} Tune trials failed: "
                               + "; ".join(failed) + f" (Tune's logs: {out / '_tune'})")
    finally:
        if started:
            ray.shutdown()
