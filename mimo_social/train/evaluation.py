"""``evaluate``: reload the policy of a ``train`` directory and run episodes with it.

``evaluate(run, episodes=10)`` reloads ``run/model.zip`` (``model="best"`` or a path for another;
a multi-agent run: every agent's model), runs the episodes with the deterministic policy
(``deterministic=False`` samples), and writes ``run/eval_results.json``. ``both=True`` also runs
the same episodes with the stochastic policy (sampled actions, torch seeded with ``seed``): its
numbers under ``res["stochastic"]`` (recordings, videos and frames are of the first policy
only). ``progress`` shows a progress bar over the episodes. ``record`` writes a Rerun
recording of all episodes; ``video`` an MP4 of ``env.render()`` frames, which needs ``imageio``
with its ffmpeg plugin (``pip install 'imageio[ffmpeg]'``, in the ``train`` extra) or an
``ffmpeg`` program: ``frames`` writes the frames as PNG files instead.

Every output is checked before anything is loaded (:func:`check_outputs`): each path can be
written, and the MP4 encoder is made to write a two-frame video in a temporary folder
(:class:`VideoUnavailable` if it cannot). Should the video still fail while the episodes run
(a full disk, the encoder dying), the episodes go on, the recording and frames are written, and
``res["video_error"]`` says what happened (no ``res["video"]``).

A recurrent policy (``--algo recurrent_ppo``) carries its LSTM state across the steps of an
episode and starts each episode afresh (:class:`~mimo_social.train.rollouts.PolicyState`). A run
trained with ``--normalize-reward`` has ``vecnormalize.pkl`` next to ``model.zip``
(``best_vecnormalize.pkl``, ``checkpoints/vecnormalize_<n>_steps.pkl``): it is loaded with the
model (``res["vecnormalize"]``) and applied to the observations where it normalised them; the
returns reported are the env's own, never normalised. A run trained with a growth schedule
(``--growth``) is evaluated as its last training evaluation was: at the age the schedule ends at
(``forward``: the oldest, ``inverse``: the youngest; ``res["age_months"]``), or with each
episode's age drawn from the range (``stochastic``), unless ``env_kwargs`` gives ``age_months``.
"""

from __future__ import annotations

import functools

import json
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from ..core.wrappers import ActionDecoder
from .envs import make_env, make_parallel_env, make_scripted_env, run_observation
from .growth import evaluation_ages
from .rollouts import evaluate_agents, evaluate_policy, load_vecnormalize, vecnormalize_path
from .tasks import TrainInputError, algo_class

__all__ = ["evaluate", "EvalOutputs", "VideoUnavailable", "check_outputs"]


class VideoUnavailable(RuntimeError):
    """No MP4 encoder on this machine."""


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
            if state["proc"].wait():
                raise OSError(f"ffmpeg exited with code {state['proc'].returncode} writing "
                              f"{path}")
    return write, close


def _writable(name: str, path: Path, folder: bool) -> None:
    """A TrainInputError naming ``name`` and ``path`` unless ``path`` can be written: a file
    (``folder=False``) or a folder, existing and writable, or made in the nearest existing
    folder above it, which must be writable."""
    if not str(path):
        raise TrainInputError(f"{name}: an empty path; allowed: a "
                              f"{'folder' if folder else 'file'} to write")
    if path.exists():
        if folder != path.is_dir():
            raise TrainInputError(
                f"{name} {path}: is a {'file' if folder else 'folder'}; allowed: a "
                f"{'folder to write into' if folder else 'file to write'}")
        if not os.access(path, os.W_OK | (os.X_OK if folder else 0)):
            raise TrainInputError(f"{name} {path}: not writable")
        return
    above = path.absolute().parent
    while not above.exists():
        above = above.parent
    if not above.is_dir():
        raise TrainInputError(f"{name} {path}: {above} is a file, not a folder")
    if not os.access(above, os.W_OK | os.X_OK):
        raise TrainInputError(f"{name} {path}: the folder {above} is not writable")


