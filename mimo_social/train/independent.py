"""``--mode independent``: one SB3 policy per agent, all acting in one world at the same time.

Every model's ``learn()`` runs in its own thread on an :class:`~mimo_social.train.lockstep.
AgentView` of one shared ParallelEnv (:mod:`mimo_social.train.lockstep`); episodes, evaluations
and checkpoints are handled in the stepping thread while every model is parked. Writes
``model_<agent>.zip``, ``best_model_<agent>.zip`` and
``checkpoints/model_<agent>_<steps>_steps.zip``.
A stop signal (:mod:`mimo_social.train.interrupt`; it reaches the main thread, which steps the
env) ends every learner at the same env step: the stepping thread raises :class:`Interrupted`,
which aborts the learner threads, and the models are saved as they stand.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

from .envs import make_parallel_env
from .interrupt import Interrupted
from .lockstep import Lockstep, run_lockstep
from .progress import write_config
from .rollouts import evaluate_agents
from .runlog import RunLog, Schedule, first_update, rounding_note
from .single import warn

__all__ = ["train_independent"]


class _IndependentLog:
    """Episode returns of the shared env, evaluations and checkpoints of the independent mode
    (runs in the stepping thread, every model parked)."""

    def __init__(self, log: RunLog, schedule: Schedule, models: dict, out: Path, stop=None):
        self.log, self.schedule, self.models, self.out = log, schedule, models, out
        self.stop = stop
        self.hub: Lockstep | None = None
        self.returns = {a: 0.0 for a in models}
        self.lengths = {a: 0 for a in models}

    @property
    def rows(self):
        return self.log.rows

    @property
    def eval_steps(self):
        return self.log.eval_steps

    def on_reset(self, obs, infos):
        self.returns = {a: 0.0 for a in self.models}
        self.lengths = {a: 0 for a in self.models}

    def on_step(self, obs, rewards, terms, truncs, infos):
        n = self.hub.env_steps
        for a, r in rewards.items():
            self.returns[a] += float(r)
            self.lengths[a] += 1
            if terms.get(a) or truncs.get(a):
                self.log.episode(n, a, self.returns[a], self.lengths[a],
                                 infos.get(a, {}).get("is_success"))
        if self.log.bar is not None:
            self.log.bar.update(n - self.log.bar.n)
        if self.stop is not None and self.stop.requested:
            raise Interrupted(f"signal {self.stop.signum}")
        if self.schedule.checkpoint_due(n):
            self.checkpoint(n)
        episodes = self.schedule.eval_due(n)
        if episodes:
            self.log.evaluate(n, episodes)

    def checkpoint(self, n: int) -> None:
        (self.out / "checkpoints").mkdir(exist_ok=True)
        for a, m in self.models.items():
            m.save(self.out / "checkpoints" / f"model_{a}_{n}_steps.zip")


def train_independent(cls, algo_kwargs, task, env_kwargs, steps, seed, out, eval_env,
                      eval_episodes, eval_seed, schedule, bar, t0, verbose, stop=None,
                      config=None):
    """Train one model per agent in lockstep; returns ``(models, state)`` (``state.log.rows``:
    the evaluations). ``stop``: a :class:`~mimo_social.train.interrupt.StopSignals`."""
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv

    from .encoders import policy_for

    normalize_obs = bool((config or {}).get("normalize_obs"))
    env = make_parallel_env(task, **env_kwargs)   # flat observations (one space per agent)
    agents = list(env.possible_agents)
    models: dict[str, Any] = {}
    log = RunLog(out, agents,
                 lambda k, det: evaluate_agents(models, eval_env, k, eval_seed, det),
                 lambda: [m.save(out / f"best_model_{a}.zip") for a, m in models.items()], t0,
                 bar, schedule, eval_seed)
    state = _IndependentLog(log, schedule, models, out, stop)
    hub = Lockstep(env, on_step=state.on_step, on_reset=state.on_reset)
    state.hub = hub
    try:
        for k, a in enumerate(agents):  # built in order: each seeds the global RNGs (SB3)
            view = hub.view(a)
            venv = DummyVecEnv([lambda v=view: Monitor(v)])
            policy, kw = policy_for(venv.observation_space, algo_kwargs, normalize_obs,
                                    str((config or {}).get("algo")) == "recurrent_ppo")
            models[a] = cls(policy, venv, seed=seed + k, device="cpu", verbose=verbose, **kw)
        first = models[agents[0]]
        schedule.first = first_update(first)
        if config is not None:
            planned, note = rounding_note(first, str(config.get("algo", "")), steps)
            if note:
                warn(note)
            if bar is not None:
                bar.total = planned
            config.update({"steps": steps, "steps_planned": planned, **schedule.describe()})
            write_config(out, config)
        try:
            run_lockstep(hub, {a: functools.partial(models[a].learn, total_timesteps=steps)
                               for a in agents})
        except Interrupted:
            pass
        except Exception:
            if stop is None or not stop.requested:
                raise
        interrupted = stop is not None and stop.requested
        n = hub.env_steps   # every model has made its last update (or was stopped)
        for a, m in models.items():
            m.save(out / f"model_{a}.zip")
        if schedule.final_checkpoint_due(n) and not interrupted:
            state.checkpoint(n)
        log.evaluate(n, 1 if interrupted else schedule.final_episodes())
    finally:
        log.close()
        env.close()
    return models, state
