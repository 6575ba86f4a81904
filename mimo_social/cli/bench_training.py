"""``mimo-social bench training``: env steps per second of SB3 PPO training against the env
alone, per task and number of env workers (:mod:`mimo_social.bench.training`, issue 29).

    mimo-social bench training                       # the figures of BENCHMARKS.md
    mimo-social bench training --tasks reach --workers 2 --steps 8192 --json out.json

The measuring functions of SB3 are here (the bench layer does not import the training layer):
:func:`env_rate` steps the learner's vector env as :func:`mimo_social.train.train` builds it
(``one_learner_vec_env`` of ``monitored_env``, the observation layout a run uses by default:
images for the CNN where the learner has eyes); :func:`ppo_rate` runs
``train(task, "ppo", steps, seed, out, mode=..., n_envs=workers)`` with the shipped
hyperparameters, no evaluation before the end (one final evaluation of one episode per
policy) and a checkpoint every rollout + one vector step, the first of which starts the timed
learning phase (:func:`mimo_social.bench.training.learning_phase`).
"""

from __future__ import annotations

import argparse
import functools
import json
import shlex
import tempfile
import time
from pathlib import Path

from ..bench import training as bench
from ..train import MULTI_TASKS, TASKS, train
from ..train.workers import ENVS_PER_WORKER
from ._args import comma_choices, output_dir, output_file, positive_int, seed, write_file

__all__ = ["NAME", "HELP", "add_parser", "run", "MODES", "DEFAULT_STEPS", "DEFAULT_STEPS_EYES",
           "OBSERVATION", "has_eyes", "default_steps", "env_rate", "ppo_rate", "rollout_steps",
           "measure"]

#: its name under ``mimo-social bench`` and its line in the list of measurements
NAME = "training"
HELP = "SB3 PPO's env steps/s while training against the env alone, 1 and 2 workers"

#: the tasks it measures -> their training mode: one-agent tasks as they are, the social ones
#: with one learner and the partner scripted
MODES = {**{t: None for t in TASKS}, **{t: "scripted" for t in MULTI_TASKS}}
#: env steps per configuration by default: 8 PPO rollouts of 2048, and 2 for a learner with
#: eyes (its CNN's update takes ~50 s a rollout on one torch thread); the default tasks and
#: workers take about 6 min on 2 cores
DEFAULT_STEPS = 16384
DEFAULT_STEPS_EYES = 4096
#: the learner's observation layout, as train() builds it by default (images for the CNN)
OBSERVATION = {"flat": False, "frame_stack": 1}


def rollout_steps(task: str, mode: str | None, n_envs: int,
                  algo_kwargs: dict | None = None) -> int:
    """Env steps per PPO rollout in a run of ``task`` with ``n_envs`` envs: the shipped
    ``n_steps`` (under ``algo_kwargs``) per env, as train() divides it, times ``n_envs``."""
    from ..train.hyperparams import resolve, to_sb3
    from ..train.single import vector_defaults

    resolved, _ = resolve(task, "ppo", algo_kwargs, mode=mode)
    kw = vector_defaults(to_sb3("ppo", resolved), set(algo_kwargs or {}), int(n_envs), "ppo")
    return int(kw.get("n_steps", 2048)) * int(n_envs)


def has_eyes(task: str) -> bool:
    """Whether the task's learner sees images (its observation is the image ``Dict``)."""
    from gymnasium import spaces

    from ..train import make_env

    env = make_env(task, **OBSERVATION)
    try:
        return isinstance(env.observation_space, spaces.Dict)
    finally:
        env.close()


def default_steps(tasks) -> dict:
    """Task -> :data:`DEFAULT_STEPS`, or :data:`DEFAULT_STEPS_EYES` for a learner with eyes."""
    return {t: DEFAULT_STEPS_EYES if has_eyes(t) else DEFAULT_STEPS for t in tasks}


def env_rate(config: bench.TrainingConfig, steps: int, seed: int = 0) -> dict:
    """The env alone: the learner's vector env (``config.n_envs`` envs in ``config.workers``
    worker processes), random actions."""
    from ..train.single import monitored_env
    from ..train.workers import one_learner_vec_env   # (imports SB3)

    env_fn = functools.partial(monitored_env, config.task, {}, dict(OBSERVATION))
    return bench.env_alone(lambda: one_learner_vec_env(env_fn, config.n_envs,
                                                       n_workers=config.workers), steps, seed)


