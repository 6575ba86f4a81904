"""Recording whole episodes: one episode now (:func:`record_episode`), or every k-th episode of
an env during training (:class:`RecordingParallelEnv`, :func:`recording_env_fn` for vector envs).
"""

from __future__ import annotations

import multiprocessing
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..core.wrappers import ParallelWrapper

from ..util.checks import check_int, check_seed
from .recorder import Recorder, parallel_of

__all__ = [
    "FIRST_VEC_WORKER",
    "RecordSubEnv",
    "RecordingParallelEnv",
    "record_episode",
    "recording_env_fn",
]


def record_episode(env, path: str | Path, policy: Callable[[dict], dict] | None = None, *,
                   seed: int | None = None, max_steps: int | None = None,
                   every_k_steps: int = 1, **recorder_options) -> dict:
    """Reset ``env``, run one episode and record it to ``path``; return a small summary.

    ``policy(obs) -> actions`` gets the observation dict of the live agents and returns their
    actions; without one, actions are sampled from the action spaces (seeded by ``seed``). The
    episode ends when no agent is left or after ``max_steps`` steps. ``env``: as for
    :class:`Recorder` (the episode is run on the ``MimoParallelEnv`` inside it).
    """
    seed = check_seed(seed, "record_episode")
    if max_steps is not None:
        max_steps = check_int("record_episode", "max_steps", max_steps, lo=0)
    penv = parallel_of(env)
    if penv is None:
        raise TypeError(f"record_episode needs a MimoParallelEnv, the Gymnasium adapter or a "
                        f"wrapper of one, got {type(env).__name__}")
    if policy is None:
        for k, a in enumerate(penv.possible_agents):
            penv.action_space(a).seed(None if seed is None else seed + k)

        def policy(obs):
            return {a: penv.action_space(a).sample() for a in penv.agents}
    steps = 0
    with Recorder(penv, path, every_k_steps, **recorder_options) as rec:
        obs, _ = penv.reset(seed=seed)
        rec.log_reset(obs)
        while penv.agents and (max_steps is None or steps < max_steps):
            actions = policy(obs)
            obs, rewards, _, _, _ = penv.step(actions)
            rec.log_step(actions, rewards, obs)
            steps += 1
    return {"path": str(rec.path), "steps": steps, "sim_time": steps * penv.dt,
            "rows": rec.rows, "bytes": rec.path.stat().st_size, "overhead_s": rec.overhead_s}


def _check_episode_options(owner: str, path_pattern, every_k_episodes) -> None:
    check_int(owner, "every_k_episodes", every_k_episodes, lo=1)
    try:
        str(path_pattern).format(episode=0)
    except (KeyError, IndexError, ValueError) as e:
        raise ValueError(f"path_pattern={str(path_pattern)!r}: {e!r}; it may only use "
                         "{episode} (e.g. 'runs/ep{episode:05d}.rrd')") from None


#: per claim key: how many wrappers with that key have reset in this process (see
#: :class:`RecordingParallelEnv`'s ``claim``)
_CLAIMS: dict[str, int] = {}

#: the name of the first worker process of :func:`mimo_social.train.vector.sb3_vec_env`
FIRST_VEC_WORKER = "mimo_social-vec-0"


def _main_or_first_worker() -> bool:
    return (multiprocessing.parent_process() is None
            or multiprocessing.current_process().name == FIRST_VEC_WORKER)


