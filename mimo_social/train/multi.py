"""Multi-agent training (``--mode shared | independent | scripted``; docs/training_multi.md).

The social tasks (:data:`~mimo_social.train.tasks.MULTI_TASKS`) are PettingZoo modules
``mimo_social.envs.<task>_v0`` with ``parallel_env(**kwargs)`` and ``scripted_env(partner=None,
**kwargs)``. Three ways to train them:

``shared`` (default): parameter sharing
    One SB3 policy acts for every agent. :func:`~mimo_social.train.vector.sb3_vec_env` turns
    ``n_envs`` worlds into one SB3 VecEnv with a slot per agent (SuperSuit underneath), so the
    policy sees each agent's observation as a separate sample. Every agent needs the same
    (flattened) observation and action space. ``--steps`` counts environment steps (summed over
    the worlds): SB3 runs ``steps * n_agents`` agent-transitions.

``independent``: one policy per agent, in the same world at the same time
    :mod:`mimo_social.train.independent` (each model's ``learn()`` in its own thread on a
    lockstep Gymnasium view of the shared ParallelEnv, :mod:`mimo_social.train.lockstep`).

``scripted``: one learner, the partner scripted
    The catalogue's Gymnasium id of the task (``SingleAgentEnv(module.scripted_env(...))``)
    through :func:`~mimo_social.train.envs.make_env`: the one-agent path with the task's default
    scripted partner.

Evaluation (on the schedule of :class:`~mimo_social.train.runlog.Schedule`: by default within an
evaluation budget, else every ``--eval-every`` steps; and at the end) runs ``--eval-episodes``
episodes of the deterministic and of the stochastic policy on a separate env in which every
learning agent acts with its own policy (scripted partners keep their script). It gives per-agent
returns and success rates (``is_success`` of the agent's info on its last step); the summary
columns average them across agents. SIGINT / SIGTERM stop the run between two steps and save it
as it stands (:mod:`mimo_social.train.interrupt`).

``--algo recurrent_ppo`` (an LSTM policy) works in every mode: ``shared`` keeps one LSTM state
per agent slot, the evaluations one per agent. ``--normalize-reward`` (SB3's ``VecNormalize`` on
the rewards, saved next to each model) is for ``shared`` and ``scripted`` (the one VecEnv of the
one policy); ``independent`` refuses it (the runner says so before anything runs).
"""

from __future__ import annotations

import functools
import time
from pathlib import Path

from .curriculum import monitored_curriculum_env
from .envs import make_env, make_parallel_env, make_scripted_env
from .independent import train_independent
from .interrupt import StopSignals, workers_ignore_sigint
from .progress import write_config
from .rollouts import evaluate_agents
from .runlog import RunLog, Schedule, episode_limit, first_update, rounding_note, sb3_callback
from .single import (build_model, curriculum_controller, finish_config, learn_and_finish,
                     monitored_env, vector_defaults, warm_start_run, warn)
from .tasks import TrainInputError, algo_class, check_mode, task_module

__all__ = ["train_multi", "check_shared_spaces"]


def check_shared_spaces(env, task: str) -> None:
    """``--mode shared``: every agent of the flat env ``env`` has the same spaces, else a
    TrainInputError saying which differ."""
    agents = env.possible_agents
    first = agents[0]
    for a in agents[1:]:
        for kind, space in (("observation", env.observation_space), ("action", env.action_space)):
            s0, s1 = space(first), space(a)
            if s0 != s1:   # gymnasium's space equality: kind, shape, dtype and bounds (or n)
                what = (f"{s0} vs {s1}" if type(s0) is not type(s1) or s0.shape != s1.shape
                        else f"same shape {s0.shape}, different bounds")
                raise TrainInputError(
                    f"--mode shared needs every agent to have the same observation and action "
                    f"space; in {task!r} the flat {kind} spaces of {first} and {a} differ "
                    f"({what}). "
                    "Use --mode independent (one policy per agent) instead")