def ppo_rate(config: bench.TrainingConfig, steps: int, seed: int = 0, *, root: str | Path,
             algo_kwargs: dict | None = None) -> dict:
    """A PPO run of ``steps`` env steps into ``root/<task>_<workers>`` (the shipped
    hyperparameters under ``algo_kwargs``) and its learning phase's figures. ValueError when
    ``steps`` does not reach past the first rollout (nothing to time)."""
    rollout = rollout_steps(config.task, config.mode, config.n_envs, algo_kwargs)
    if steps <= rollout:
        raise ValueError(f"steps={steps}: {config.name} needs more than one PPO rollout "
                         f"({rollout} env steps) to time the learning after the first update; "
                         f"give at least {2 * rollout}")
    out = Path(root) / f"{config.task}_{config.workers}x{config.envs_per_worker}"
    t0 = time.time()
    train(config.task, "ppo", steps, seed, out, mode=config.mode, n_envs=config.n_envs,
          n_cpus=config.workers, progress=False, eval_every=10 * steps, eval_episodes=1,
          checkpoint_every=rollout + config.n_envs, algo_kwargs=algo_kwargs)
    res = bench.learning_phase(out, t0, time.time())
    if res["rollout"] != rollout:
        raise RuntimeError(f"{out}: the run's rollout is {res['rollout']} env steps, not the "
                           f"{rollout} expected: the timed phase would start mid-rollout")
    return res


def measure(tasks=bench.DEFAULT_TASKS, workers=bench.DEFAULT_WORKERS,
            steps: int | dict | None = None, seed: int = 0, *, root: str | Path | None = None,
            algo_kwargs: dict | None = None, progress: bool = False, command: str = "",
            envs_per_worker=(ENVS_PER_WORKER,)) -> dict:
    """:func:`mimo_social.bench.training.measure` with SB3's measuring functions: every task x
    workers configuration, ``steps`` env steps each (or task -> steps; None:
    :func:`default_steps`); the runs go to ``root`` (None: a temporary folder, removed)."""
    configurations = bench.configs(tasks, workers, MODES, envs_per_worker)
    if steps is None:
        steps = default_steps(tasks)
    with tempfile.TemporaryDirectory(prefix="bench_training_") as tmp:
        rate = functools.partial(ppo_rate, root=Path(root or tmp), algo_kwargs=algo_kwargs)
        return bench.measure(configurations, steps, env_rate=env_rate, ppo_rate=rate, seed=seed,
                             progress=progress, command=command,
                             settings={"algo_kwargs": algo_kwargs or "shipped"})


def add_parser(subparsers, name: str = NAME, **kw) -> argparse.ArgumentParser:
    """Add the parser as ``name`` (``kw``: more of argparse's ``add_parser`` settings)."""
    parser = subparsers.add_parser(
        name, **kw,
        description="Env steps per second of SB3 PPO training (train()'s shipped "
                    "hyperparameters, the learning phase between the first update and the end, "
                    "evaluation timed apart) against the same vector env stepped alone with "
                    "random actions, per task and number of env workers, back to back.")
    parser.add_argument("--tasks", type=comma_choices(list(MODES), "task"),
                        default=list(bench.DEFAULT_TASKS),
                        help=f"tasks, comma-separated (default {','.join(bench.DEFAULT_TASKS)}; "
                             "social tasks with --mode scripted)")
    parser.add_argument("--workers", type=comma_choices([str(n) for n in range(1, 17)],
                                                        "worker count"),
                        default=[str(n) for n in bench.DEFAULT_WORKERS],
                        help="env worker counts, comma-separated, 1 to 16 (default 1,2)")
    parser.add_argument("--envs-per-worker", type=comma_choices([str(n) for n in range(1, 33)],
                                                                "envs per worker"),
                        default=[str(ENVS_PER_WORKER)],
                        help=f"envs each worker steps, comma-separated, 1 to 32 (default "
                             f"{ENVS_PER_WORKER}: train's; 1 is the one-env-per-process "
                             "layout of before)")
    parser.add_argument("--steps", type=positive_int, default=None,
                        help=f"env steps per configuration, each side; more than one PPO "
                             f"rollout of 2048 (default {DEFAULT_STEPS}, {DEFAULT_STEPS_EYES} "
                             "for a learner with eyes)")
    parser.add_argument("--seed", type=seed, default=0, help="seed of runs and actions")
    parser.add_argument("--runs", type=output_dir, default=None,
                        help="keep the training runs here (default: a temporary folder)")
    parser.add_argument("--json", default=None, type=output_file, help="write all results here")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    workers = [int(n) for n in args.workers]
    envs = [int(n) for n in args.envs_per_worker]
    command = (f"mimo-social bench training --tasks {','.join(args.tasks)} --workers "
               f"{','.join(map(str, workers))} --envs-per-worker {','.join(map(str, envs))}"
               + (f" --steps {args.steps}" if args.steps else "") + f" --seed {args.seed}")
    results = measure(args.tasks, workers, args.steps, args.seed, root=args.runs,
                      progress=True, command=command, envs_per_worker=envs)
    print(bench.markdown(results))
    if args.json:
        write_file(args.json, json.dumps(results, indent=1))
        print(f"wrote {shlex.quote(str(args.json))}")
    return 0
