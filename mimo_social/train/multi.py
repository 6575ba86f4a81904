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

Evaluation (every ``--eval-every`` steps and at the end) runs ``--eval-episodes`` deterministic
episodes on a separate env in which every learning agent acts with its own policy (scripted
partners keep their script). It gives per-agent returns and success rates (``is_success`` of the
agent's info on its last step); the summary columns average them across agents.
"""

from __future__ import annotations

import functools
import time
from pathlib import Path
from typing import Callable


from .envs import make_env, make_parallel_env, make_scripted_env
from .independent import train_independent
from .progress import write_config
from .rollouts import evaluate_agents
from .runlog import RunLog, Schedule
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


def _sb3_callback(log: RunLog, schedule: Schedule, slot_agents: list[str], per_env_step: int,
                  save_checkpoint: Callable[[int], None]):
    """SB3 callback of the shared and scripted modes: episodes by slot, evaluations, checkpoints.
    ``per_env_step``: SB3 timesteps per environment step (the number of agent slots a world)."""
    from stable_baselines3.common.callbacks import BaseCallback

    class MultiAgentLog(BaseCallback):
        def _on_step(self) -> bool:
            n = self.num_timesteps // per_env_step
            for i, info in enumerate(self.locals.get("infos", ())):
                ep = info.get("episode")
                if ep is not None:
                    log.episode(n, slot_agents[i % len(slot_agents)], float(ep["r"]), int(ep["l"]),
                                info.get("is_success"))
            if log.bar is not None:
                log.bar.update(n - log.bar.n)
            if schedule.checkpoint_due(n):
                save_checkpoint(n)
            if schedule.eval_due(n):
                log.evaluate(n)
            return True

        def _on_training_end(self) -> None:  # after the last update
            n = self.num_timesteps // per_env_step
            if log.bar is not None:
                log.bar.update(n - log.bar.n)
            if schedule.final_checkpoint_due(n):
                save_checkpoint(n)
            log.evaluate(n)

    return MultiAgentLog()


# -- training ------------------------------------------------------------------------------------
def train_multi(task: str, algo: str, steps: int, seed: int, out: Path, *, mode: str | None,
                eval_every: int, eval_episodes: int, checkpoint_every: int, progress: bool,
                env_kwargs: dict, algo_kwargs: dict, n_envs: int = 1, n_cpus: int = 0,
                verbose: int = 0, config: dict) -> dict:
    """The multi-agent part of :func:`mimo_social.train.runner.train` (arguments checked there)."""
    mode = check_mode(task, mode)
    if mode != "shared" and (n_envs != 1 or n_cpus != 0):
        raise TrainInputError(f"--n-envs/--n-cpus are for --mode shared; got n_envs={n_envs}, "
                              f"n_cpus={n_cpus} with --mode {mode}")
    cls = algo_class(algo)
    module = task_module(task)
    config.update({"env_module": module.__name__, "mode": mode, "n_envs": n_envs,
                   "n_cpus": n_cpus})
    eval_env = (make_scripted_env if mode == "scripted" else make_parallel_env)(task, **env_kwargs)
    if mode == "shared":
        try:
            check_shared_spaces(eval_env, task)
        except TrainInputError:
            eval_env.close()
            raise
    agents = list(eval_env.possible_agents)
    config["agents"] = agents
    if (mode == "shared" and algo == "sac"
            and algo_kwargs.get("buffer_size") == min(1_000_000, steps)
            and "buffer_size" not in config.get("algo_kwargs_given", ())):
        # SB3 counts every agent's transition: room for all of them (train's default is steps)
        algo_kwargs["buffer_size"] = min(1_000_000, steps * len(agents))
    config.pop("algo_kwargs_given", None)
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
    schedule = Schedule(eval_every, checkpoint_every, steps)
    t0 = time.perf_counter()
    try:
        if mode == "independent":
            models, done = train_independent(cls, algo_kwargs, task, env_kwargs, steps, seed, out,
                                             eval_env, eval_episodes, eval_seed, schedule, bar,
                                             t0, verbose)
            rows = done.rows
        else:
            model, log, venv = _train_one_policy(cls, algo_kwargs, module, task, mode, env_kwargs,
                                                 steps, seed, out, eval_env, eval_episodes,
                                                 eval_seed, schedule, bar, t0, verbose, n_envs,
                                                 n_cpus)
            rows = log.rows
    finally:
        eval_env.close()
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - t0
    timesteps = rows[-1]["timesteps"]
    config.update({"wall_time_s": round(wall, 1), "timesteps_done": int(timesteps)})
    write_config(out, config)
    models_out = ({a: str(out / f"model_{a}.zip") for a in agents} if mode == "independent"
                  else {a: str(out / "model.zip") for a in agents})
    return {"out": str(out), "model": models_out[agents[0]], "models": models_out,
            "mode": mode, "agents": agents, "wall_time_s": wall, "timesteps": int(timesteps),
            "last_eval": rows[-1], "rows": rows}


def _train_one_policy(cls, algo_kwargs, module, task, mode, env_kwargs, steps, seed, out, eval_env,
                      eval_episodes, eval_seed, schedule, bar, t0, verbose, n_envs, n_cpus):
    """shared (one policy, one VecEnv slot per agent) and scripted (one learner) modes."""
    from stable_baselines3.common.vec_env import DummyVecEnv, VecMonitor

    agents = list(eval_env.possible_agents)
    if mode == "shared":
        from .vector import sb3_vec_env
        env_fn = functools.partial(module.parallel_env, **env_kwargs)
        venv = VecMonitor(sb3_vec_env(env_fn, n_envs=n_envs, n_cpus=n_cpus))
        per_env_step = len(agents)
    else:
        from stable_baselines3.common.monitor import Monitor
        venv = DummyVecEnv([lambda: Monitor(make_env(task, **env_kwargs))])
        per_env_step = 1
    try:
        model = cls("MlpPolicy", venv, seed=seed, device="cpu", verbose=verbose, **algo_kwargs)

        def evaluate():
            return evaluate_agents({a: model for a in agents}, eval_env, eval_episodes, eval_seed)

        def checkpoint(n):
            (out / "checkpoints").mkdir(exist_ok=True)
            model.save(out / "checkpoints" / f"model_{n}_steps.zip")

        log = RunLog(out, agents, evaluate, lambda: model.save(out / "best_model.zip"), t0, bar)
        try:
            cb = _sb3_callback(log, schedule, agents, per_env_step, checkpoint)
            model.learn(total_timesteps=steps * per_env_step, callback=cb)
        finally:
            log.close()
        model.save(out / "model.zip")
    finally:
        venv.close()
    return model, log, venv