# -- training ------------------------------------------------------------------------------------
def train_multi(task: str, algo: str, steps: int, seed: int, out: Path, *, mode: str | None,
                eval_every: int | None, eval_episodes: int, checkpoint_every: int,
                progress: bool, env_kwargs: dict, algo_kwargs: dict, n_envs: int = 1,
                n_cpus: int = 0, verbose: int = 0, config: dict,
                worker_timeout: float = 600.0, curriculum=None, bc: dict | None = None) -> dict:
    """The multi-agent part of :func:`mimo_social.train.runner.train` (arguments checked there).
    ``eval_every=None``: the budgeted schedule. ``n_envs``: worlds (shared mode) or envs of
    the one learner (scripted mode), in ``n_cpus`` spawned worker processes (0: in this
    process); the independent mode steps one world. ``curriculum`` and ``bc`` (scripted mode,
    checked by the runner): as :func:`~mimo_social.train.single.train_single`'s; the
    evaluations run on the curriculum's last stage."""
    mode = check_mode(task, mode)
    from .hyperparams import to_json

    cls = algo_class(algo)
    module = task_module(task)
    config.update({"env_module": module.__name__, "mode": mode, "n_envs": n_envs,
                   "n_cpus": n_cpus, "worker_timeout": float(worker_timeout)})
    # scripted: the learner's observations as make_env gives them (images for the CNN); shared
    # and independent: flat (the runner says so in config["observation"])
    observation = dict(config.get("observation", {"flat": mode != "scripted"}))
    final_kwargs = env_kwargs if curriculum is None else curriculum.stages[-1].kwargs(env_kwargs)
    eval_env = (make_scripted_env if mode == "scripted" else make_parallel_env)(
        task, **observation, **final_kwargs)
    if mode == "shared":
        try:
            check_shared_spaces(eval_env, task)
        except TrainInputError:
            eval_env.close()
            raise
    agents = list(eval_env.possible_agents)
    config["agents"] = agents
    if config.get("categorical_heads"):
        from .categorical_heads import record_learner_groups
        record_learner_groups(config, eval_env, eval_env.unwrapped.action_space(agents[0]),
                              agents[0])
    if (mode == "shared" and algo == "sac"
            and algo_kwargs.get("buffer_size") == min(1_000_000, steps)
            and "buffer_size" not in config.get("algo_kwargs_given", ())):
        # SB3 counts every agent's transition: room for all of them (train's default is steps)
        algo_kwargs["buffer_size"] = min(1_000_000, steps * len(agents))
    given = config.pop("algo_kwargs_given", None)
    if mode in ("scripted", "shared", "independent"):   # the env steps per rollout of one env
        algo_kwargs = vector_defaults(algo_kwargs, set(algo_kwargs if given is None else given),
                                      int(n_envs), algo, config.get("algo_kwargs_provenance"))
    config["algo_kwargs"] = to_json(algo_kwargs)
    if mode == "independent":
        config["models"] = {a: f"model_{a}.zip" for a in agents}
    else:
        config["models"] = {a: "model.zip" for a in agents}
    write_config(out, config)
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=steps, unit="step", desc=f"{out.name}", dynamic_ncols=True)
    eval_seed = 10_000 + seed
    schedule = Schedule(eval_every, checkpoint_every, steps, episodes=eval_episodes,
                        episode_steps=episode_limit(eval_env))
    stop = StopSignals()
    t0 = time.perf_counter()
    try:
        with stop:
            if mode == "independent":
                models, done = train_independent(cls, algo_kwargs, task, env_kwargs, steps, seed,
                                                 out, eval_env, eval_episodes, eval_seed,
                                                 schedule, bar, t0, verbose, stop=stop,
                                                 config=config, n_envs=int(n_envs),
                                                 n_cpus=int(n_cpus),
                                                 worker_timeout=float(worker_timeout))
                log = done.log
            else:
                model, log, venv = _train_one_policy(cls, algo, algo_kwargs, module, task, mode,
                                                     env_kwargs, steps, seed, out, eval_env,
                                                     eval_seed, schedule, bar, t0, verbose,
                                                     n_envs, n_cpus, worker_timeout, stop,
                                                     config, curriculum, bc)
    finally:
        eval_env.close()
        if bar is not None:
            bar.close()
    rows = log.rows
    wall = time.perf_counter() - t0
    timesteps = rows[-1]["timesteps"]
    write_config(out, finish_config(config, wall, timesteps, stop, log.eval_steps))
    models_out = ({a: str(out / f"model_{a}.zip") for a in agents} if mode == "independent"
                  else {a: str(out / "model.zip") for a in agents})
    return {"out": str(out), "model": models_out[agents[0]], "models": models_out,
            "mode": mode, "agents": agents, "wall_time_s": wall, "timesteps": int(timesteps),
            "last_eval": rows[-1], "rows": rows, "interrupted": stop.requested,
            "signal": stop.signum, "steps_planned": config.get("steps_planned", steps)}


