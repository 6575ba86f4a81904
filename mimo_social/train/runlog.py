"""The run log of every mode: episodes, evaluations, best model, learning curve; when to evaluate.

:class:`RunLog` writes ``episodes.csv`` (one-agent runs: ``timesteps, return, length, success``;
multi-agent runs: one row per agent and episode, with an ``agent`` column), ``progress.csv`` and
``learning_curve.png`` and saves the best model. Every evaluation runs the deterministic policy
(the mean action) and the stochastic one (sampled actions; torch's random numbers forked and
seeded, so that neither training nor the evaluation depends on the other) on the same seeded
episodes. :class:`Schedule` says when an evaluation (and with how many episodes) or a checkpoint
is due: by default within an evaluation budget (:data:`EVAL_FRACTION` of the steps trained).
:func:`sb3_callback` is the SB3 callback of the one-learner and shared modes.
"""

from __future__ import annotations

import csv
import math
import time
from pathlib import Path
from typing import Callable

import numpy as np

from .plots import plot_learning_curve
from .progress import agent_columns, write_progress

__all__ = ["RunLog", "Schedule", "EVAL_FRACTION", "EVAL_POINTS", "sb3_callback",
           "episode_limit", "first_update", "planned_timesteps", "rounding_note"]

#: the default evaluation budget: env steps evaluated (both policies) per env step trained
EVAL_FRACTION = 0.1
#: the default schedule's candidate evaluation points (geometric from the first update)
EVAL_POINTS = 20


def episode_limit(env, default: int = 1000) -> int:
    """The most steps an episode of ``env`` (a flat Gymnasium env or ParallelEnv) can last."""
    seen, todo = set(), [env]
    while todo:
        obj = todo.pop(0)
        if obj is None or id(obj) in seen:
            continue
        seen.add(id(obj))
        value = getattr(obj, "max_steps", None)
        if isinstance(value, (int, np.integer)) and value > 0:
            return int(value)
        todo += [getattr(obj, "unwrapped", None), getattr(obj, "parallel", None),
                 getattr(obj, "env", None)]
    spec = getattr(env, "spec", None)
    return int(getattr(spec, "max_episode_steps", None) or default)