def check_outputs(record=None, video=None, frames=None) -> None:
    """Before an evaluation loads anything: every output path given can be written (a
    TrainInputError naming it otherwise) and, for ``video``, the MP4 encoder works: it writes
    a two-frame 16x16 video in a temporary folder (:class:`VideoUnavailable` with the reason
    otherwise, e.g. no ``imageio`` with its ffmpeg plugin and no ``ffmpeg`` program)."""
    for name, path, folder in (("record", record, False), ("video", video, False),
                               ("frames", frames, True)):
        if path is not None:
            _writable(name, Path(path), folder)
    if video is None:
        return
    with tempfile.TemporaryDirectory(prefix="mimo-social-video-") as tmp:
        probe = Path(tmp) / "probe.mp4"
        try:
            write, close = _mp4_writer(probe, 25)
        except VideoUnavailable as e:
            raise VideoUnavailable(str(e).replace(str(probe), str(video))) from None
        try:
            for _ in range(2):
                write(np.zeros((16, 16, 3), np.uint8))
            close()
        except Exception as e:  # noqa: BLE001 (any encoder failure says the same)
            raise VideoUnavailable(f"cannot write {video}: the MP4 encoder failed on a test "
                                   f"video ({type(e).__name__}: {e}); use --frames DIR to "
                                   "write the frames as PNG files") from None
        if not probe.is_file() or probe.stat().st_size == 0:
            raise VideoUnavailable(f"cannot write {video}: the MP4 encoder wrote nothing for "
                                   "a test video; use --frames DIR to write the frames as PNG "
                                   "files")


class EvalOutputs:
    """What an evaluation writes besides its numbers: a Rerun recording of the inner
    ParallelEnv ``penv``, an MP4 and/or PNG frames of ``env.render()`` every ``frame_every``
    steps. ``on_reset()`` / ``on_step(actions, rewards)`` after each reset / step; ``close()``."""

    def __init__(self, env, penv, record=None, video=None, frames=None, frame_every: int = 1):
        self.env, self.frames, self.frame_every = env, frames, int(frame_every)
        self.want_frames = video is not None or frames is not None
        self.write = self._close_video = None
        #: why the video failed while the episodes ran (None: it did not)
        self.video_error: str | None = None
        self.recorder = None
        if record is not None:            # first: a video that fails does not stop it
            from ..recording.recorder import Recorder
            self.recorder = Recorder(penv, record)
        if frames is not None:
            Path(frames).mkdir(parents=True, exist_ok=True)
        if video is not None:
            self.video = Path(video)
            try:
                self.write, self._close_video = _mp4_writer(
                    self.video, int(penv.metadata.get("render_fps", 100)))
            except VideoUnavailable as e:
                self.video_error = str(e)
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
            try:
                self.write(frame)
            except Exception as e:  # noqa: BLE001 (the episodes and the recording go on)
                self._video_failed(e)
        if self.frames is not None:
            import matplotlib.image as mpimg
            mpimg.imsave(Path(self.frames) / f"ep{self.episode:03d}_{self.step:05d}.png", frame)

    def _video_failed(self, error: Exception, when: str = "") -> None:
        self.video_error = (f"cannot write {self.video}: {type(error).__name__}: {error} "
                            f"({when}episode {self.episode}, step {self.step}); the other "
                            "outputs were written")
        close, self.write, self._close_video = self._close_video, None, None
        try:
            if close is not None:
                close()
        except Exception:  # noqa: BLE001 (the first error is the one to report)
            pass

    def close(self) -> None:
        try:
            if self.recorder is not None:
                self.recorder.close()
        finally:
            if self._close_video is not None:
                close, self._close_video, self.write = self._close_video, None, None
                try:
                    close()
                except Exception as e:  # noqa: BLE001
                    self._video_failed(e, "closing it after ")

    def report(self, res: dict, record, video, frames) -> dict:
        """``res`` with the paths written (``record``, ``video``, ``frames``) and, if the video
        failed, ``video_error`` instead of ``video``."""
        for key, value in (("record", record), ("video", video), ("frames", frames)):
            if value is not None:
                res[key] = str(value)
        if self.video_error is not None:
            res.pop("video", None)
            res["video_error"] = self.video_error
        return res