def _train_one_policy(cls, algo, algo_kwargs, module, task, mode, env_kwargs, steps, seed, out,
                      eval_env, eval_seed, schedule, bar, t0, verbose, n_envs, n_cpus,
                      worker_timeout, stop, config, curriculum=None, bc=None):
    """shared (one policy, one VecEnv slot per agent) and scripted (one learner) modes; the
    scripted mode takes a ``curriculum`` and a warm start (``bc``)."""
    from stable_baselines3.common.vec_env import VecMonitor

    agents = list(eval_env.possible_agents)
    if mode == "shared":
        from supersuit.vector.sb3_vector_wrapper import SB3VecEnvWrapper

        from .vector import SeededVecEnv, SpawnConcatVecEnv, sb3_vec_env
        env_fn = functools.partial(module.parallel_env, **env_kwargs)
        if n_cpus == 0:
            venv = sb3_vec_env(env_fn, n_envs=n_envs, n_cpus=0)
        else:
            with workers_ignore_sigint():
                venv = SeededVecEnv(SB3VecEnvWrapper(SpawnConcatVecEnv(
                    env_fn, n_envs, n_cpus, "spawn", timeout_s=worker_timeout)))
        venv = VecMonitor(venv)
        per_env_step = len(agents)
    else:
        from .workers import one_learner_vec_env
        env_fn = (functools.partial(monitored_env, task, dict(env_kwargs),
                                    config.get("observation")) if curriculum is None else
                  functools.partial(monitored_curriculum_env, task, config.get("observation"),
                                    curriculum.plan(env_kwargs)))
        venv = one_learner_vec_env(env_fn, int(n_envs), worker_timeout, n_workers=int(n_cpus))
        per_env_step = 1
    try:
        venv, model, save = build_model(cls, algo, venv, config, algo_kwargs, seed, verbose)
        control = curriculum_controller(curriculum, venv, None, config, out)
        planned, note = rounding_note(model, algo, steps, per_env_step)
        if note:
            warn(note)
        schedule.first = first_update(model, per_env_step)
        if bar is not None:
            bar.total = planned
        config.update({"steps": steps, "steps_planned": planned, **schedule.describe()})
        write_config(out, config)

        def evaluate(episodes, deterministic):
            return evaluate_agents({a: model for a in agents}, eval_env, episodes, eval_seed,
                                   deterministic)

        def checkpoint(n):
            (out / "checkpoints").mkdir(exist_ok=True)
            save(out / "checkpoints" / f"model_{n}_steps.zip")

        log = RunLog(out, agents, evaluate, lambda: save(out / "best_model.zip"), t0, bar,
                     schedule, eval_seed)
        if control is not None:
            control.t_start = log.t_start
            log.columns.append(control.columns)
        keep = None
        if bc is not None:   # on the learner's Gymnasium env, with the evaluated stage's kwargs
            demo_env = make_env(task, **config.get("observation", {}),
                                **(env_kwargs if curriculum is None
                                   else curriculum.stages[-1].kwargs(env_kwargs)))
            try:
                keep = warm_start_run(model, task, demo_env, bc, seed, config, out, log,
                                      schedule.episodes, steps * per_env_step)
            finally:
                demo_env.close()
        try:
            cb = sb3_callback(log, schedule, agents, per_env_step, checkpoint, stop,
                              on_step=None if control is None else control.on_step)
            if keep is not None:
                from stable_baselines3.common.callbacks import CallbackList
                cb = CallbackList([cb, keep])
            learn_and_finish(model, steps, per_env_step, cb, stop, save, out, schedule,
                             checkpoint, bar, log)
            if keep is not None:
                config["bc"]["keep_updates_made"] = int(keep.updates)
        finally:
            log.close()
    finally:
        venv.close()
    return model, log, venv