def first_update(model, per_env_step: int = 1) -> int:
    """Env steps before an SB3 model's first update: on-policy ``n_steps * n_envs``;
    off-policy ``learning_starts + 1`` (``per_env_step``: SB3 timesteps per env step)."""
    if hasattr(model, "n_steps"):
        return max(1, int(model.n_steps) * int(model.n_envs) // per_env_step)
    return max(1, (int(getattr(model, "learning_starts", 0)) + 1) // per_env_step)


def planned_timesteps(model, total: int) -> int:
    """SB3 timesteps ``model.learn(total_timesteps=total)`` will run: on-policy algorithms
    collect whole rollouts of ``n_steps * n_envs``; off-policy ones step every env together."""
    chunk = (int(model.n_steps) * int(model.n_envs) if hasattr(model, "n_steps")
             else int(model.n_envs))
    return -(-int(total) // chunk) * chunk


def rounding_note(model, algo: str, steps: int, per_env_step: int = 1) -> tuple[int, str | None]:
    """(env steps that will be trained, a message when that is not ``steps``)."""
    done = planned_timesteps(model, steps * per_env_step) // per_env_step
    if done == steps:
        return done, None
    if hasattr(model, "n_steps"):
        why = (f"{algo.upper()} collects rollouts of n_steps x n_envs = {model.n_steps} x "
               f"{model.n_envs} = {model.n_steps * model.n_envs}"
               + (f" agent-steps ({per_env_step} agents a world)" if per_env_step > 1 else ""))
    else:
        why = f"{algo.upper()} steps its {model.n_envs} envs together"
    return done, (f"{why}: --steps {steps} trains {done} steps (give a multiple, or n_steps in "
                  "--algo-kwargs, to train exactly --steps)")


class Schedule:
    """Evaluation and checkpoint step counters. Nothing is due once ``n`` reaches ``total``: the
    last evaluation and checkpoint are made after the models' last update (:meth:`final`).

    ``eval_every``: evaluate every so many steps with ``episodes`` episodes (per policy), as
    asked. ``None``: the budgeted default: no evaluation before the first update (``first``,
    set once the model exists), candidate points on a geometric grid of :data:`EVAL_POINTS` from
    there to ``total``, and at a point ``ceil(episodes * n / total)`` episodes per policy (one
    early, ``episodes`` at the end) if the env steps evaluated so far plus its own
    (``policies * episodes * episode_steps``, an episode counted at its longest) stay within
    ``fraction`` of the steps trained and leave room for the final evaluation: early evaluations
    are short and come as soon as one episode fits, later ones longer. The final evaluation has
    as many episodes (1 to ``episodes``) as fit in ``fraction * total``."""

    def __init__(self, eval_every: int | None, checkpoint_every: int, total: int, *,
                 episodes: int = 5, episode_steps: int = 1000, first: int = 1,
                 fraction: float = EVAL_FRACTION, policies: int = 2):
        self.eval_every, self.checkpoint_every, self.total = eval_every, checkpoint_every, total
        self.episodes, self.episode_steps, self.fraction = int(episodes), episode_steps, fraction
        self.policies = policies
        self.next_ckpt = checkpoint_every if checkpoint_every > 0 else math.inf
        self.spent = 0            # env steps evaluated so far (every policy)
        self.first = first
        self.next_eval = eval_every if eval_every else None

    @property
    def budgeted(self) -> bool:
        return not self.eval_every

    def describe(self) -> dict:
        """What config.json says about the schedule."""
        if not self.budgeted:
            return {"eval_every": self.eval_every, "eval_episodes": self.episodes}
        return {"eval_every": None, "eval_episodes": self.episodes,
                "eval_budget": self.fraction, "eval_first": self.first,
                "eval_episode_steps_max": self.episode_steps}

    def cost(self, episodes: int) -> int:
        return self.policies * int(episodes) * int(self.episode_steps)

    def final_episodes(self) -> int:
        if not self.budgeted:
            return self.episodes
        fit = int(self.fraction * self.total) // max(1, self.cost(1))
        return max(1, min(self.episodes, fit))

    def points(self) -> np.ndarray:
        lo, hi = max(1, self.first), self.total
        if lo >= hi:
            return np.array([], dtype=int)
        return np.unique(np.geomspace(lo, hi, EVAL_POINTS).astype(int))[:-1]

    def spend(self, steps: int) -> None:
        self.spent += int(steps)

    def final_checkpoint_due(self, n: int) -> bool:
        return self.next_ckpt <= n

    def checkpoint_due(self, n: int) -> bool:
        if n < self.next_ckpt or n >= self.total:
            return False
        while self.next_ckpt <= n:
            self.next_ckpt += self.checkpoint_every
        return True

    def eval_due(self, n: int) -> int:
        """Episodes (per policy) to evaluate now; 0: none due."""
        if n >= self.total:
            return 0
        if not self.budgeted:
            if n < self.next_eval:
                return 0
            while self.next_eval <= n:
                self.next_eval += self.eval_every
            return self.episodes
        if self.next_eval is None:
            self.next_eval = self.first
        if n < self.next_eval:
            return 0
        reserve = self.cost(self.final_episodes())
        room = min(self.fraction * n - self.spent,
                   self.fraction * self.total - reserve - self.spent)
        # the episodes grow with the run, from one to `episodes` at its end
        episodes = max(1, min(self.episodes, math.ceil(self.episodes * n / self.total)))
        if room < self.cost(episodes):
            return 0
        later = self.points()[self.points() > n]
        self.next_eval = int(later[0]) if len(later) else self.total
        return episodes


class RunLog:
    """What every mode writes while it trains (one instance per run, used from one thread at a
    time). ``evaluate(episodes, deterministic)`` gives :func:`~.rollouts.evaluate_policy`'s or
    :func:`~.rollouts.evaluate_agents`' numbers; ``agents=None``: a one-agent run (no agent
    column, no per-agent columns)."""

    def __init__(self, out: Path, agents, evaluate: Callable[[int, bool], dict],
                 save_best: Callable[[], None], t_start: float, bar=None,
                 schedule: Schedule | None = None, eval_seed: int = 0):
        self.out, self.agents = out, (list(agents) if agents is not None else None)
        self._evaluate, self._save_best = evaluate, save_best
        self.t_start, self.bar, self.schedule, self.eval_seed = t_start, bar, schedule, eval_seed
        self.rows: list[dict] = []
        #: functions giving further columns of every progress row (e.g. a curriculum's stage)
        self.columns: list[Callable[[], dict]] = []
        self.best = -math.inf
        self.train_returns: list[float] = []
        self.eval_steps = 0
        self.file = open(out / "episodes.csv", "w", newline="")
        self.episodes = csv.writer(self.file)
        self.episodes.writerow(["timesteps", "return", "length", "success"] if agents is None
                               else ["timesteps", "agent", "return", "length", "success"])

    def episode(self, n: int, agent: str | None, ret: float, length: int, success) -> None:
        self.train_returns.append(float(ret))
        self.episodes.writerow([n, *(() if self.agents is None else (agent,)), f"{ret:.6g}",
                                int(length), "" if success is None else int(bool(success))])

    def _stochastic(self, episodes: int) -> dict:
        import torch
        with torch.random.fork_rng(devices=[]):
            torch.manual_seed(self.eval_seed)
            return self._evaluate(episodes, False)

    @staticmethod
    def _env_steps(res: dict) -> int:
        if "agents" in res:   # the longest-lived agent's steps, episode by episode
            per = [r["lengths"] for r in res["agents"].values()]
            return int(np.sum(np.max(per, axis=0)))
        return int(np.sum(res["lengths"]))

    def evaluate(self, n: int, episodes: int, budget: bool = True) -> dict:
        """One evaluation row at env step ``n``; ``budget=False``: its steps are not taken from
        the schedule's evaluation budget (an evaluation outside the schedule, e.g. right after a
        behaviour-cloning warm start)."""
        det = self._evaluate(episodes, True)
        sto = self._stochastic(episodes)
        steps = self._env_steps(det) + self._env_steps(sto)
        self.eval_steps += steps
        if self.schedule is not None and budget:
            self.schedule.spend(steps)
        row = {"timesteps": n, "wall_time_s": round(time.perf_counter() - self.t_start, 2),
               "eval_return_mean": det["return_mean"], "eval_return_std": det["return_std"],
               "eval_length_mean": det["length_mean"], "eval_success_rate": det["success_rate"],
               "eval_return_mean_stochastic": sto["return_mean"],
               "eval_return_std_stochastic": sto["return_std"],
               "eval_length_mean_stochastic": sto["length_mean"],
               "eval_success_rate_stochastic": sto["success_rate"],
               "eval_episodes": int(episodes), "eval_steps": self.eval_steps,
               "train_return_mean": (float(np.mean(self.train_returns)) if self.train_returns
                                     else float("nan")),
               "train_episodes": len(self.train_returns)}
        if "agents" in det:
            row.update(agent_columns(det))
            row.update(agent_columns(sto, suffix="_stochastic"))
        for extra in self.columns:
            row.update(extra())
        self.train_returns = []
        self.rows.append(row)
        if det["return_mean"] > self.best:
            self.best = det["return_mean"]
            self._save_best()
        self.write()
        if self.bar is not None:
            post = {"eval_return": f"{det['return_mean']:.3g}"}
            if not math.isnan(det["success_rate"]):
                post["success"] = f"{det['success_rate']:.0%}/{sto['success_rate']:.0%}"
            self.bar.set_postfix(post)
        return row

    def write(self) -> None:
        """progress.csv, the episodes so far and the curve (also with no evaluation yet)."""
        write_progress(self.out / "progress.csv", self.rows)
        self.file.flush()
        plot_learning_curve(self.out)

    def close(self) -> None:
        if not self.file.closed:
            self.file.close()
        if self.bar is not None:
            self.bar.close()


def sb3_callback(log: RunLog, schedule: Schedule, slot_agents: list[str] | None,
                 per_env_step: int, save_checkpoint: Callable[[int], None], stop=None,
                 update_threads: int = 1, on_step: Callable[[int, list], None] | None = None):
    """SB3 callback of the one-learner, scripted and shared modes: episodes (by slot: agent
    ``slot_agents[i % len]``), evaluations, checkpoints, and a stop when ``stop.requested``
    (:class:`~.interrupt.StopSignals`). ``per_env_step``: SB3 timesteps per environment step
    (the number of agent slots a world). The final evaluation is the caller's. Torch runs on
    one thread while the envs step (the workers have the other cores) and on
    ``update_threads`` (default 1) for the update in between. The runs keep 1: on the 2-core
    machine under load, PPO's update of reach's 64x64 MLP (320 minibatches of 64) took 4-10 s
    on one thread and 89-219 s on two (threads spinning against the other processes).
    ``on_step(n, infos)``: after each vector step's episodes are logged, before a checkpoint or
    evaluation (a curriculum's :meth:`~.curriculum.CurriculumController.on_step`)."""
    import torch
    from stable_baselines3.common.callbacks import BaseCallback

    class RunLogCallback(BaseCallback):
        def _on_rollout_start(self) -> None:
            torch.set_num_threads(1)

        def _on_rollout_end(self) -> None:
            torch.set_num_threads(max(1, int(update_threads)))

        def _on_training_end(self) -> None:
            torch.set_num_threads(1)

        def _on_step(self) -> bool:
            n = self.num_timesteps // per_env_step
            for i, info in enumerate(self.locals.get("infos", ())):
                ep = info.get("episode")
                if ep is not None:
                    agent = slot_agents[i % len(slot_agents)] if slot_agents else None
                    log.episode(n, agent, float(ep["r"]), int(ep["l"]), info.get("is_success"))
            if on_step is not None:
                on_step(n, self.locals.get("infos", ()))
            if log.bar is not None:
                log.bar.update(n - log.bar.n)
            if stop is not None and stop.requested:
                return False
            if schedule.checkpoint_due(n):
                save_checkpoint(n)
            episodes = schedule.eval_due(n)
            if episodes:
                log.evaluate(n, episodes)
            return True

    return RunLogCallback()