class _Bar:
    """A tqdm bar over ``total`` episodes (or nothing), as ``on_episode``."""

    def __init__(self, total: int, enabled: bool, desc: str):
        self.bar = None
        if enabled:
            from tqdm import tqdm
            self.bar = tqdm(total=total, unit="episode", desc=desc, dynamic_ncols=True)

    def __call__(self) -> None:
        if self.bar is not None:
            self.bar.update(1)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _sampled(make: Callable[[], Any], run_episodes: Callable[[Any], dict], seed: int) -> dict:
    """The stochastic policy's numbers: ``run_episodes(env)`` on a fresh env of ``make()``
    (closed after), torch's random numbers forked and seeded with ``seed``."""
    import torch
    env = make()
    try:
        with torch.random.fork_rng(devices=[]):
            torch.manual_seed(seed)
            res = run_episodes(env)
    finally:
        env.close()
    keep = ("returns", "lengths", "return_mean", "return_std", "length_mean", "success_rate",
            "agents")
    return {k: res[k] for k in keep if k in res}


def evaluate(run: str | Path, episodes: int = 10, *, model: str = "final", seed: int = 0,
             deterministic: bool = True, record: str | Path | None = None,
             video: str | Path | None = None, frames: str | Path | None = None,
             frame_every: int = 1, env_kwargs: Mapping[str, Any] | None = None,
             both: bool = False, progress: bool = False) -> dict:
    """Reload a trained policy from a ``train`` directory and run ``episodes`` episodes
    (``both``: with the deterministic and with the stochastic policy; module docstring)."""
    check_outputs(record, video, frames)        # before anything slow is loaded
    import torch
    torch.set_num_threads(1)
    run = Path(run)
    if not (run / "config.json").exists():
        raise FileNotFoundError(f"{run}/config.json not found: give a directory written by "
                                "'mimo-social train'")
    config = json.loads((run / "config.json").read_text())
    if config.get("mode") is not None:
        return _evaluate_multi(run, config, episodes, model=model, seed=seed,
                              deterministic=deterministic, record=record, video=video,
                              frames=frames, frame_every=frame_every, env_kwargs=env_kwargs,
                              both=both, progress=progress)
    path = {"final": run / "model.zip", "best": run / "best_model.zip"}.get(model, Path(model))
    if not path.exists():
        raise FileNotFoundError(f"model {path} not found (--model final, best or a .zip path)")
    policy = algo_class(config["algo"]).load(str(path), device="cpu")
    stats = vecnormalize_path(path)
    normalize = load_vecnormalize(stats)
    kw = dict(config.get("env_kwargs", {}))
    kw.update(env_kwargs or {})
    grown, wrap = evaluation_ages(config, env_kwargs or {})   # a growth run: its last age
    kw.update(grown)
    want_frames = video is not None or frames is not None
    obs = run_observation(config)     # the layout the run was trained on
    env = wrap(make_env(config["task"], render_mode="rgb_array" if want_frames else None, **obs,
                        **kw))
    penv = env.unwrapped.parallel
    outputs = EvalOutputs(env, penv, record, video, frames, frame_every)
    agent = penv.possible_agents[0]
    decode = ActionDecoder(penv.action_space(agent))   # the flat action as the env takes it

    def on_step(action, reward, info, reset):
        if reset:
            outputs.on_reset()
        else:
            outputs.on_step({agent: decode(action, agent)}, {agent: float(reward)})

    t0 = time.perf_counter()
    bar = _Bar(episodes * (2 if both else 1), progress, f"eval {run.name}")
    try:
        res = evaluate_policy(policy, env, episodes, seed, deterministic, on_step, bar,
                              normalize)
        if both:
            res["stochastic"] = _sampled(
                lambda: wrap(make_env(config["task"], **obs, **kw)),
                lambda e: evaluate_policy(policy, e, episodes, seed, False, on_episode=bar,
                                          normalize=normalize), seed)
    finally:
        bar.close()
        outputs.close()
        env.close()
    res.update({"task": config["task"], "algo": config["algo"], "model": str(path),
                "vecnormalize": str(stats) if stats.is_file() else None,
                "episodes": episodes, "deterministic": deterministic, "seed": seed,
                "wall_time_s": round(time.perf_counter() - t0, 2)})
    if config.get("growth"):
        res["age_months"] = kw.get("age_months", config["growth"].get("spec"))
    outputs.report(res, record, video, frames)
    (run / "eval_results.json").write_text(json.dumps(res, indent=2, default=float))
    return res


