"""One learner: a one-agent task, or a social task's learner with its partner scripted.

Stable-Baselines3 on the task's Gymnasium env (:func:`~mimo_social.train.envs.make_env`: flat
observations, or images and a vector for a learner with eyes, through the CNN of
:func:`~mimo_social.train.encoders.policy_for`), CPU, ``n_envs`` envs (one: in this process;
more: one spawned worker process each, :mod:`mimo_social.train.workers`). An SB3 callback
(:func:`~mimo_social.train.runlog.sb3_callback`) evaluates the deterministic and the stochastic
policy on the :class:`~mimo_social.train.runlog.Schedule` (by default within an evaluation
budget), checkpoints every ``checkpoint_every`` steps, logs every training episode to
``episodes.csv`` and rewrites ``progress.csv`` and ``learning_curve.png`` after each evaluation.
SIGINT / SIGTERM stop the run between two steps: it is saved as it stands
(:mod:`mimo_social.train.interrupt`; ``config.json`` says ``"interrupted": true``).
``--normalize-reward``: the learner's envs in SB3's ``VecNormalize`` (rewards only,
:func:`reward_normalizer`), its statistics saved next to every model (:func:`model_saver`); the
episodes logged and the evaluations (a separate, unwrapped env) are the env's own returns.
``--curriculum`` (env options by stage, :mod:`~mimo_social.train.curriculum`) and
``--bc-episodes`` (a warm start cloned from the scripted controller before any RL step,
:mod:`~mimo_social.train.demonstrations`) are this path's and ``--mode scripted``'s.
"""

from __future__ import annotations

import functools
import sys
import time
from pathlib import Path

from .curriculum import CurriculumController, curriculum_env, curriculum_envs
from .envs import make_env
from .growth import GrowthController, monitored_growth_env, wrap_growth
from .interrupt import StopSignals
from .progress import write_config
from .rollouts import evaluate_policy, vecnormalize_path
from .runlog import RunLog, Schedule, episode_limit, first_update, rounding_note, sb3_callback

__all__ = ["train_single", "monitored_env", "vector_defaults", "warn", "reward_normalizer",
           "model_saver", "build_model", "learn_and_finish"]


def monitored_env(task: str, env_kwargs: dict, observation: dict | None = None):
    """``make_env(task, **observation, **env_kwargs)`` with Gymnasium's
    ``RecordEpisodeStatistics`` (the ``info["episode"]`` SB3 reads; not SB3's Monitor, so that a
    worker process does not import torch); module-level: picklable for the workers.
    ``observation``: ``flat`` and ``frame_stack`` of :func:`make_env`."""
    from gymnasium.wrappers import RecordEpisodeStatistics
    return RecordEpisodeStatistics(make_env(task, **(observation or {}), **env_kwargs))


def warn(text: str) -> None:
    """A line on stderr that a run's user must see."""
    print(f"mimo-social train: note: {text}", file=sys.stderr, flush=True)


