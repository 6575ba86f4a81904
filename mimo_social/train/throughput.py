"""Training throughput of the two engines: environment steps per second while PPO trains.

``sb3_throughput(task, workers, seconds)``
    SB3's PPO with one shared policy on ``workers`` worlds, each in its own worker process
    (:func:`~mimo_social.train.vector.sb3_vec_env` with ``n_envs = n_cpus = workers``, spawned).
``rllib_throughput(task, workers, seconds)``
    RLlib's PPO with one shared policy on ``workers`` env runners (one world each), built by
    :func:`mimo_social.train.rllib.build_config`; Ray must be initialised by the caller (a
    local instance or ``ray.init(address=...)``).

Both train the same way, so that only the engine differs: ``rollout`` environment steps per
iteration (every agent's transition of them is a sample: two agents give ``2 * rollout``),
``epochs`` passes over them in minibatches of ``minibatch`` samples, a ``hidden`` MLP (64x64 by
default) for the policy and for the value function, no observation normalisation. The first
iteration (process and env start, GL contexts, the first update) is the warm-up and is timed
apart; then whole iterations run until ``seconds`` have passed. Each returns a dict:
``env_steps`` and ``seconds`` of the timed iterations, ``steps_per_s`` (their ratio),
``iterations``, ``warmup_s``, ``sample_s`` / ``learn_s`` (time spent collecting samples and
updating the policy per timed iteration, mean; RLlib's are its smoothed timers).
"""

from __future__ import annotations

import functools
import time
from typing import Any, Mapping, Sequence

from .tasks import MULTI_TASKS, TrainInputError, task_module

__all__ = ["sb3_throughput", "rllib_throughput", "time_to_success", "ENGINES"]

ENGINES = ("sb3", "rllib")


def _check(task: str, workers: int, seconds: float) -> None:
    if task not in MULTI_TASKS:
        raise TrainInputError(f"throughput: task {task!r}; allowed: {', '.join(MULTI_TASKS)}")
    if int(workers) < 1:
        raise TrainInputError(f"throughput: workers={workers}; allowed: a positive integer")
    if not seconds > 0:
        raise TrainInputError(f"throughput: seconds={seconds}; allowed: a positive number")


