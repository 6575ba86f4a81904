"""``train``: the one entry point that trains a policy (or one per agent) on a task.

It checks the arguments (:mod:`mimo_social.train.tasks`), builds the SB3 keyword arguments and the
run's ``config.json``, then hands over to :func:`~mimo_social.train.single.train_single` (one
learner: a one-agent task) or :func:`~mimo_social.train.multi.train_multi` (a social task in
``--mode shared | independent | scripted``).

Stable-Baselines3, CPU, ``torch`` on one thread, with the hyperparameters shipped for the task
and algorithm (:mod:`mimo_social.train.hyperparams`, docs/hyperparameters.md: SB3's defaults
unless a measurement here says otherwise; SAC's replay buffer capped at the run's steps), which
``algo_kwargs`` override key by key (every key checked before anything runs). A learner with eyes
sees its images through a CNN (:mod:`mimo_social.train.encoders`, docs/training_vision.md).
``--algo recurrent_ppo`` (sb3-contrib's RecurrentPPO) gives the policy memory: an LSTM after the
MLP inputs or after the CNN (docs/training.md, "Memory").
Evaluations follow a budget (at most ~10 % of the training steps, none before the first update;
docs/training.md) and run the deterministic and the sampled policy. A run writes to ``out``:

* ``config.json``: task, algorithm, seed, steps, the observation layout and the keyword arguments
  with their provenance (what ``eval`` reads);
* ``model.zip`` (the final policy) and ``best_model.zip`` (best mean evaluation return);
* ``checkpoints/model_<steps>_steps.zip`` every ``checkpoint_every`` steps;
* with ``normalize_reward``: SB3's ``VecNormalize`` statistics next to each model
  (``vecnormalize.pkl``, ``best_vecnormalize.pkl``,
  ``checkpoints/vecnormalize_<steps>_steps.pkl``; the rewards the learner sees are scaled,
  every number written is the env's own);
* ``progress.csv``: one row per evaluation (:data:`~mimo_social.train.progress.PROGRESS_FIELDS`:
  the deterministic policy's ``eval_*`` columns and the sampled policy's ``eval_*_stochastic``,
  on a separate env, the same seeded episodes every time; the train columns summarise the
  training episodes since the last row);
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

__all__ = ["train", "run_growth"]


def run_growth(spec, cur, task: str, mode: str | None, env_kwargs):
    """``train``'s ``growth`` (or the curriculum's ``growth`` key) checked before anything
    is written: a :class:`~mimo_social.train.growth.Growth`, or None. One-agent tasks only;
    the env must have ``set_age`` (the core env's age change between episodes)."""
    from .growth import check_set_age, parse_growth
    growth = parse_growth(spec)
    from_cur = getattr(cur, "growth", None)
    if growth is not None and from_cur is not None:
        raise TrainInputError(f"growth {growth.spec} and the curriculum's growth "
                              f"{from_cur.spec}: allowed: one of the two")
    growth = growth if growth is not None else from_cur
    if growth is None:
        return None
    if mode is not None:
        raise TrainInputError(f"growth {growth.spec} with --mode {mode}; allowed: a one-agent "
                              "task (its learner is the only infant)")
    if "age_months" in (env_kwargs or {}):
        raise TrainInputError(f"growth {growth.spec} with env_kwargs age_months="
                              f"{env_kwargs['age_months']!r}: the schedule sets the age; allowed:"
                              " one of the two")
    from .envs import make_env
    env = make_env(task, **dict(env_kwargs or {}))
    try:
        check_set_age(env, growth)
    finally:
        env.close()
    return growth


def train(task: str, algo: str, steps: int, seed: int, out: str | Path, *,
          eval_every: int | None = None, eval_episodes: int = 5,
          checkpoint_every: int | None = None, progress: bool = True,
          env_kwargs: Mapping[str, Any] | None = None,
          algo_kwargs: Mapping[str, Any] | None = None, verbose: int = 0,
          mode: str | None = None, n_envs: int | None = None, n_cpus: int | None = None,
          normalize_obs: bool | None = None, flat_obs: bool = False, frame_stack: int = 1,
          obs_min_std: float = 0.0, worker_timeout: float = 600.0, normalize_reward: bool = False,
          curriculum=None, bc_episodes: int = 0, bc_epochs: int = 20, intrinsic=None,
          bc_kwargs: Mapping[str, Any] | None = None, recipe: str | None = None,
          growth=None, categorical_heads: bool = False) -> dict:
    """Train one policy (or one per agent); returns a summary (paths, last evaluation, wall
    time). See the module docstring for what it writes.

    ``mode`` (``shared``, ``independent``, ``scripted``; default ``shared``) is for the
    multi-agent tasks (:mod:`mimo_social.train.multi`). ``n_envs``: envs stepped together (one
    learner, ``scripted``) or worlds (``shared``, ``independent``); default
    :func:`~mimo_social.train.workers.default_n_envs` (one per core). ``n_cpus``: the spawned
    worker processes that step them (each a contiguous block, one after the other); default one
    per core, at most one per env; 0: all in this process. ``eval_every=None``: the budgeted
    evaluation schedule
    (:class:`~mimo_social.train.runlog.Schedule`). ``algo_kwargs`` override the shipped
    hyperparameters (:mod:`mimo_social.train.hyperparams`; every key checked before anything
    runs). ``normalize_obs`` (None: the task's shipped ``[run]`` default) puts running input
    statistics in front of the policy; ``obs_min_std`` (0: none; with ``normalize_obs``) floors
    their scale, so that inputs which only jitter (held joints) are not scaled up to the size
    of the ones that move. A learner with eyes gets the CNN
    (:mod:`mimo_social.train.encoders`) unless ``flat_obs``; ``frame_stack`` frames of each
    image. ``worker_timeout``: seconds a worker may take to answer before the run fails.
    ``normalize_reward``: the learner's rewards scaled by SB3's ``VecNormalize`` (a running
    estimate of the discounted return's spread, with the algorithm's ``gamma``; observations
    untouched: ``normalize_obs`` does that inside the policy), its statistics saved next to
    every model (one learner, ``scripted`` and ``shared``; not ``independent``).
    ``curriculum`` (one learner): a shipped curriculum's name, a .toml / .json file or a dict
    (:mod:`mimo_social.train.curriculum`); ``bc_episodes`` (one learner): scripted episodes
    cloned into the policy for ``bc_epochs`` epochs before any RL step, ``bc_kwargs`` the
    other settings (:mod:`mimo_social.train.demonstrations`); both checked before anything is
    written. ``intrinsic`` (None, ``"rnd"`` or a settings mapping; not ``independent``): an RND
    novelty bonus added to the learner's rewards (:mod:`mimo_social.train.intrinsic`; with
    ``{"extrinsic": 0}`` a reward-free run). ``recipe``: the name of the shipped recipe the
    run follows (:mod:`mimo_social.train.recipes`), recorded in ``config.json``. ``growth``
    (one-agent tasks): the infant's age as training goes, a spec such as ``"forward:1-12"``
    or a :class:`~mimo_social.train.growth.Growth` (:mod:`mimo_social.train.growth`; a
    curriculum file may give it instead). ``categorical_heads`` (PPO, A2C; one learner or
    ``shared``): the learner's face and voice logits sampled as categorical choices beside its
    Gaussian motors (:mod:`mimo_social.train.categorical_heads`)."""
    from .hyperparams import resolve, run_options, to_json, to_sb3

    mode = check_mode(task, mode)
    if mode is not None:
        task_module(task)  # a clear error before anything is written
    env_id = check_task(task)
    cls = algo_class(algo)
    steps, seed = int(steps), int(seed)
    if steps < 1:
        raise TrainInputError(f"steps={steps}; allowed: a positive integer")
    if isinstance(frame_stack, bool) or not isinstance(frame_stack, int) or frame_stack < 1:
        raise TrainInputError(f"frame_stack={frame_stack!r}; allowed: an integer >= 1")
    if not isinstance(normalize_reward, bool):
        raise TrainInputError(f"normalize_reward={normalize_reward!r}; allowed: True or False")
    if normalize_reward and mode == "independent":
        raise TrainInputError("--normalize-reward is for one learner (a one-agent task, --mode "
                              "scripted) and --mode shared; --mode independent trains one model "
                              "per agent on views of one world: leave it out there")
    if frame_stack > 1 and (flat_obs or mode in ("shared", "independent")):
        raise TrainInputError(f"frame_stack={frame_stack} stacks eye images for the CNN: not "
                              "with flat observations (--flat-obs, or --mode shared / "
                              "independent, whose observations are flat)")
    from .categorical_heads import check_categorical_heads
    check_categorical_heads(categorical_heads, algo, mode)
    # the shipped hyperparameters under the command line's, every key checked: before anything
    resolved, provenance = resolve(task, algo, algo_kwargs, mode=mode, steps=steps)
    if normalize_obs is None:
        normalize_obs = bool(run_options(task, mode).get("normalize_obs", False))
    if (isinstance(obs_min_std, bool) or not isinstance(obs_min_std, (int, float))
            or not 0.0 <= float(obs_min_std) <= 10.0):
        raise TrainInputError(f"obs_min_std={obs_min_std!r}; allowed: a number from 0 (no "
                              "floor) to 10")
    if obs_min_std and not normalize_obs:
        raise TrainInputError(f"obs_min_std={obs_min_std!r} floors the scale of the running "
                              "observation normaliser: it needs normalize_obs (--normalize-obs)")
    from .workers import default_n_envs, default_workers
    if n_envs is None:
        n_envs = default_n_envs()
    if isinstance(n_envs, bool) or not isinstance(n_envs, int) or n_envs < 1:
        raise TrainInputError(f"n_envs={n_envs!r}; allowed: an integer >= 1")
    if n_cpus is None:
        n_cpus = default_workers(n_envs)
    if isinstance(n_cpus, bool) or not isinstance(n_cpus, int) or not 0 <= n_cpus <= n_envs:
        raise TrainInputError(f"n_cpus={n_cpus!r}; allowed: 0 (every env in this process) to "
                              f"n_envs={n_envs} (worker processes, each stepping a block of "
                              "the envs)")
    from .intrinsic import check_intrinsic
    try:
        intrinsic = check_intrinsic(intrinsic, seed)
    except ValueError as e:
        raise TrainInputError(str(e)) from None
    if intrinsic is not None and mode == "independent":
        raise TrainInputError("intrinsic: an intrinsic bonus is for one learner (a one-agent "
                              "task, --mode scripted) and --mode shared, not --mode independent")
    # a curriculum (every stage's env made once) and the warm start: checked before anything
    from .curriculum import prepare_curriculum
    from .demonstrations import check_bc
    bc = check_bc(task, algo, mode, bc_episodes, bc_epochs, bc_kwargs)
    if bc is not None and bc["critic_epochs"] and normalize_reward:
        raise TrainInputError("bc_kwargs: critic_epochs with --normalize-reward: the critic would "
                              "be fitted to raw returns before the reward scale is known; "
                              "allowed: one of the two")
    cur = prepare_curriculum(curriculum, task, mode, {
        "flat": bool(flat_obs) or mode in ("shared", "independent"),
        "frame_stack": int(frame_stack)}, dict(env_kwargs or {}))
    growth = run_growth(growth, cur, task, mode, env_kwargs)
    import torch

    eval_every = int(eval_every) if eval_every else None
    checkpoint_every = int(checkpoint_every) if checkpoint_every is not None else max(steps // 5, 1)
    torch.set_num_threads(1)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    env_kwargs = dict(env_kwargs or {})
    kwargs = to_sb3(algo, resolved)
    # the learner's observations: flat for the shared and independent modes (one flat space
    # per agent); otherwise the image Dict and the CNN when it has eyes, unless flat_obs
    flat = bool(flat_obs) or mode in ("shared", "independent")
    config = {"task": task, "env_id": env_id, "algo": algo, "steps": steps,
              "seed": seed, "normalize_obs": bool(normalize_obs),
              "obs_min_std": float(obs_min_std),
              "normalize_reward": bool(normalize_reward),
              "observation": {"flat": flat, "frame_stack": int(frame_stack)},
              "env_kwargs": env_kwargs, "algo_kwargs": to_json(resolved),
              "algo_kwargs_provenance": provenance, "eval_every": eval_every,
              "eval_episodes": eval_episodes, "checkpoint_every": checkpoint_every,
              "algo_kwargs_given": sorted(algo_kwargs or {})}
    if categorical_heads:
        config["categorical_heads"] = True
    if recipe is not None:
        config["recipe"] = str(recipe)
    if bc is not None:
        config["bc"] = dict(bc)
    if intrinsic is not None:
        config["intrinsic"] = intrinsic
    extra = {} if cur is None and bc is None else {"curriculum": cur, "bc": bc}
    if growth is not None:
        extra["growth"] = growth
    if mode is not None:
        return train_multi(task, algo, steps, seed, out, mode=mode, eval_every=eval_every,
                           eval_episodes=eval_episodes, checkpoint_every=checkpoint_every,
                           progress=progress, env_kwargs=env_kwargs, algo_kwargs=kwargs,
                           n_envs=int(n_envs), n_cpus=int(n_cpus), verbose=verbose,
                           config=config, worker_timeout=float(worker_timeout), **extra)
    return train_single(cls, task, steps, seed, out, eval_every=eval_every,
                        eval_episodes=eval_episodes, checkpoint_every=checkpoint_every,
                        progress=progress, env_kwargs=env_kwargs, algo_kwargs=kwargs,
                        verbose=verbose, config=config, n_envs=int(n_envs),
                        n_cpus=int(n_cpus), worker_timeout=float(worker_timeout), **extra)
