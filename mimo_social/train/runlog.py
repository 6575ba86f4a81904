"""The run log of the multi-agent modes: episodes, evaluations, best model, learning curve.

:class:`RunLog` writes ``episodes.csv`` (one row per agent and episode), ``progress.csv`` and
``learning_curve.png`` and saves the best model; :class:`Schedule` says when an evaluation or a
checkpoint is due.
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

__all__ = ["RunLog", "Schedule"]


class RunLog:
    """What every mode writes while it trains (one instance per run, used from one thread at a
    time)."""

    def __init__(self, out: Path, agents, evaluate: Callable[[], dict],
                 save_best: Callable[[], None], t_start: float, bar=None):
        self.out, self.agents = out, list(agents)
        self._evaluate, self._save_best = evaluate, save_best
        self.t_start, self.bar = t_start, bar
        self.rows: list[dict] = []
        self.best = -math.inf
        self.train_returns: list[float] = []
        self.file = open(out / "episodes.csv", "w", newline="")
        self.episodes = csv.writer(self.file)
        self.episodes.writerow(["timesteps", "agent", "return", "length", "success"])

    def episode(self, n: int, agent: str, ret: float, length: int, success) -> None:
        self.train_returns.append(float(ret))
        self.episodes.writerow([n, agent, f"{ret:.6g}", int(length),
                                "" if success is None else int(bool(success))])

    def evaluate(self, n: int) -> dict:
        res = self._evaluate()
        row = {"timesteps": n, "wall_time_s": round(time.perf_counter() - self.t_start, 2),
               "eval_return_mean": res["return_mean"], "eval_return_std": res["return_std"],
               "eval_length_mean": res["length_mean"], "eval_success_rate": res["success_rate"],
               "train_return_mean": (float(np.mean(self.train_returns)) if self.train_returns
                                     else float("nan")),
               "train_episodes": len(self.train_returns), **agent_columns(res)}
        self.train_returns = []
        self.rows.append(row)
        if res["return_mean"] > self.best:
            self.best = res["return_mean"]
            self._save_best()
        write_progress(self.out / "progress.csv", self.rows)
        self.file.flush()
        plot_learning_curve(self.out)
        if self.bar is not None:
            post = {"eval_return": f"{res['return_mean']:.3g}"}
            if not math.isnan(res["success_rate"]):
                post["success"] = f"{res['success_rate']:.0%}"
            self.bar.set_postfix(post)
        return row

    def close(self) -> None:
        self.file.close()
        if self.bar is not None:
            self.bar.close()


class Schedule:
    """Evaluation and checkpoint step counters. Nothing is due once ``n`` reaches ``total``: the
    last evaluation and checkpoint are made after the models' last update (:meth:`final`)."""

    def __init__(self, eval_every: int, checkpoint_every: int, total: int):
        self.eval_every, self.checkpoint_every, self.total = eval_every, checkpoint_every, total
        self.next_eval = eval_every
        self.next_ckpt = checkpoint_every if checkpoint_every > 0 else math.inf

    def final_checkpoint_due(self, n: int) -> bool:
        return self.next_ckpt <= n

    def checkpoint_due(self, n: int) -> bool:
        if n < self.next_ckpt or n >= self.total:
            return False
        while self.next_ckpt <= n:
            self.next_ckpt += self.checkpoint_every
        return True

    def eval_due(self, n: int) -> bool:
        if n < self.next_eval or n >= self.total:
            return False
        while self.next_eval <= n:
            self.next_eval += self.eval_every
        return True