def _action_decoder(env) -> Callable[[str, Any], Any]:
    """Flat action -> the agent's action as the env takes it, for the recorder (which checks it
    as ``env.step`` does)."""
    inner = env.unwrapped
    decoders = {a: ActionDecoder(inner.action_space(a)) for a in env.possible_agents}
    return lambda a, act: decoders[a](act, a)


def _load_policies(run: Path, config: dict, model: str) -> tuple[dict, dict]:
    cls = algo_class(config["algo"])
    agents = config["agents"]
    if config["mode"] == "independent":
        if model in ("final", "best"):
            prefix = "model" if model == "final" else "best_model"
            paths = {a: run / f"{prefix}_{a}.zip" for a in agents}
        else:
            raise FileNotFoundError(f"--model {model!r}: an independent run has one model per "
                                    "agent; use --model final or best")
    else:
        path = {"final": run / "model.zip", "best": run / "best_model.zip"}.get(model, Path(model))
        paths = {a: path for a in agents}
    for p in set(paths.values()):
        if not Path(p).exists():
            raise FileNotFoundError(f"model {p} not found (--model final, best"
                                    + (")" if config["mode"] == "independent"
                                       else " or a .zip path)"))
    loaded = {p: cls.load(str(p), device="cpu") for p in sorted(set(paths.values()))}
    return {a: loaded[p] for a, p in paths.items()}, {a: str(p) for a, p in paths.items()}


def evaluate_with_outputs(policies: Mapping[str, Any], env, inner, episodes: int, seed: int,
                          deterministic: bool, record, video, frames, frame_every: int,
                          on_episode=None, normalize: Mapping[str, Any] | None = None) -> dict:
    """Run :func:`evaluate_agents` on ``env`` (its MimoParallelEnv: ``inner``) while recording,
    filming or saving frames as asked; close both; the results with ``wall_time_s`` and the
    ``record`` / ``video`` / ``frames`` paths given. The multi-agent evaluation of either
    engine."""
    outputs = EvalOutputs(env, inner, record, video, frames, frame_every)
    decode = _action_decoder(env)

    def on_step(actions, rewards, obs, reset):
        if reset:
            outputs.on_reset()
        else:
            outputs.on_step({a: decode(a, act) for a, act in actions.items()}, rewards)

    t0 = time.perf_counter()
    try:
        res = evaluate_agents(policies, env, episodes, seed, deterministic, on_step, on_episode,
                              normalize)
    finally:
        outputs.close()
        env.close()
    res["wall_time_s"] = round(time.perf_counter() - t0, 2)
    return outputs.report(res, record, video, frames)


def _evaluate_multi(run: Path, config: dict, episodes: int, *, model: str, seed: int,
                   deterministic: bool, record, video, frames, frame_every: int,
                   env_kwargs: Mapping[str, Any] | None, both: bool = False,
                   progress: bool = False) -> dict:
    """The multi-agent part of :func:`evaluate`."""
    policies, paths = _load_policies(run, config, model)
    stats = {a: vecnormalize_path(p) for a, p in paths.items()}
    normalize = {a: load_vecnormalize(p) for a, p in stats.items()}
    kw = dict(config.get("env_kwargs", {}))
    kw.update(env_kwargs or {})
    want_frames = video is not None or frames is not None
    make = functools.partial(
        make_scripted_env if config["mode"] == "scripted" else make_parallel_env,
        **(run_observation(config) if config["mode"] == "scripted" else {}))
    env = make(config["task"], render_mode="rgb_array" if want_frames else None, **kw)
    bar = _Bar(episodes * (2 if both else 1), progress, f"eval {run.name}")
    try:
        res = evaluate_with_outputs(policies, env, env.unwrapped, episodes, seed, deterministic,
                                    record, video, frames, frame_every, bar, normalize)
        if both:
            res["stochastic"] = _sampled(
                lambda: make(config["task"], **kw),
                lambda e: evaluate_agents(policies, e, episodes, seed, False, on_episode=bar,
                                          normalize=normalize), seed)
    finally:
        bar.close()
    res.update({"task": config["task"], "algo": config["algo"], "mode": config["mode"],
                "model": paths[next(iter(paths))], "models": paths,
                "vecnormalize": next((str(p) for p in stats.values() if p.is_file()), None),
                "episodes": episodes,
                "deterministic": deterministic, "seed": seed})
    (run / "eval_results.json").write_text(json.dumps(res, indent=2, default=float))
    return res