def vector_defaults(algo_kwargs: dict, given, n_envs: int, algo: str,
                    provenance: dict | None = None) -> dict:
    """SB3 keyword arguments for ``n_envs`` envs, those not given keeping the one-env learning:
    PPO's rollout stays the shipped ``n_steps`` in all (``n_steps // n_envs`` per env), SAC
    keeps one gradient step per env step (``gradient_steps=-1``). ``provenance`` (key -> where
    the value comes from, config.json's) says what was changed."""
    kw = dict(algo_kwargs)
    if n_envs > 1 and algo in ("ppo", "recurrent_ppo") and "n_steps" not in given:
        default = 128 if algo == "recurrent_ppo" else 2048
        kw["n_steps"] = max(64, int(kw.get("n_steps", default)) // n_envs)
        if provenance is not None:
            provenance["n_steps"] = (f"{provenance.get('n_steps', 'SB3 default')}, divided by "
                                     f"n_envs={n_envs} (the same rollout in all)")
    if n_envs > 1 and algo == "sac" and "gradient_steps" not in given:
        kw["gradient_steps"] = -1
        if provenance is not None:
            provenance["gradient_steps"] = (f"-1 for n_envs={n_envs} (one gradient step per env "
                                            "step, as with one env)")
    return kw


def reward_normalizer(venv, config: dict, algo_kwargs: dict):
    """``(venv, normalizer)``: with ``config["normalize_reward"]``, ``venv`` in SB3's
    ``VecNormalize`` (``norm_obs=False, norm_reward=True``, the algorithm's ``gamma``; written
    to ``config["vecnormalize"]``) and that wrapper; otherwise ``(venv, None)``. The wrapper
    changes only the rewards the learner sees: the episodes its callback logs come from the
    monitors below it."""
    if not config.get("normalize_reward"):
        return venv, None
    from stable_baselines3.common.vec_env import VecNormalize
    gamma = float(algo_kwargs.get("gamma", 0.99))
    vec = VecNormalize(venv, training=True, norm_obs=False, norm_reward=True, gamma=gamma)
    config["vecnormalize"] = {"file": "vecnormalize.pkl", "norm_obs": False,
                              "norm_reward": True, "gamma": gamma,
                              "clip_reward": float(vec.clip_reward),
                              "epsilon": float(vec.epsilon)}
    return vec, vec


def model_saver(model, normalizer=None):
    """``save(path)``: ``model.save(path)`` and, with a ``normalizer`` (a ``VecNormalize``), its
    statistics next to it (:func:`~mimo_social.train.rollouts.vecnormalize_path`)."""
    def save(path) -> None:
        model.save(path)
        if normalizer is not None:
            normalizer.save(str(vecnormalize_path(path)))
    return save


def finish_config(config: dict, wall: float, timesteps: int, stop: StopSignals,
                  eval_steps: int) -> dict:
    config.update({"wall_time_s": round(wall, 1), "timesteps_done": int(timesteps),
                   "eval_steps_done": int(eval_steps), "interrupted": stop.requested})
    if stop.requested:
        config["signal"] = stop.signum
    return config


def build_model(cls, algo: str, venv, config: dict, algo_kwargs: dict, seed: int,
                verbose: int):
    """The SB3 model of one policy on ``venv`` (one learner, or the shared / scripted modes):
    an intrinsic bonus added to the rewards when ``config["intrinsic"]`` asks for one
    (:class:`~mimo_social.train.intrinsic.RNDBonus`), the rewards normalised when the run asks
    for it (:func:`reward_normalizer`), the policy
    :func:`~mimo_social.train.encoders.policy_for` picks for the observation and, with
    ``config["categorical_groups"]``, the categorical heads (its name recorded in
    ``config["policy"]``). Returns ``(venv, model, save)``: the env the model steps, the model
    and its :func:`model_saver`."""
    from .encoders import policy_for     # (torch: lazily, see train_single)
    from .tasks import RECURRENT_ALGOS
    if config.get("intrinsic"):
        from .intrinsic import RNDBonus
        venv = RNDBonus(venv, config["intrinsic"])
    venv, normalizer = reward_normalizer(venv, config, algo_kwargs)
    policy, kw = policy_for(venv.observation_space, algo_kwargs,
                            bool(config.get("normalize_obs")), algo in RECURRENT_ALGOS,
                            float(config.get("obs_min_std", 0.0)),
                            config.get("categorical_groups"))
    config["policy"] = getattr(policy, "__name__", policy)
    model = cls(policy, venv, seed=seed, device="cpu", verbose=verbose, **kw)
    return venv, model, model_saver(model, normalizer)


def learn_and_finish(model, steps: int, per_env_step: int, callback, stop, save, out: Path,
                     schedule, checkpoint, bar, log) -> int:
    """``model.learn`` for ``steps`` env steps (``per_env_step`` transitions each), then what
    follows the last update: ``model.zip``, the last checkpoint when due, the bar, the final
    evaluation (one episode of each policy after a stop signal). Returns the env steps done."""
    try:
        model.learn(total_timesteps=steps * per_env_step, callback=callback)
    except Exception:
        if not stop.requested:   # (a worker killed by the same signal)
            raise
    n = int(model.num_timesteps) // per_env_step   # after the model's last update
    save(out / "model.zip")
    if schedule.final_checkpoint_due(n) and not stop.requested:
        checkpoint(n)
    if bar is not None:
        bar.update(n - bar.n)
    log.evaluate(n, 1 if stop.requested else schedule.final_episodes())
    return n


def curriculum_controller(curriculum, venv, eval_env, config: dict, out: Path):
    """The :class:`~mimo_social.train.curriculum.CurriculumController` of a run (None without
    a curriculum): it rewrites config.json and says so on stderr at every stage change."""
    if curriculum is None:
        return None
    return CurriculumController(curriculum, venv, eval_env, config,
                                lambda: write_config(out, config), warn)


def growth_envs(growth, task: str, observation: dict, env_kwargs: dict, curriculum, eval_env,
                steps: int):
    """``(eval_env, env_fn)`` of a run under a growth schedule: the evaluation env and each
    training env (the task's env, or its curriculum env, below its episode statistics) in a
    :class:`~mimo_social.train.growth.GrowthEnv`."""
    if curriculum is None:
        make = functools.partial(make_env, task, **observation, **env_kwargs)
    else:
        make = functools.partial(curriculum_env, task, dict(observation),
                                 curriculum.plan(env_kwargs))
    return (wrap_growth(eval_env, growth, steps),
            functools.partial(monitored_growth_env, make, growth.describe(), steps))


def growth_controller(growth, venv, eval_env, steps: int, config: dict, out: Path):
    """The :class:`~mimo_social.train.growth.GrowthController` of a run (None without a
    growth schedule): it rewrites config.json and says so on stderr at each whole month."""
    if growth is None:
        return None
    return GrowthController(growth, venv, eval_env, steps, config,
                            lambda: write_config(out, config), warn)


def step_hooks(*controls):
    """The callback's ``on_step``: every controller's (None: no controller)."""
    hooks = [c.on_step for c in controls if c is not None]
    if not hooks:
        return None

    def on_step(n, infos) -> None:
        for hook in hooks:
            hook(n, infos)
    return on_step


def warm_start_run(model, task: str, env, bc: dict, seed: int, config: dict, out: Path, log,
                   eval_episodes: int, total_steps: int):
    """The behaviour-cloning warm start of a run before any RL step (on ``env``, the learner's
    Gymnasium env), recorded in ``config["bc"]``, then an evaluation (progress row 0). Returns
    the callback that goes on cloning during RL (None: ``keep_updates`` 0)."""
    from .demonstrations import evaluate_after_bc, keep_cloning, warm_start
    config["bc"], demos = warm_start(model, task, env, bc, seed)
    b = config["bc"]
    if bc["dagger_rounds"]:
        from .dagger import dagger
        demos, b["dagger"] = dagger(model, task, env, demos, bc, seed, report=warn)
    rate = "n/a" if b["success_rate"] is None else f"{b['success_rate']:.0%}"
    warn(f"behaviour cloning: {b['episodes']} episodes of {b['controller']} (success {rate}, "
         f"{b['samples']} pairs), {b['epochs']} epochs: {b['loss']} loss {b['loss_before']:.4g}"
         f" -> {b['loss_after']:.4g}" + (
             f"; critic fitted to the returns, {b['critic_epochs']} epochs: explained variance "
             f"{b['critic_explained_variance_before']:.2f} -> "
             f"{b['critic_explained_variance_after']:.2f}" if b.get("critic_epochs") else "")
         + "".join(f"; DAgger play {d['round']}: the policy {d['success_rate']:.0%} on its "
                   f"{bc['dagger_episodes']} episodes" + (" (kept)" if d["kept"] else "")
                   for d in b.get("dagger", ()) if d["success_rate"] is not None))
    evaluate_after_bc(log, eval_episodes)
    write_config(out, config)
    return keep_cloning(model, demos, bc, total_steps, seed)


def train_single(cls, task: str, steps: int, seed: int, out: Path, *, eval_every: int | None,
                 eval_episodes: int, checkpoint_every: int, progress: bool, env_kwargs: dict,
                 algo_kwargs: dict, verbose: int, config: dict, n_envs: int = 1,
                 n_cpus: int = 0, worker_timeout: float = 600.0, curriculum=None,
                 bc: dict | None = None, growth=None) -> dict:
    """The one-learner part of :func:`mimo_social.train.runner.train` (arguments checked
    there); ``cls`` is the SB3 algorithm class. ``eval_every=None``: the budgeted schedule.
    ``curriculum``: a checked :class:`~mimo_social.train.curriculum.Curriculum`; ``bc``: the
    warm start's settings (:func:`~mimo_social.train.demonstrations.check_bc`); ``growth``: a
    checked :class:`~mimo_social.train.growth.Growth` (the infant's age by training step)."""
    from .hyperparams import to_json     # (torch: not imported by the workers, which import
    from .workers import one_learner_vec_env     # this module for monitored_env)

    algo = str(config.get("algo", cls.__name__)).lower()
    given = config.pop("algo_kwargs_given", None)
    given = set(algo_kwargs) if given is None else set(given)
    algo_kwargs = vector_defaults(algo_kwargs, given, int(n_envs), algo,
                                  config.get("algo_kwargs_provenance"))
    config.update({"algo_kwargs": to_json(algo_kwargs), "n_envs": int(n_envs),
                   "n_cpus": int(n_cpus), "worker_timeout": float(worker_timeout)})
    observation = dict(config.get("observation", {}))
    if curriculum is None:
        eval_env = make_env(task, **observation, **env_kwargs)
        env_fn = functools.partial(monitored_env, task, dict(env_kwargs), observation)
    else:
        eval_env, env_fn = curriculum_envs(curriculum, task, observation, env_kwargs)
    if growth is not None:
        eval_env, env_fn = growth_envs(growth, task, observation, env_kwargs, curriculum,
                                       eval_env, steps)
    if config.get("categorical_heads"):
        from .categorical_heads import record_learner_groups
        record_learner_groups(config, eval_env, eval_env.unwrapped.action_space, task)
    venv = one_learner_vec_env(env_fn, int(n_envs), worker_timeout, n_workers=int(n_cpus))
    stop = StopSignals()
    try:
        venv, model, save = build_model(cls, algo, venv, config, algo_kwargs, seed, verbose)
        control = curriculum_controller(curriculum, venv, eval_env, config, out)
        grow = growth_controller(growth, venv, eval_env, steps, config, out)
        planned, note = rounding_note(model, algo, steps)
        if note:
            warn(note)
        schedule = Schedule(eval_every, checkpoint_every, steps, episodes=eval_episodes,
                            episode_steps=episode_limit(eval_env), first=first_update(model))
        config.update({"steps": steps, "steps_planned": planned, **schedule.describe()})
        write_config(out, config)
        bar = None
        if progress:
            from tqdm import tqdm
            bar = tqdm(total=planned, unit="step", desc=f"{out.name}", dynamic_ncols=True)
        eval_seed = 10_000 + seed
        log = RunLog(out, None,
                     lambda k, det: evaluate_policy(model, eval_env, k, eval_seed, det),
                     lambda: save(out / "best_model.zip"), time.perf_counter(), bar,
                     schedule, eval_seed)
        if control is not None:
            control.t_start = log.t_start
            log.columns.append(control.columns)
        if grow is not None:
            grow.t_start = log.t_start
            log.columns.append(grow.columns)
        keep = None
        if bc is not None:
            keep = warm_start_run(model, task, eval_env, bc, seed, config, out, log,
                                  eval_episodes, steps)

        def checkpoint(n):
            (out / "checkpoints").mkdir(exist_ok=True)
            save(out / "checkpoints" / f"model_{n}_steps.zip")

        t0 = log.t_start
        try:
            with stop:
                cb = sb3_callback(log, schedule, None, 1, checkpoint, stop,
                                  on_step=step_hooks(control, grow))
                if keep is not None:
                    from stable_baselines3.common.callbacks import CallbackList
                    cb = CallbackList([cb, keep])
                learn_and_finish(model, steps, 1, cb, stop, save, out, schedule, checkpoint,
                                 bar, log)
        finally:
            log.close()
        wall = time.perf_counter() - t0
        if keep is not None:
            config["bc"]["keep_updates_made"] = int(keep.updates)
        write_config(out, finish_config(config, wall, model.num_timesteps, stop, log.eval_steps))
    finally:
        venv.close()
        eval_env.close()
    last = log.rows[-1]
    return {"out": str(out), "model": str(out / "model.zip"), "wall_time_s": wall,
            "timesteps": int(model.num_timesteps), "last_eval": last, "rows": log.rows,
            "interrupted": stop.requested, "signal": stop.signum, "steps_planned": planned}
