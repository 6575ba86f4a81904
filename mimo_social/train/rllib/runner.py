"""``train_rllib``: the ``--engine rllib`` form of :func:`mimo_social.train.train`.

``train_rllib(task, algo, steps, seed, out, *, mode=None, eval_every=None, eval_episodes=5,
checkpoint_every=None, progress=True, env_kwargs=None, algo_kwargs=None, normalize_obs=False,
address=None, num_env_runners=1, num_envs_per_runner=1, num_cpus_per_learner=1,
num_gpus_per_learner=0, num_cpus=None, flat_obs=False, frame_stack=1) -> dict``

Joins the Ray cluster at ``address`` (``"auto"`` or ``HOST:PORT``: ``ray.init(address=...)``;
every node needs this package and ray installed) or starts a local Ray with ``num_cpus``
(default: one per env runner, at least 2), builds the algorithm with
:func:`~mimo_social.train.rllib.config.build_config`, and calls ``algo.train()`` until
``steps`` environment steps have been sampled (an iteration samples a whole train batch, so the
last one may overshoot). Agents with eyes see image Dicts and learn with the CNN module
(PPO, APPO) unless ``flat_obs`` (or SAC): see :mod:`~mimo_social.train.rllib.config`. The
learner runs in this process; the env runners are Ray actors, each making its envs (and their
GL contexts) in its own process. Writes to ``out`` what the SB3 path writes
(:mod:`mimo_social.train.runner`):

* ``config.json`` (``"engine": "rllib"``, the agents and ``modules``: agent -> RLModule id,
  ``"observation": {"flat", "frame_stack"}``: what ``eval`` makes its env with);
* ``progress.csv`` with per-agent columns (one-agent tasks: the summary columns only),
  ``episodes.csv`` (every training episode of every agent) and ``learning_curve.png``: the
  evaluations are ``eval_episodes`` deterministic episodes in this process, every
  ``eval_every`` steps and after the last iteration;
* ``checkpoint/`` (``algo.save`` after the last iteration), ``best_checkpoint/`` (best mean
  evaluation return) and ``checkpoints/step_<steps>/`` every ``checkpoint_every`` steps.
"""

from __future__ import annotations

import pickle
import time
from pathlib import Path
from typing import Any, Mapping

from ..progress import write_config
from ..rollouts import evaluate_agents
from ..runlog import RunLog, Schedule, episode_limit
from ..tasks import TrainInputError, check_mode, check_task
from .config import (build_config, check_algo, is_flat, learner_spaces, module_ids, obs_filter,
                     quiet_rllib)

__all__ = ["train_rllib", "init_ray", "filter_state"]


def init_ray(address: str | None = None, num_cpus: int | None = None) -> bool:
    """Join the cluster at ``address`` or start a local Ray (``num_cpus``); False when Ray was
    already initialised in this process (then it is left running)."""
    import ray

    if ray.is_initialized():
        return False
    kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False,
                              "configure_logging": True, "logging_level": "ERROR"}
    try:
        if address:
            ray.init(address=address, **kwargs)
        else:
            ray.init(num_cpus=num_cpus, **kwargs)
    except (ConnectionError, ValueError, RuntimeError) as e:
        where = f"the Ray cluster at {address!r}" if address else "a local Ray"
        hint = ""
        if address and address != "auto":
            hint = (" (is it up: 'ray status --address ...'? A cluster with token authentication "
                    "also needs RAY_AUTH_MODE=token and its token in RAY_AUTH_TOKEN or "
                    "~/.ray/auth_token here)")
        raise TrainInputError(f"cannot start or join {where}: "
                              f"{str(e).splitlines()[0] if str(e) else type(e).__name__}"
                              + hint) from None
    return True


def _steps_of(result: Mapping) -> int:
    from ray.rllib.utils.metrics import ENV_RUNNER_RESULTS, NUM_ENV_STEPS_SAMPLED_LIFETIME

    n = result.get(NUM_ENV_STEPS_SAMPLED_LIFETIME)
    if n is None:
        n = result.get(ENV_RUNNER_RESULTS, {}).get(NUM_ENV_STEPS_SAMPLED_LIFETIME, 0)
    return int(n)


