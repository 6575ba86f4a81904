"""``train``: the one entry point that trains a policy (or one per agent) on a task.

It checks the arguments (:mod:`mimo_social.train.tasks`), builds the SB3 keyword arguments and the
run's ``config.json``, then hands over to :func:`~mimo_social.train.single.train_single` (one
learner: a one-agent task) or :func:`~mimo_social.train.multi.train_multi` (a social task in
``--mode shared | independent | scripted``).

Stable-Baselines3 with its default hyperparameters (as in the paper: PPO with two hidden layers of
64, SAC with two of 256), CPU, ``torch`` on one thread. One change to SAC's defaults: the replay
buffer holds ``min(1e6, steps)`` transitions (it could never hold more; SB3 would allocate room
for a million of these large observations). ``algo_kwargs`` and ``env_kwargs`` override. A run
writes to ``out``:

* ``config.json``: task, algorithm, seed, steps and the keyword arguments (what ``eval`` reads);
* ``model.zip`` (the final policy) and ``best_model.zip`` (best mean evaluation return);
* ``checkpoints/model_<steps>_steps.zip`` every ``checkpoint_every`` steps;
* ``progress.csv``: one row per evaluation (every ``eval_every`` steps and at the end):
  ``timesteps, wall_time_s, eval_return_mean, eval_return_std, eval_length_mean,
  eval_success_rate, train_return_mean, train_episodes`` (the evaluation runs ``eval_episodes``
  deterministic episodes on a separate env, the same seeded episodes every time; the train
  columns summarise the training episodes since the last row);
* ``episodes.csv``: every training episode (``timesteps, return, length, success``; multi-agent
  runs: ``timesteps, agent, return, length, success``, one row per agent and episode);
* ``learning_curve.png``: evaluation return (mean and std) and training returns against steps,
  and the success rate where the task reports one.

Multi-agent runs add per-agent columns to ``progress.csv`` (``eval_return_mean_<agent>``,
``eval_success_rate_<agent>``; the summary columns average the agents) and one line per agent to
``learning_curve.png``; ``independent`` saves ``model_<agent>.zip`` (and ``best_model_<agent>``,
``checkpoints/model_<agent>_<steps>_steps.zip``). The last evaluation and checkpoint of a run are
made after the last update (of the model that is saved as ``model.zip``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from .multi import train_multi
from .single import train_single
from .tasks import TrainInputError, algo_class, check_mode, check_task, task_module

__all__ = ["train"]


def train(task: str, algo: str, steps: int, seed: int, out: str | Path, *,
          eval_every: int | None = None, eval_episodes: int = 5,
          checkpoint_every: int | None = None, progress: bool = True,
          env_kwargs: Mapping[str, Any] | None = None,
          algo_kwargs: Mapping[str, Any] | None = None, verbose: int = 0,
          mode: str | None = None, n_envs: int = 1, n_cpus: int = 0,
          normalize_obs: bool = False) -> dict:
    """Train one policy (or one per agent); returns a summary (paths, last evaluation, wall
    time). See the module docstring for what it writes. ``mode`` (``shared``, ``independent``,
    ``scripted``; default ``shared``), ``n_envs`` and ``n_cpus`` (shared mode: worlds and worker
    processes) are for the multi-agent tasks (:mod:`mimo_social.train.multi`). ``normalize_obs``
    puts :class:`~mimo_social.train.obs_norm.RunningNorm` in front of the policy."""
    mode = check_mode(task, mode)
    if mode is not None:
        task_module(task)  # a clear error before anything is written
    if mode is None and (n_envs != 1 or n_cpus != 0):
        raise TrainInputError(f"n_envs={n_envs}, n_cpus={n_cpus}: several worlds are for the "
                              f"multi-agent tasks in --mode shared; {task!r} trains on one env")
    import torch

    env_id = check_task(task)
    cls = algo_class(algo)
    steps, seed = int(steps), int(seed)
    if steps < 1:
        raise TrainInputError(f"steps={steps}; allowed: a positive integer")
    eval_every = int(eval_every) if eval_every else max(steps // 20, 1)
    checkpoint_every = int(checkpoint_every) if checkpoint_every is not None else max(steps // 5, 1)
    torch.set_num_threads(1)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    env_kwargs = dict(env_kwargs or {})
    kwargs = dict(algo_kwargs or {})
    if algo == "sac":
        kwargs.setdefault("buffer_size", min(1_000_000, steps))
    if normalize_obs:  # running input statistics inside the policy (saved in model.zip)
        from .obs_norm import RunningNorm
        kwargs["policy_kwargs"] = {**kwargs.get("policy_kwargs", {}),
                                   "features_extractor_class": RunningNorm}
    config = {"task": task, "env_id": env_id, "algo": algo, "steps": steps,
              "seed": seed, "normalize_obs": bool(normalize_obs),
              "env_kwargs": env_kwargs, "algo_kwargs": kwargs, "eval_every": eval_every,
              "eval_episodes": eval_episodes, "checkpoint_every": checkpoint_every}
    if mode is not None:
        config["algo_kwargs_given"] = sorted(algo_kwargs or {})
        return train_multi(task, algo, steps, seed, out, mode=mode, eval_every=eval_every,
                           eval_episodes=eval_episodes, checkpoint_every=checkpoint_every,
                           progress=progress, env_kwargs=env_kwargs, algo_kwargs=kwargs,
                           n_envs=int(n_envs), n_cpus=int(n_cpus), verbose=verbose,
                           config=config)
    return train_single(cls, task, steps, seed, out, eval_every=eval_every,
                        eval_episodes=eval_episodes, checkpoint_every=checkpoint_every,
                        progress=progress, env_kwargs=env_kwargs, algo_kwargs=kwargs,
                        verbose=verbose, config=config)
