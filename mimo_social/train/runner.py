"""Train, evaluate and compare policies: ``mimo-social train | eval | compare``.

One-agent tasks (:data:`TASKS`: reach, standup, selfbody, catch) and the multi-agent social tasks
(:data:`MULTI_TASKS`: high_five, mirror, joint_attention, social_touch, handover; each a
PettingZoo module ``mimo_social.envs.<task>_v0``). For a multi-agent task ``--mode`` chooses how
it learns (details and limits in docs/training_multi.md and :mod:`mimo_social.train.multi`):

* ``shared`` (default): parameter sharing, one policy for every agent through SuperSuit
  (:func:`~mimo_social.train.vector.sb3_vec_env`; one VecEnv slot per agent, ``--n-envs`` worlds,
  ``--n-cpus`` worker processes); every agent needs the same observation and action space;
* ``independent``: one policy per agent, all acting in one world at the same time (each model's
  ``learn()`` in its own thread on a lockstep Gymnasium view of the shared ParallelEnv);
* ``scripted``: one learner, its partner driven by the task's default scripted partner
  (``SingleAgentEnv(module.scripted_env())``, then the one-agent path).

``--steps`` counts environment steps in every mode. Multi-agent runs add per-agent columns to
``progress.csv`` (``eval_return_mean_<agent>``, ``eval_success_rate_<agent>``; the summary
columns average the agents), an ``agent`` column to ``episodes.csv``, one line per agent to
``learning_curve.png``; ``independent`` saves ``model_<agent>.zip`` (and ``best_model_<agent>``,
``checkpoints/model_<agent>_<steps>_steps.zip``). ``eval`` reloads every kind and prints
per-agent numbers; ``compare`` plots the across-agent mean. The last evaluation and checkpoint of
a run are made after the last update (of the model that is saved as ``model.zip``).

``mimo-social train --task reach --algo ppo --steps 200000 --seed 0 --out runs/reach_ppo``
    Stable-Baselines3 with its default hyperparameters (as in the paper: PPO with two hidden layers
    of 64, SAC with two of 256), on the task's Gymnasium env with flattened observations
    (:func:`~mimo_social.core.wrappers.make_sb3_single`), one env, CPU, ``torch`` on one thread.
    One change to SAC's defaults: the replay buffer holds ``min(1e6, steps)`` transitions (it
    could never hold more; SB3 would allocate room for a million of these large observations).
    ``--algo-kwargs '{"n_steps": 512}'`` and ``--env-kwargs '{"max_steps": 200}'`` override.
    It writes to ``--out``:

    * ``config.json``: task, algorithm, seed, steps and the keyword arguments (what ``eval`` reads);
    * ``model.zip`` (the final policy) and ``best_model.zip`` (best mean evaluation return);
    * ``checkpoints/model_<steps>_steps.zip`` every ``--checkpoint-every`` steps;
    * ``progress.csv``: one row per evaluation (every ``--eval-every`` steps and at the end):
      ``timesteps, wall_time_s, eval_return_mean, eval_return_std, eval_length_mean,
      eval_success_rate, train_return_mean, train_episodes`` (the evaluation runs
      ``--eval-episodes`` deterministic episodes on a separate env, the same seeded episodes
      every time; the train columns summarise the training episodes since the last row);
    * ``episodes.csv``: every training episode (``timesteps, return, length, success``; multi-agent
      runs: ``timesteps, agent, return, length, success``, one row per agent and episode);
    * ``learning_curve.png``: evaluation return (mean and std) and training returns against steps,
      and the success rate where the task reports one.

``mimo-social eval DIR --episodes 10 [--record run.rrd] [--video run.mp4 | --frames DIR]``
    Reloads ``DIR/model.zip`` (``--model best`` or a path for another), runs the episodes with the
    deterministic policy (``--stochastic`` samples), prints the mean return, success rate and
    length and writes ``DIR/eval_results.json``. ``--record`` writes a Rerun recording of all
    episodes; ``--video`` an MP4 of ``env.render()`` frames, which needs ``imageio`` with its
    ffmpeg plugin or an ``ffmpeg`` program (the command says so and stops if neither is there:
    ``--frames DIR`` writes the frames as PNG files instead).

``mimo-social compare --task standup --algos ppo,sac --seeds 3 --steps 50000 --out runs/cmp``
    Trains every algorithm with seeds 0..n-1 (``--jobs`` processes at a time) into
    ``OUT/<algo>_seed<k>`` and plots the evaluation returns of all runs together (the paper's
    Fig. 8: each algorithm's mean over seeds with the min-max band, PPO red, SAC blue) to
    ``OUT/compare.png`` with the numbers in ``OUT/compare.csv``. ``--plot-only`` re-plots
    existing runs.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..envs.catalog import CATALOG

__all__ = ["TASKS", "MULTI_TASKS", "ALL_TASKS", "ALGOS", "make_env", "train", "evaluate",
           "compare", "plot_compare", "add_parser", "read_progress", "write_progress",
           "progress_agents", "VideoUnavailable", "TrainInputError"]

# one-agent tasks: task -> Gymnasium id; multi-agent (social) tasks: task -> PettingZoo module
# with parallel_env and scripted_env (both read from the catalogue)
TASKS = {e.name: e.gym_id for e in CATALOG if e.kind == "one-agent"}
MULTI_TASKS = {e.name: e.module.__name__ for e in CATALOG if e.social}
ALL_TASKS = (*TASKS, *MULTI_TASKS)
ALGOS = ("ppo", "sac")
COLORS = {"ppo": "tab:red", "sac": "tab:blue"}
PROGRESS_FIELDS = ("timesteps", "wall_time_s", "eval_return_mean", "eval_return_std",
                   "eval_length_mean", "eval_success_rate", "train_return_mean", "train_episodes")


class VideoUnavailable(RuntimeError):
    """No MP4 encoder on this machine."""


class TrainInputError(ValueError):
    """A task, mode or option that ``train`` / ``eval`` / ``compare`` cannot use (says why)."""


def _json_default(value):
    """config.json: a class (e.g. a features extractor in policy_kwargs) by its dotted name."""
    if isinstance(value, type):
        return f"{value.__module__}.{value.__qualname__}"
    raise TypeError(f"not JSON serialisable: {value!r}")


def _check_task(task: str) -> str:
    if task in MULTI_TASKS:
        return MULTI_TASKS[task]
    if task not in TASKS:
        raise TrainInputError(f"task {task!r} not allowed; allowed: {', '.join(ALL_TASKS)} "
                         f"(one-agent: {', '.join(TASKS)}; multi-agent: {', '.join(MULTI_TASKS)})")
    return TASKS[task]


def _check_algo(algo: str) -> str:
    if algo not in ALGOS:
        raise TrainInputError(f"algo {algo!r} not allowed; allowed: {', '.join(ALGOS)}")
    return algo


def make_env(task: str, render_mode: str | None = None, **env_kwargs):
    """The task's Gymnasium env with Box observations and actions (for SB3); for a multi-agent
    task the one-learner env of its scripted mode (the partner scripted)."""
    from ..core.wrappers import make_sb3_single
    if task in MULTI_TASKS:
        from .multi import _scripted_gym, _with_render
        return _scripted_gym(task, **_with_render(env_kwargs, render_mode))
    kwargs = dict(env_kwargs)
    if render_mode is not None:
        kwargs["render_mode"] = render_mode
    return make_sb3_single(_check_task(task), **kwargs)


def _algo_class(algo: str):
    from stable_baselines3 import PPO, SAC
    return {"ppo": PPO, "sac": SAC}[_check_algo(algo)]


def _run_episode(model, env, seed: int | None, deterministic: bool = True, on_step=None):
    """One episode; returns (return, length, success or None)."""
    obs, info = env.reset(seed=seed)
    if on_step is not None:
        on_step(None, None, info, reset=True)
    total, length, success = 0.0, 0, None
    while True:
        action, _ = model.predict(obs, deterministic=deterministic)
        obs, reward, terminated, truncated, info = env.step(action)
        total += float(reward)
        length += 1
        if on_step is not None:
            on_step(action, reward, info, reset=False)
        if terminated or truncated:
            if "is_success" in info:
                success = bool(info["is_success"])
            return total, length, success


def _evaluate_policy(model, env, episodes: int, seed: int, deterministic: bool = True,
                     on_step=None) -> dict:
    returns, lengths, successes = [], [], []
    for k in range(episodes):
        r, n, s = _run_episode(model, env, seed + k, deterministic, on_step)
        returns.append(r)
        lengths.append(n)
        if s is not None:
            successes.append(s)
    return {"returns": returns, "lengths": lengths,
            "return_mean": float(np.mean(returns)), "return_std": float(np.std(returns)),
            "length_mean": float(np.mean(lengths)),
            "success_rate": float(np.mean(successes)) if successes else float("nan")}


# -- training ------------------------------------------------------------------------------------
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
            res = _evaluate_policy(self.model, eval_env, eval_episodes, eval_seed)
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


def write_progress(path: Path, rows) -> None:
    """``progress.csv``: :data:`PROGRESS_FIELDS` then any further columns of the rows (the
    per-agent ``eval_return_mean_<agent>`` / ``eval_success_rate_<agent>`` of multi-agent runs)."""
    fields = list(PROGRESS_FIELDS)
    for row in rows[:1]:
        fields += [k for k in row if k not in fields]
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for row in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})


def read_progress(path: Path) -> dict[str, np.ndarray]:
    """Every column of a ``progress.csv`` as a float array (empty cells: NaN)."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        rows = list(reader)
        fields = list(reader.fieldnames or PROGRESS_FIELDS)
    return {k: np.array([float(r[k]) if r.get(k) not in ("", None) else np.nan for r in rows])
            for k in fields}