def sb3_throughput(task: str, workers: int, seconds: float, *, seed: int = 0,
                   rollout: int = 1024, minibatch: int = 256, epochs: int = 4,
                   hidden: Sequence[int] = (64, 64),
                   env_kwargs: Mapping[str, Any] | None = None) -> dict:
    """Environment steps per second of SB3 PPO (shared policy) on ``workers`` worker processes."""
    _check(task, workers, seconds)
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback

    from .vector import sb3_vec_env

    module = task_module(task)
    env_fn = functools.partial(module.parallel_env, **dict(env_kwargs or {}))
    t0 = time.perf_counter()
    venv = sb3_vec_env(env_fn, n_envs=workers, n_cpus=workers)
    sample = []

    class Timer(BaseCallback):
        def _on_rollout_start(self) -> None:
            self.t = time.perf_counter()

        def _on_rollout_end(self) -> None:
            sample.append(time.perf_counter() - self.t)

        def _on_step(self) -> bool:
            return True

    try:
        n_agents = venv.num_envs // workers
        n_steps = max(1, rollout // workers)         # per slot: workers * n_agents slots
        per_iter = n_steps * venv.num_envs           # agent transitions per iteration
        model = PPO("MlpPolicy", venv, n_steps=n_steps, batch_size=min(minibatch, per_iter),
                    n_epochs=epochs, policy_kwargs={"net_arch": list(hidden)}, seed=seed,
                    device="cpu", verbose=0)
        timer = Timer()
        model.learn(per_iter, callback=timer)        # warm-up: the first iteration
        warm = time.perf_counter() - t0
        sample.clear()
        start, t1, iters = model.num_timesteps, time.perf_counter(), 0
        while time.perf_counter() - t1 < seconds:
            model.learn(per_iter, callback=timer, reset_num_timesteps=False)
            iters += 1
        elapsed = time.perf_counter() - t1
        env_steps = (model.num_timesteps - start) // n_agents
    finally:
        venv.close()
    return _result(env_steps, elapsed, iters, warm, sum(sample) / len(sample),
                   elapsed / iters - sum(sample) / len(sample))


def _result(env_steps, elapsed, iters, warm, sample_s, learn_s) -> dict:
    return {"env_steps": int(env_steps), "seconds": round(elapsed, 3),
            "steps_per_s": env_steps / elapsed, "iterations": iters,
            "warmup_s": round(warm, 2), "sample_s": round(sample_s, 3),
            "learn_s": round(learn_s, 3)}


def rllib_throughput(task: str, workers: int, seconds: float, *, seed: int = 0,
                     rollout: int = 1024, minibatch: int = 256, epochs: int = 4,
                     hidden: Sequence[int] = (64, 64), envs_per_runner: int = 1,
                     env_kwargs: Mapping[str, Any] | None = None) -> dict:
    """Environment steps per second of RLlib PPO (shared policy) on ``workers`` env runners
    (``envs_per_runner`` worlds each). Ray must be running (``ray.init``)."""
    _check(task, workers, seconds)
    from ray.rllib.utils.metrics import ENV_RUNNER_RESULTS, NUM_ENV_STEPS_SAMPLED_LIFETIME

    from .rllib import build_config, flat_env

    # the spaces passed in: one shared module for every agent (their spaces are equal in the
    # social tasks; build_config's own check reads Box bounds, which a Discrete face lacks)
    env = flat_env(task, "shared", **dict(env_kwargs or {}))
    try:
        agents = list(env.possible_agents)
        spaces = (agents, {a: (env.observation_space(a), env.action_space(a)) for a in agents})
    finally:
        env.close()
    algo_kwargs = {"fcnet_hiddens": list(hidden), "fcnet_activation": "tanh",
                   "train_batch_size_per_learner": rollout, "minibatch_size": minibatch,
                   "num_epochs": epochs}
    config = build_config(task, "shared", "ppo", seed, num_env_runners=workers,
                          num_envs_per_runner=envs_per_runner, env_kwargs=dict(env_kwargs or {}),
                          algo_kwargs=algo_kwargs, spaces=spaces)
    t0 = time.perf_counter()
    algo = config.build_algo()
    try:
        first = algo.train()                         # warm-up: the first iteration
        warm = time.perf_counter() - t0
        start = first[ENV_RUNNER_RESULTS][NUM_ENV_STEPS_SAMPLED_LIFETIME]
        t1, iters = time.perf_counter(), 0
        while time.perf_counter() - t1 < seconds:
            result = algo.train()
            iters += 1
        elapsed = time.perf_counter() - t1
        env_steps = result[ENV_RUNNER_RESULTS][NUM_ENV_STEPS_SAMPLED_LIFETIME] - start
    finally:
        algo.stop()
    timers = result.get("timers", {})
    return _result(env_steps, elapsed, iters, warm, timers.get("env_runner_sampling_timer", 0.0),
                   timers.get("learner_update_timer", 0.0))


def time_to_success(engine: str, task: str, out, *, threshold: float = 0.8,
                    steps: int = 300_000, workers: int = 2, seed: int = 0,
                    eval_every: int = 10_000, eval_episodes: int = 10) -> dict:
    """Train PPO (shared policy, each engine's defaults, 64x64 tanh MLP in both) on ``task`` for
    ``steps`` env steps with ``workers`` worker processes / env runners, evaluating every
    ``eval_every`` steps, into ``out``; the wall time and steps at the first evaluation whose
    success rate reaches ``threshold`` (None where none did). Long: minutes to hours."""
    import math
    from pathlib import Path

    from .progress import read_progress

    if engine not in ENGINES:
        raise TrainInputError(f"engine {engine!r}; allowed: {', '.join(ENGINES)}")
    common = dict(mode="shared", eval_every=eval_every, eval_episodes=eval_episodes,
                  checkpoint_every=0, progress=False)
    if engine == "sb3":
        from .runner import train
        res = train(task, "ppo", steps, seed, out, n_envs=workers, n_cpus=workers, **common)
    else:
        from .rllib import train_rllib
        res = train_rllib(task, "ppo", steps, seed, out, num_env_runners=workers, **common)
    p = read_progress(Path(out) / "progress.csv")
    hit = [i for i, s in enumerate(p["eval_success_rate"]) if not math.isnan(s) and s >= threshold]
    first = hit[0] if hit else None
    return {"engine": engine, "task": task, "threshold": threshold, "workers": workers,
            "steps_budget": steps, "reached": first is not None,
            "wall_time_s": None if first is None else float(p["wall_time_s"][first]),
            "timesteps": None if first is None else int(p["timesteps"][first]),
            "run_wall_time_s": float(res["wall_time_s"]),
            "best_success": float(max((s for s in p["eval_success_rate"] if not math.isnan(s)),
                                      default=float("nan"))), "out": str(out)}