class RecordingParallelEnv(ParallelWrapper):
    """A ParallelEnv wrapper that records every ``every_k_episodes``-th episode to its own file.

    ``env``: a ``MimoParallelEnv`` (or a wrapper of one that keeps its dict observations and
    actions). Episodes are counted by the resets of this wrapper, from 0: episodes 0, k, 2k ...
    are recorded to ``path_pattern.format(episode=n)`` (e.g. ``"runs/ep{episode:05d}.rrd"``),
    each with a :class:`Recorder` (``recorder_options`` go to it) that the wrapper feeds itself
    with the actions, rewards and observations it passes on, and closes (writing the file's
    footer) when the episode ends, at the next reset or at :meth:`close`.

    It pickles (for vector envs in worker processes): an open recorder stays with the process
    that opened it and the copy starts its own at its next chosen episode; files are opened
    lazily, at the reset of a chosen episode, in the process that steps the env.

    ``claim=(key, n)`` makes it record only if it is the n-th (from 0) of the wrappers with that
    key to reset in its process, in the main process or the first worker of ``sb3_vec_env``
    (:func:`recording_env_fn` uses it: SuperSuit makes every world as a pickled copy of one env,
    so the worlds can only tell themselves apart by the order they reset in, world 0 first).
    """

    def __init__(self, env, path_pattern: str | Path = "recordings/ep{episode:05d}.rrd",
                 every_k_episodes: int = 10, *, claim: tuple[str, int] | None = None,
                 **recorder_options):
        _check_episode_options(type(self).__name__, path_pattern, every_k_episodes)
        super().__init__(env)
        self.path_pattern = str(path_pattern)
        self.every_k_episodes = int(every_k_episodes)
        self.recorder_options = dict(recorder_options)
        self.claim = None if claim is None else (str(claim[0]), int(claim[1]))
        self.rank: int | None = None         # with a claim: its place among the wrappers
        self.chosen = claim is None          # records (with a claim: known at the first reset)
        self.episode = -1                    # index of the current episode (-1: before a reset)
        self.recorder: Recorder | None = None
        self.paths: list[Path] = []          # the files this wrapper (in this process) wrote
        self.possible_agents = list(env.possible_agents)

    def _recorded_env(self):
        return self.env if hasattr(self.env, "world") else self.env.unwrapped

    def reset(self, seed: int | None = None, options: dict | None = None):
        obs, infos = self.env.reset(seed=seed, options=options)
        self._stop_recording()
        if self.claim is not None and self.rank is None:
            key, wanted = self.claim
            self.rank = _CLAIMS.get(key, 0)
            _CLAIMS[key] = self.rank + 1
            self.chosen = self.rank == wanted and _main_or_first_worker()
        self.episode += 1
        if self.chosen and self.episode % self.every_k_episodes == 0:
            path = Path(self.path_pattern.format(episode=self.episode))
            options = {"recording_name": f"episode {self.episode}", **self.recorder_options}
            self.recorder = Recorder(self._recorded_env(), path, **options)
            self.paths.append(path)
            self.recorder.log_reset(obs)
        return obs, infos

    def step(self, actions):
        obs, rewards, terminations, truncations, infos = self.env.step(actions)
        rec = self.recorder
        if rec is not None:
            rec.log_step(actions, rewards, obs)
            if not self.env.agents:
                self._stop_recording()
        return obs, rewards, terminations, truncations, infos

    def _stop_recording(self) -> None:
        if self.recorder is not None:
            rec, self.recorder = self.recorder, None
            rec.close()

    def close(self):
        self._stop_recording()
        return self.env.close()

    def __getstate__(self):
        state = self.__dict__.copy()
        state["recorder"] = None             # an open file never travels
        if self.claim is not None:           # a copy claims its own place at its first reset
            state["rank"], state["chosen"] = None, False
        return state


class RecordSubEnv:
    """The ``env_fn`` made by :func:`recording_env_fn` (picklable when ``env_fn`` is)."""

    def __init__(self, env_fn: Callable[[], Any], path_pattern: str | Path,
                 every_k_episodes: int = 10, sub_env: int = 0, **recorder_options):
        check_int("recording_env_fn", "sub_env", sub_env, lo=0)
        _check_episode_options("recording_env_fn", path_pattern, every_k_episodes)
        self.env_fn = env_fn
        self.path_pattern = str(path_pattern)
        self.every_k_episodes = int(every_k_episodes)
        self.sub_env = int(sub_env)
        self.recorder_options = dict(recorder_options)
        self.key = uuid.uuid4().hex          # travels with the pickle: the same in every worker

    def __call__(self) -> RecordingParallelEnv:
        return RecordingParallelEnv(self.env_fn(), self.path_pattern, self.every_k_episodes,
                                    claim=(self.key, self.sub_env), **self.recorder_options)


def recording_env_fn(env_fn: Callable[[], Any], path_pattern: str | Path,
                     every_k_episodes: int = 10, sub_env: int = 0,
                     **recorder_options) -> RecordSubEnv:
    """``env_fn`` for :func:`~mimo_social.train.vector.sb3_vec_env` whose world ``sub_env``
    (default 0) records every ``every_k_episodes``-th episode to ``path_pattern``::

        venv = sb3_vec_env(recording_env_fn(high_five_v0.parallel_env, "runs/ep{episode:05d}.rrd",
                                            every_k_episodes=10), n_envs=8, n_cpus=2)

    Every world gets a :class:`RecordingParallelEnv` (inside ``FlattenParallel``, so it sees the
    dict actions and observations), but only one records: the ``sub_env``-th to reset in the
    main process (``n_cpus=0``) or in the first worker process (``n_cpus>=1``, which holds
    worlds 0, 1, ...; ``sub_env`` must be below its number of worlds). SuperSuit resets worlds
    in order, so that is world ``sub_env``. The others pass everything through.
    """
    return RecordSubEnv(env_fn, path_pattern, every_k_episodes, sub_env, **recorder_options)