def progress_agents(p: Mapping[str, np.ndarray]) -> list[str]:
    """The agents with per-agent columns in a progress table (none for one-agent runs)."""
    prefix = "eval_return_mean_"
    return [k[len(prefix):] for k in p if k.startswith(prefix)]


def train(task: str, algo: str, steps: int, seed: int, out: str | Path, *,
          eval_every: int | None = None, eval_episodes: int = 5,
          checkpoint_every: int | None = None, progress: bool = True,
          env_kwargs: Mapping[str, Any] | None = None,
          algo_kwargs: Mapping[str, Any] | None = None, verbose: int = 0,
          mode: str | None = None, n_envs: int = 1, n_cpus: int = 0,
          normalize_obs: bool = False) -> dict:
    """Train one policy (or one per agent); returns a summary (paths, last evaluation, wall
    time). See the module docstring for what it writes. ``mode`` (``shared``, ``independent``,
    ``scripted``; default ``shared``), ``n_envs`` and ``n_cpus`` (shared mode: worlds and worker
    processes) are for the multi-agent tasks (:mod:`mimo_social.train.multi`)."""
    from .multi import check_mode, task_module
    mode = check_mode(task, mode)
    if mode is not None:
        task_module(task)  # a clear error before anything is written
    if mode is None and (n_envs != 1 or n_cpus != 0):
        raise TrainInputError(f"n_envs={n_envs}, n_cpus={n_cpus}: several worlds are for the "
                         f"multi-agent tasks in --mode shared; {task!r} trains on one env")
    import torch
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv

    _check_task(task)
    cls = _algo_class(algo)
    steps, seed = int(steps), int(seed)
    if steps < 1:
        raise TrainInputError(f"steps={steps}; allowed: a positive integer")
    eval_every = int(eval_every) if eval_every else max(steps // 20, 1)
    checkpoint_every = int(checkpoint_every) if checkpoint_every is not None else max(steps // 5, 1)
    torch.set_num_threads(1)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    env_kwargs = dict(env_kwargs or {})
    kwargs = dict(algo_kwargs or {})
    if algo == "sac":
        kwargs.setdefault("buffer_size", min(1_000_000, steps))
    if normalize_obs:  # running input statistics inside the policy (saved in model.zip)
        from .obs_norm import RunningNorm
        kwargs["policy_kwargs"] = {**kwargs.get("policy_kwargs", {}),
                                   "features_extractor_class": RunningNorm}
    config = {"task": task, "env_id": _check_task(task), "algo": algo, "steps": steps,
              "seed": seed, "normalize_obs": bool(normalize_obs),
              "env_kwargs": env_kwargs, "algo_kwargs": kwargs, "eval_every": eval_every,
              "eval_episodes": eval_episodes, "checkpoint_every": checkpoint_every}
    if mode is not None:
        from .multi import train_multi
        config["algo_kwargs_given"] = sorted(algo_kwargs or {})
        return train_multi(task, algo, steps, seed, out, mode=mode, eval_every=eval_every,
                           eval_episodes=eval_episodes, checkpoint_every=checkpoint_every,
                           progress=progress, env_kwargs=env_kwargs, algo_kwargs=kwargs,
                           n_envs=int(n_envs), n_cpus=int(n_cpus), verbose=verbose,
                           config=config)
    (out / "config.json").write_text(json.dumps(config, indent=2, default=_json_default))

    venv = DummyVecEnv([lambda: Monitor(make_env(task, **env_kwargs))])
    eval_env = make_env(task, **env_kwargs)
    model = cls("MlpPolicy", venv, seed=seed, device="cpu", verbose=verbose, **kwargs)
    t0 = time.perf_counter()
    cb = _callbacks(out, eval_env, eval_every, eval_episodes, 10_000 + seed, checkpoint_every,
                    steps, progress, t0)
    model.learn(total_timesteps=steps, callback=cb)
    wall = time.perf_counter() - t0
    model.save(out / "model.zip")
    config.update({"wall_time_s": round(wall, 1), "timesteps_done": int(model.num_timesteps)})
    (out / "config.json").write_text(json.dumps(config, indent=2, default=_json_default))
    venv.close()
    eval_env.close()
    last = cb.rows[-1]
    return {"out": str(out), "model": str(out / "model.zip"), "wall_time_s": wall,
            "timesteps": int(model.num_timesteps), "last_eval": last, "rows": cb.rows}


def plot_learning_curve(run: str | Path, path: str | Path | None = None) -> Path:
    """``learning_curve.png`` of one run (from its ``progress.csv`` and ``episodes.csv``)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    run = Path(run)
    path = Path(path) if path else run / "learning_curve.png"
    p = read_progress(run / "progress.csv")
    config = json.loads((run / "config.json").read_text()) if (run / "config.json").exists() else {}
    agents = progress_agents(p)
    if agents:
        return _plot_agents(run, path, p, config, agents)
    has_success = np.isfinite(p["eval_success_rate"]).any()
    fig, axes = plt.subplots(1, 2 if has_success else 1, figsize=(11 if has_success else 6.5, 4),
                             squeeze=False)
    ax = axes[0, 0]
    ep_path = run / "episodes.csv"
    if ep_path.exists():
        with open(ep_path, newline="") as f:
            eps = [(float(r["timesteps"]), float(r["return"])) for r in csv.DictReader(f)]
        if eps:
            x, y = np.array(eps).T
            ax.plot(x, y, ".", ms=2, color="0.6", alpha=0.5, label="training episodes")
    t, m, s = p["timesteps"], p["eval_return_mean"], p["eval_return_std"]
    color = COLORS.get(config.get("algo"), "tab:green")
    ax.plot(t, m, "-o", ms=3, color=color, label="evaluation (mean)")
    ax.fill_between(t, m - s, m + s, color=color, alpha=0.2, lw=0)
    ax.set_xlabel("environment steps")
    ax.set_ylabel("episode return")
    ax.set_title(f"{config.get('task', '?')} - {config.get('algo', '?').upper()} "
                 f"(seed {config.get('seed', '?')})")
    ax.legend(loc="best", fontsize=8)
    ax.grid(alpha=0.3)
    if has_success:
        ax = axes[0, 1]
        ax.plot(t, 100 * p["eval_success_rate"], "-o", ms=3, color=color)
        ax.set_ylim(-5, 105)
        ax.set_xlabel("environment steps")
        ax.set_ylabel("evaluation success rate (%)")
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _plot_agents(run: Path, path: Path, p, config: dict, agents: list[str]) -> Path:
    """Learning curve of a multi-agent run: one line per agent (return; success rate)."""
    import matplotlib.pyplot as plt

    success_keys = [f"eval_success_rate_{a}" for a in agents]
    has_success = any(np.isfinite(p[k]).any() for k in success_keys if k in p)
    fig, axes = plt.subplots(1, 2 if has_success else 1, figsize=(11 if has_success else 6.5, 4),
                             squeeze=False)
    colors = {a: f"C{i}" for i, a in enumerate(agents)}
    # line style and marker per agent too: cooperative tasks give the agents the same numbers
    styles = {a: (("-", "o"), ("--", "s"), (":", "^"), ("-.", "D"))[i % 4]
              for i, a in enumerate(agents)}
    ax = axes[0, 0]
    ep_path = run / "episodes.csv"
    if ep_path.exists():
        with open(ep_path, newline="") as f:
            eps = list(csv.DictReader(f))
        for a in agents:
            xy = [(float(r["timesteps"]), float(r["return"])) for r in eps if r.get("agent") == a]
            if xy:
                x, y = np.array(xy).T
                ax.plot(x, y, ".", ms=2, color=colors[a], alpha=0.25)
    t = p["timesteps"]
    for a in agents:
        ls, mk = styles[a]
        ax.plot(t, p[f"eval_return_mean_{a}"], ls=ls, marker=mk, ms=4, color=colors[a],
                label=f"{a} (evaluation)")
    ax.set_xlabel("environment steps")
    ax.set_ylabel("episode return")
    ax.set_title(f"{config.get('task', '?')} - {config.get('algo', '?').upper()} "
                 f"{config.get('mode', '')} (seed {config.get('seed', '?')})")
    ax.legend(loc="best", fontsize=8)
    ax.grid(alpha=0.3)
    if has_success:
        ax = axes[0, 1]
        for a in agents:
            ls, mk = styles[a]
            ax.plot(t, 100 * p[f"eval_success_rate_{a}"], ls=ls, marker=mk, ms=4, color=colors[a],
                    label=a)
        ax.set_ylim(-5, 105)
        ax.set_xlabel("environment steps")
        ax.set_ylabel("evaluation success rate (%)")
        ax.legend(loc="best", fontsize=8)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


# -- evaluation ----------------------------------------------------------------------------------
def _mp4_writer(path: Path, fps: int):
    """A function that takes frames and a close function, or VideoUnavailable."""
    try:
        import imageio.v2 as imageio  # needs its ffmpeg plugin (imageio-ffmpeg) for mp4
        writer = imageio.get_writer(str(path), fps=fps)
        return writer.append_data, writer.close
    except Exception as e:  # ImportError, or no ffmpeg backend
        reason = f"imageio: {e}"
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        raise VideoUnavailable(
            f"cannot write {path}: no MP4 encoder on this machine ({reason}; and no ffmpeg "
            "program on PATH). Install one (pip install imageio imageio-ffmpeg, or apt-get "
            "install ffmpeg), or use --frames DIR to write the frames as PNG files.")
    state = {}

    def write(frame):
        if "proc" not in state:
            h, w = frame.shape[:2]
            state["proc"] = subprocess.Popen(
                [ffmpeg, "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
                 "-s", f"{w}x{h}", "-r", str(fps), "-i", "-", "-pix_fmt", "yuv420p",
                 "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", str(path)],
                stdin=subprocess.PIPE)
        state["proc"].stdin.write(np.ascontiguousarray(frame, dtype=np.uint8).tobytes())

    def close():
        if "proc" in state:
            state["proc"].stdin.close()
            state["proc"].wait()
    return write, close


class EvalOutputs:
    """What an evaluation writes besides its numbers: a Rerun recording of the inner
    ParallelEnv ``penv``, an MP4 and/or PNG frames of ``env.render()`` every ``frame_every``
    steps. ``on_reset()`` / ``on_step(actions, rewards)`` after each reset / step; ``close()``."""

    def __init__(self, env, penv, record=None, video=None, frames=None, frame_every: int = 1):
        self.env, self.frames, self.frame_every = env, frames, int(frame_every)
        self.want_frames = video is not None or frames is not None
        self.write = self._close_video = None
        if video is not None:
            self.write, self._close_video = _mp4_writer(
                Path(video), int(penv.metadata.get("render_fps", 100)))
        if frames is not None:
            Path(frames).mkdir(parents=True, exist_ok=True)
        self.recorder = None
        if record is not None:
            from ..recording.recorder import Recorder
            self.recorder = Recorder(penv, record)
        self.episode, self.step = -1, 0

    def on_reset(self) -> None:
        self.episode += 1
        self.step = 0
        if self.recorder is not None:
            self.recorder.log_reset()
        self._frame()

    def on_step(self, actions: Mapping[str, Any], rewards: Mapping[str, float]) -> None:
        self.step += 1
        if self.recorder is not None:
            self.recorder.log_step(actions, rewards)
        self._frame()

    def _frame(self) -> None:
        if not self.want_frames or self.step % self.frame_every:
            return
        frame = self.env.render()
        if self.write is not None:
            self.write(frame)
        if self.frames is not None:
            import matplotlib.image as mpimg
            mpimg.imsave(Path(self.frames) / f"ep{self.episode:03d}_{self.step:05d}.png", frame)

    def close(self) -> None:
        if self.recorder is not None:
            self.recorder.close()
        if self._close_video is not None:
            self._close_video()


def evaluate(run: str | Path, episodes: int = 10, *, model: str = "final", seed: int = 0,
             deterministic: bool = True, record: str | Path | None = None,
             video: str | Path | None = None, frames: str | Path | None = None,
             frame_every: int = 1, env_kwargs: Mapping[str, Any] | None = None) -> dict:
    """Reload a trained policy from a ``train`` directory and run ``episodes`` episodes."""
    import torch
    torch.set_num_threads(1)
    run = Path(run)
    if not (run / "config.json").exists():
        raise FileNotFoundError(f"{run}/config.json not found: give a directory written by "
                                "'mimo-social train'")
    config = json.loads((run / "config.json").read_text())
    if config.get("mode") is not None:
        from .multi import evaluate_multi
        return evaluate_multi(run, config, episodes, model=model, seed=seed,
                              deterministic=deterministic, record=record, video=video,
                              frames=frames, frame_every=frame_every, env_kwargs=env_kwargs)
    path = {"final": run / "model.zip", "best": run / "best_model.zip"}.get(model, Path(model))
    if not path.exists():
        raise FileNotFoundError(f"model {path} not found (--model final, best or a .zip path)")
    policy = _algo_class(config["algo"]).load(str(path), device="cpu")
    kw = dict(config.get("env_kwargs", {}))
    kw.update(env_kwargs or {})
    want_frames = video is not None or frames is not None
    env = make_env(config["task"], render_mode="rgb_array" if want_frames else None, **kw)
    penv = env.unwrapped.parallel
    outputs = EvalOutputs(env, penv, record, video, frames, frame_every)
    agent = penv.possible_agents[0]

    def on_step(action, reward, info, reset):
        if reset:
            outputs.on_reset()
        else:
            outputs.on_step({agent: np.asarray(action)}, {agent: float(reward)})

    t0 = time.perf_counter()
    try:
        res = _evaluate_policy(policy, env, episodes, seed, deterministic, on_step)
    finally:
        outputs.close()
        env.close()
    res.update({"task": config["task"], "algo": config["algo"], "model": str(path),
                "episodes": episodes, "deterministic": deterministic, "seed": seed,
                "wall_time_s": round(time.perf_counter() - t0, 2)})
    if record is not None:
        res["record"] = str(record)
    if video is not None:
        res["video"] = str(video)
    if frames is not None:
        res["frames"] = str(frames)
    (run / "eval_results.json").write_text(json.dumps(res, indent=2, default=float))
    return res


# -- several seeds -------------------------------------------------------------------------------
def _train_quiet(kwargs):
    import warnings
    warnings.filterwarnings("ignore")
    t0 = time.perf_counter()
    train(**kwargs)
    return kwargs["out"], time.perf_counter() - t0


def compare(task: str, algos=ALGOS, seeds: int = 3, steps: int = 50_000,
            out: str | Path = "runs/compare", *, jobs: int = 1, plot_only: bool = False,
            mode: str | None = None, **train_kwargs) -> Path:
    """Train every algorithm with seeds 0..seeds-1 and plot them together; returns the PNG.
    Multi-agent tasks train in ``mode``; the plot shows the evaluation return and success rate
    averaged across agents, ``compare.csv`` has the per-agent columns too."""
    from .multi import check_mode, task_module
    out = Path(out)
    algos = [_check_algo(a) for a in algos]
    _check_task(task)
    mode = check_mode(task, mode)
    if mode is not None:
        task_module(task)
        train_kwargs["mode"] = mode
    runs = [dict(task=task, algo=a, steps=steps, seed=s, out=str(out / f"{a}_seed{s}"),
                 **train_kwargs) for a in algos for s in range(int(seeds))]
    if not plot_only:
        out.mkdir(parents=True, exist_ok=True)
        if jobs <= 1:
            for kw in runs:
                train(**kw)
        else:
            import multiprocessing as mp
            from concurrent.futures import ProcessPoolExecutor
            for kw in runs:
                kw["progress"] = False
            with ProcessPoolExecutor(max_workers=jobs, mp_context=mp.get_context("spawn")) as ex:
                for path, secs in ex.map(_train_quiet, runs):
                    print(f"done {path} in {secs:.0f} s", flush=True)
    return plot_compare(out, task)


def plot_compare(out: str | Path, task: str | None = None) -> Path:
    """``compare.png`` / ``compare.csv`` from every ``<algo>_seed<k>`` run below ``out``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    by_algo: dict[str, list] = {}
    for run in sorted(out.glob("*_seed*")):
        if not (run / "progress.csv").exists():
            continue
        config = json.loads((run / "config.json").read_text())
        by_algo.setdefault(config["algo"], []).append((config, read_progress(run / "progress.csv")))
    if not by_algo:
        raise FileNotFoundError(f"no runs with a progress.csv below {out}")
    has_success = any(np.isfinite(p["eval_success_rate"]).any()
                      for runs in by_algo.values() for _, p in runs)
    fig, axes = plt.subplots(1, 2 if has_success else 1, figsize=(11 if has_success else 6.5, 4),
                             squeeze=False)
    rows = []
    fields = ["algo", "seed", *PROGRESS_FIELDS]
    for runs in by_algo.values():
        for _, p in runs:
            fields += [k for k in p if k not in fields]
    for algo, runs in sorted(by_algo.items()):
        color = COLORS.get(algo, None)
        end = min(p["timesteps"][-1] for _, p in runs)
        grid = np.unique(np.concatenate([p["timesteps"][p["timesteps"] <= end] for _, p in runs]))
        for key, ax, scale in (("eval_return_mean", axes[0, 0], 1.0),
                               ("eval_success_rate", axes[0, 1] if has_success else None, 100.0)):
            if ax is None:
                continue
            ys = np.array([np.interp(grid, p["timesteps"], p[key]) for _, p in runs]) * scale
            for y in ys:
                ax.plot(grid, y, color=color, alpha=0.25, lw=0.8)
            ax.plot(grid, np.nanmean(ys, axis=0), color=color, lw=2,
                    label=f"{algo.upper()} ({len(runs)} seeds)")
            ax.fill_between(grid, np.nanmin(ys, axis=0), np.nanmax(ys, axis=0), color=color,
                            alpha=0.15, lw=0)
        for config, p in runs:
            for i in range(len(p["timesteps"])):
                rows.append({"algo": algo, "seed": config["seed"],
                             **{k: p[k][i] for k in p}})
    first = next(iter(by_algo.values()))[0][0]
    task = task or first["task"]
    if first.get("mode"):
        task = f"{task} ({first['mode']}, mean over agents)"
    fig.suptitle(task)
    axes[0, 0].set_title("evaluation return (mean over seeds, min-max band)", fontsize=10)
    axes[0, 0].set_xlabel("environment steps")
    axes[0, 0].set_ylabel("episode return")
    axes[0, 0].legend(loc="best", fontsize=8)
    axes[0, 0].grid(alpha=0.3)
    if has_success:
        axes[0, 1].set_title("evaluation success rate", fontsize=10)
        axes[0, 1].set_xlabel("environment steps")
        axes[0, 1].set_ylabel("success (%)")
        axes[0, 1].set_ylim(-5, 105)
        axes[0, 1].grid(alpha=0.3)
    fig.tight_layout()
    png = out / "compare.png"
    fig.savefig(png, dpi=110)
    plt.close(fig)
    with open(out / "compare.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
    return png


# -- command line --------------------------------------------------------------------------------
def _json_arg(text: str) -> dict:
    try:
        value = json.loads(text)
    except json.JSONDecodeError as e:
        raise argparse.ArgumentTypeError(f"not JSON: {e}") from None
    if not isinstance(value, dict):
        raise argparse.ArgumentTypeError("expected a JSON object, e.g. '{\"max_steps\": 200}'")
    return value


def _common(p):
    p.add_argument("--task", required=True, choices=sorted(ALL_TASKS),
                   help=f"one-agent: {', '.join(TASKS)}; multi-agent: {', '.join(MULTI_TASKS)}")
    p.add_argument("--mode", default=None, choices=("shared", "independent", "scripted"),
                   help="multi-agent tasks: shared (one policy for all agents, the default), "
                   "independent (one policy per agent) or scripted (one learner, the partner "
                   "scripted)")
    p.add_argument("--steps", type=int, required=True, help="environment steps to train for")
    p.add_argument("--eval-every", type=int, default=None,
                   help="steps between evaluations (default: steps / 20)")
    p.add_argument("--eval-episodes", type=int, default=5, help="episodes per evaluation")
    p.add_argument("--checkpoint-every", type=int, default=None,
                   help="steps between checkpoints (default: steps / 5; 0: none)")
    p.add_argument("--env-kwargs", type=_json_arg, default={},
                   help="JSON keyword arguments for the env, e.g. '{\"max_steps\": 200}'")
    p.add_argument("--algo-kwargs", type=_json_arg, default={},
                   help="JSON keyword arguments for the SB3 algorithm (default: SB3's defaults)")
    p.add_argument("--normalize-obs", action="store_true",
                   help="normalise every observation input by running statistics inside the "
                   "policy (mimo_social.train.obs_norm.RunningNorm; saved in the model): for eye images")


def _train_main(args) -> int:
    try:
        res = train(args.task, args.algo, args.steps, args.seed, args.out,
                    eval_every=args.eval_every, eval_episodes=args.eval_episodes,
                    checkpoint_every=args.checkpoint_every, progress=not args.no_progress,
                    env_kwargs=args.env_kwargs, algo_kwargs=args.algo_kwargs, mode=args.mode,
                    n_envs=args.n_envs, n_cpus=args.n_cpus, normalize_obs=args.normalize_obs)
    except TrainInputError as e:
        print(f"mimo-social train: {e}", file=sys.stderr)
        return 2
    last = res["last_eval"]
    success = last["eval_success_rate"]
    mode = f" ({res['mode']})" if res.get("mode") else ""
    print(f"trained {args.algo.upper()} on {args.task}{mode} for {res['timesteps']} steps in "
          f"{res['wall_time_s']:.0f} s; last evaluation: return {last['eval_return_mean']:.3g}"
          + ("" if math.isnan(success) else f", success {success:.0%}"))
    for a in res.get("agents", ()):
        s = last[f"eval_success_rate_{a}"]
        print(f"  {a}: return {last[f'eval_return_mean_{a}']:.3g}"
              + ("" if math.isnan(s) else f", success {s:.0%}"))
    models = sorted({Path(m).name for m in res.get("models", {"": res["model"]}).values()})
    print(f"wrote {res['out']}/" + ("{" + ", ".join(models) + "}" if len(models) > 1 else models[0])
          + ", progress.csv, learning_curve.png")
    return 0


def _eval_main(args) -> int:
    try:
        res = evaluate(args.dir, args.episodes, model=args.model, seed=args.seed,
                       deterministic=not args.stochastic, record=args.record, video=args.video,
                       frames=args.frames, frame_every=args.frame_every,
                       env_kwargs=args.env_kwargs)
    except (VideoUnavailable, FileNotFoundError, TrainInputError) as e:
        print(f"mimo-social eval: {e}", file=sys.stderr)
        return 2
    success = res["success_rate"]
    mode = f" {res['mode']}" if res.get("mode") else ""
    print(f"{res['task']} {res['algo'].upper()}{mode} {Path(res['model']).name}: "
          f"{res['episodes']} episodes, return {res['return_mean']:.4g} +- "
          f"{res['return_std']:.3g}, length {res['length_mean']:.0f}"
          + ("" if math.isnan(success) else f", success {success:.0%}"))
    for a, r in res.get("agents", {}).items():
        s = r["success_rate"]
        print(f"  {a} ({Path(res['models'][a]).name}): return {r['return_mean']:.4g} +- "
              f"{r['return_std']:.3g}" + ("" if math.isnan(s) else f", success {s:.0%}"))
    for key in ("record", "video", "frames"):
        if key in res:
            print(f"wrote {res[key]}")
    return 0


def _compare_main(args) -> int:
    algos = [a.strip() for a in args.algos.split(",") if a.strip()]
    try:
        png = _compare_run(args, algos)
    except TrainInputError as e:
        print(f"mimo-social compare: {e}", file=sys.stderr)
        return 2
    print(f"wrote {png} and {png.with_suffix('.csv')}")
    return 0


def _compare_run(args, algos):
    return compare(args.task, algos, args.seeds, args.steps, args.out, jobs=args.jobs,
                   plot_only=args.plot_only, mode=args.mode, eval_every=args.eval_every,
                   eval_episodes=args.eval_episodes, checkpoint_every=args.checkpoint_every,
                   env_kwargs=args.env_kwargs, algo_kwargs=args.algo_kwargs,
                   normalize_obs=args.normalize_obs)


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("train", help="train PPO or SAC on a one-agent or social task",
                              description="Train a Stable-Baselines3 policy (default "
                              "hyperparameters) with periodic evaluation, checkpoints and a "
                              "learning curve (CSV and PNG).")
    _common(p)
    p.add_argument("--algo", required=True, choices=ALGOS)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--n-envs", type=int, default=1, help="--mode shared: worlds stepped "
                   "together (one VecEnv slot per agent of each)")
    p.add_argument("--n-cpus", type=int, default=0, help="--mode shared: worker processes for "
                   "the worlds (0: all in this process)")
    p.set_defaults(func=_train_main)

    p = subparsers.add_parser("eval", help="run a trained policy (optionally record or film it)",
                              description="Reload the policy of a 'train' directory and run "
                              "episodes with it.")
    p.add_argument("dir", help="a directory written by 'mimo-social train'")
    p.add_argument("--episodes", type=int, default=10)
    p.add_argument("--model", default="final", help="final (model.zip), best (best_model.zip) "
                   "or a path to a .zip")
    p.add_argument("--seed", type=int, default=0, help="seed of the first episode")
    p.add_argument("--stochastic", action="store_true", help="sample actions from the policy")
    p.add_argument("--record", default=None, help="write a Rerun recording (.rrd)")
    p.add_argument("--video", default=None, help="write an MP4 video (needs imageio+ffmpeg "
                   "or an ffmpeg program)")
    p.add_argument("--frames", default=None, help="write every frame as a PNG file into this "
                   "directory")
    p.add_argument("--frame-every", type=int, default=1, help="keep every k-th frame")
    p.add_argument("--env-kwargs", type=_json_arg, default={},
                   help="JSON keyword arguments for the env, over those of the training run")
    p.set_defaults(func=_eval_main)

    p = subparsers.add_parser("compare", help="train several algorithms and seeds, plot them "
                              "together", description="Train each algorithm with several seeds "
                              "and plot the learning curves together (the paper's Fig. 8).")
    _common(p)
    p.add_argument("--algos", default="ppo,sac", help="comma-separated: ppo,sac")
    p.add_argument("--seeds", type=int, default=3, help="seeds 0 .. n-1 per algorithm")
    p.add_argument("--out", required=True, help="output directory (one sub-directory a run)")
    p.add_argument("--jobs", type=int, default=1, help="runs at a time (processes)")
    p.add_argument("--plot-only", action="store_true", help="only re-plot existing runs")
    p.set_defaults(func=_compare_main)