def train_rllib(task: str, algo: str, steps: int, seed: int, out: str | Path, *,
                mode: str | None = None, eval_every: int | None = None, eval_episodes: int = 5,
                checkpoint_every: int | None = None, progress: bool = True,
                env_kwargs: Mapping[str, Any] | None = None,
                algo_kwargs: Mapping[str, Any] | None = None, normalize_obs: bool = False,
                address: str | None = None, num_env_runners: int = 1,
                num_envs_per_runner: int = 1, num_cpus_per_learner: int = 1,
                num_gpus_per_learner: float = 0, num_cpus: int | None = None,
                flat_obs: bool = False, frame_stack: int = 1) -> dict:
    """Train with RLlib; returns the summary :func:`mimo_social.train.train` returns (see the
    module docstring for what it writes)."""
    env_id = check_task(task)
    mode = check_mode(task, mode)
    check_algo(algo)
    steps, seed = int(steps), int(seed)
    if steps < 1:
        raise TrainInputError(f"steps={steps}; allowed: a positive integer")
    eval_every = int(eval_every) if eval_every else max(steps // 20, 1)
    checkpoint_every = int(checkpoint_every) if checkpoint_every is not None else max(steps // 5, 1)
    env_kwargs = dict(env_kwargs or {})
    algo_kwargs = dict(algo_kwargs or {})
    flat = is_flat(algo, flat_obs)
    # errors before anything starts
    agents, per_agent = learner_spaces(task, mode, env_kwargs, flat=flat, frame_stack=frame_stack)
    use_filter = obs_filter(normalize_obs, per_agent)
    observation = {"flat": flat, "frame_stack": int(frame_stack)}
    ids = module_ids(task, mode, agents)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    import ray
    import torch
    from ray import __version__ as ray_version

    torch.set_num_threads(1)
    quiet_rllib()
    config = {"engine": "rllib", "task": task, "env_id": env_id, "algo": algo, "steps": steps,
              "seed": seed, "mode": mode, "normalize_obs": bool(normalize_obs),
              "env_kwargs": env_kwargs, "algo_kwargs": algo_kwargs, "eval_every": eval_every,
              "eval_episodes": eval_episodes, "checkpoint_every": checkpoint_every,
              "agents": agents, "modules": ids, "observation": observation,
              "checkpoint": "checkpoint",
              "address": address, "num_env_runners": int(num_env_runners),
              "num_envs_per_runner": int(num_envs_per_runner),
              "num_cpus_per_learner": num_cpus_per_learner,
              "num_gpus_per_learner": num_gpus_per_learner, "ray_version": ray_version}
    write_config(out, config)
    started = init_ray(address, num_cpus if num_cpus else max(2, int(num_env_runners)))
    algorithm = None
    t0 = time.perf_counter()
    try:
        algorithm = build_config(
            task, mode, algo, seed, num_env_runners=num_env_runners,
            num_envs_per_runner=num_envs_per_runner, env_kwargs=env_kwargs,
            algo_kwargs=algo_kwargs, num_cpus_per_learner=num_cpus_per_learner,
            num_gpus_per_learner=num_gpus_per_learner, normalize_obs=normalize_obs,
            flat_obs=flat_obs, frame_stack=frame_stack,
            spaces=(agents, per_agent)).build_algo()
        rows = _iterate(algorithm, task, mode, agents, ids, env_kwargs, steps, seed, out,
                        eval_every, eval_episodes, checkpoint_every, progress, t0,
                        use_filter, observation)
    finally:
        if algorithm is not None:
            algorithm.stop()
        if started:
            ray.shutdown()
    wall = time.perf_counter() - t0
    timesteps = int(rows[-1]["timesteps"])
    config.update({"wall_time_s": round(wall, 1), "timesteps_done": timesteps})
    write_config(out, config)
    final = out / "checkpoint"
    res = {"out": str(out), "model": str(final), "models": {a: str(final) for a in agents},
           "mode": mode, "engine": "rllib", "wall_time_s": wall, "timesteps": timesteps,
           "last_eval": rows[-1], "rows": rows}
    if mode is not None:
        res["agents"] = agents
    return res


def _iterate(algorithm, task, mode, agents, ids, env_kwargs, steps, seed, out, eval_every,
             eval_episodes, checkpoint_every, progress, t0, normalize,
             observation) -> list[dict]:
    """``algorithm.train()`` up to ``steps`` environment steps, with the run log."""
    from .callbacks import episodes_of
    from .env import learner_env
    from .evaluation import FILTER_FILE, ModulePolicy, filters_from_state

    eval_env = learner_env(task, mode, flat=observation["flat"],
                           frame_stack=observation["frame_stack"], **env_kwargs)
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=steps, unit="step", desc=out.name, dynamic_ncols=True)

    obs_spaces = {a: eval_env.observation_space(a) for a in agents}

    def policies():
        norm = filters_from_state(filter_state(algorithm), obs_spaces) if normalize else {}
        return {a: ModulePolicy(algorithm.get_module(ids[a]), eval_env.action_space(a),
                                norm.get(a)) for a in agents}

    def evaluate(episodes: int, deterministic: bool):
        res = evaluate_agents(policies(), eval_env, episodes, 10_000 + seed, deterministic)
        if mode is None:  # one-agent task: the summary columns only, as the SB3 path
            (only,) = res.pop("agents").values()
            res["lengths"] = only["lengths"]
        return res

    def save(path: Path):
        algorithm.save(str(path.absolute()))
        if normalize:
            (path / FILTER_FILE).write_bytes(pickle.dumps(filter_state(algorithm)))

    schedule = Schedule(eval_every, checkpoint_every, steps, episodes=eval_episodes,
                        episode_steps=episode_limit(eval_env))
    log = RunLog(out, agents, evaluate, lambda: save(out / "best_checkpoint"), t0, bar,
                 schedule, 10_000 + seed)
    try:
        n = 0
        while n < steps:
            result = algorithm.train()
            n = _steps_of(result)
            for agent, ret, length, success in episodes_of(result):
                log.episode(n, agent, ret, length, success)
            if bar is not None:
                bar.update(min(n, steps) - bar.n)
            if schedule.checkpoint_due(n):
                save(out / "checkpoints" / f"step_{n}")
            episodes = schedule.eval_due(n)
            if episodes:
                log.evaluate(n, episodes)
        if schedule.final_checkpoint_due(n):
            save(out / "checkpoints" / f"step_{n}")
        log.evaluate(n, schedule.final_episodes())
        save(out / "checkpoint")
    finally:
        log.close()
        eval_env.close()
    return log.rows


def filter_state(algorithm):
    """The MeanStdFilter state of the first env runner (the driver's when there is no remote
    one), None without ``normalize_obs``."""
    group = algorithm.env_runner_group
    if group is not None and group.num_healthy_remote_workers() > 0:
        states = group.foreach_env_runner(lambda er: er._env_to_module.get_state(),
                                          remote_worker_ids=[1], local_env_runner=False)
        state = states[0] if states else {}
    else:
        state = algorithm.env_runner._env_to_module.get_state()
    return (state or {}).get("MeanStdFilter")
