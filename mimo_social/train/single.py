"""One learner: a one-agent task, or a social task's learner with its partner scripted.

Stable-Baselines3 on the task's Gymnasium env with flattened observations
(:func:`~mimo_social.train.envs.make_env`), one env, CPU; an SB3 callback evaluates every
``eval_every`` steps, checkpoints every ``checkpoint_every`` steps, logs every training episode to
``episodes.csv`` and rewrites ``progress.csv`` and ``learning_curve.png`` after each evaluation.
"""

from __future__ import annotations

import csv
import math
import time
from pathlib import Path

import numpy as np

from .envs import make_env
from .plots import plot_learning_curve
from .progress import write_config, write_progress
from .rollouts import evaluate_policy

__all__ = ["train_single"]


def _callbacks(out: Path, eval_env, eval_every: int, eval_episodes: int, eval_seed: int,
               checkpoint_every: int, total: int, progress: bool, t_start: float):
    from stable_baselines3.common.callbacks import BaseCallback

    class Periodic(BaseCallback):
        """Periodic evaluation, checkpoints, per-episode log, the CSVs, the PNG and a progress bar."""

        def __init__(self):
            super().__init__()
            self.rows: list[dict] = []
            self.next_eval = eval_every
            self.next_ckpt = checkpoint_every if checkpoint_every > 0 else math.inf
            self.best = -math.inf
            self.train_returns: list[float] = []
            self.bar = None
            self.episodes_file = open(out / "episodes.csv", "w", newline="")
            self.episodes = csv.writer(self.episodes_file)
            self.episodes.writerow(["timesteps", "return", "length", "success"])

        def _on_training_start(self):
            if progress:
                from tqdm import tqdm
                self.bar = tqdm(total=total, unit="step", desc=f"{out.name}", dynamic_ncols=True)

        def _on_step(self) -> bool:
            n = self.num_timesteps
            for info in self.locals.get("infos", ()):
                ep = info.get("episode")
                if ep is not None:
                    success = info.get("is_success")
                    self.train_returns.append(float(ep["r"]))
                    self.episodes.writerow([n, f"{ep['r']:.6g}", int(ep["l"]),
                                            "" if success is None else int(bool(success))])
            if self.bar is not None:
                self.bar.update(n - self.bar.n)
            if total > n >= self.next_ckpt:  # the last ones follow the last update
                self.checkpoint(n)
                while self.next_ckpt <= n:
                    self.next_ckpt += checkpoint_every
            if total > n >= self.next_eval:
                self.evaluate()
                while self.next_eval <= n:
                    self.next_eval += eval_every
            return True

        def checkpoint(self, n):
            (out / "checkpoints").mkdir(exist_ok=True)
            self.model.save(out / "checkpoints" / f"model_{n}_steps.zip")

        def evaluate(self):
            n = self.num_timesteps
            res = evaluate_policy(self.model, eval_env, eval_episodes, eval_seed)
            row = {"timesteps": n, "wall_time_s": round(time.perf_counter() - t_start, 2),
                   "eval_return_mean": res["return_mean"], "eval_return_std": res["return_std"],
                   "eval_length_mean": res["length_mean"],
                   "eval_success_rate": res["success_rate"],
                   "train_return_mean": (float(np.mean(self.train_returns))
                                         if self.train_returns else float("nan")),
                   "train_episodes": len(self.train_returns)}
            self.train_returns = []
            self.rows.append(row)
            if res["return_mean"] > self.best:
                self.best = res["return_mean"]
                self.model.save(out / "best_model.zip")
            write_progress(out / "progress.csv", self.rows)
            self.episodes_file.flush()
            plot_learning_curve(out)
            if self.bar is not None:
                post = {"eval_return": f"{res['return_mean']:.3g}"}
                if not math.isnan(res["success_rate"]):
                    post["success"] = f"{res['success_rate']:.0%}"
                self.bar.set_postfix(post)

        def _on_training_end(self):  # after the model's last update: what model.zip holds
            if self.next_ckpt <= self.num_timesteps:
                self.checkpoint(self.num_timesteps)
            if self.bar is not None:
                self.bar.update(self.num_timesteps - self.bar.n)
            self.evaluate()
            if self.bar is not None:
                self.bar.close()
            self.episodes_file.close()

    return Periodic()


def train_single(cls, task: str, steps: int, seed: int, out: Path, *, eval_every: int,
                 eval_episodes: int, checkpoint_every: int, progress: bool, env_kwargs: dict,
                 algo_kwargs: dict, verbose: int, config: dict) -> dict:
    """The one-learner part of :func:`mimo_social.train.runner.train` (arguments checked
    there); ``cls`` is the SB3 algorithm class."""
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv

    write_config(out, config)
    venv = DummyVecEnv([lambda: Monitor(make_env(task, **env_kwargs))])
    eval_env = make_env(task, **env_kwargs)
    model = cls("MlpPolicy", venv, seed=seed, device="cpu", verbose=verbose, **algo_kwargs)
    t0 = time.perf_counter()
    cb = _callbacks(out, eval_env, eval_every, eval_episodes, 10_000 + seed, checkpoint_every,
                    steps, progress, t0)
    model.learn(total_timesteps=steps, callback=cb)
    wall = time.perf_counter() - t0
    model.save(out / "model.zip")
    config.update({"wall_time_s": round(wall, 1), "timesteps_done": int(model.num_timesteps)})
    write_config(out, config)
    venv.close()
    eval_env.close()
    last = cb.rows[-1]
    return {"out": str(out), "model": str(out / "model.zip"), "wall_time_s": wall,
            "timesteps": int(model.num_timesteps), "last_eval": last, "rows": cb.rows}
