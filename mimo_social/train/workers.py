"""Several envs of one learner in worker processes: :class:`TimedSubprocVecEnv`.

``one_learner_vec_env(env_fn, n_envs, worker_timeout)``
    ``n_envs=1``: SB3's ``DummyVecEnv`` in this process. ``n_envs>1``: :class:`TimedSubprocVecEnv`,
    one spawned worker process per env (``spawn``: a GL context does not survive ``fork``). The
    workers run :func:`~mimo_social.train.gym_worker.gym_worker` (imports neither SB3 nor torch)
    and ignore SIGINT (Ctrl-C stops the run through its parent, :mod:`.interrupt`).
``default_n_envs()``
    The default number of envs: the CPU cores this process may use, at most
    :data:`MAX_DEFAULT_ENVS`.

A worker that dies or does not answer within ``worker_timeout`` seconds is a RuntimeError naming
it (its process id and exit code), never a hang.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import time
from typing import Callable, Sequence

import cloudpickle
import numpy as np
from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecEnv

from .gym_worker import gym_worker
from .interrupt import workers_ignore_sigint

__all__ = ["TimedSubprocVecEnv", "one_learner_vec_env", "default_n_envs", "MAX_DEFAULT_ENVS",
           "DEFAULT_WORKER_TIMEOUT"]

MAX_DEFAULT_ENVS = 16
DEFAULT_WORKER_TIMEOUT = 600.0


def default_n_envs() -> int:
    """The CPU cores this process may run on (``os.sched_getaffinity``), 1 to
    :data:`MAX_DEFAULT_ENVS`."""
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    return max(1, min(MAX_DEFAULT_ENVS, cores))


def check_timeout(timeout_s) -> float:
    if isinstance(timeout_s, bool) or not isinstance(timeout_s, (int, float)) or not timeout_s > 0:
        raise ValueError(f"worker_timeout={timeout_s!r}; allowed: a positive number of seconds")
    return float(timeout_s)


def stack_obs(obs: tuple):
    """The workers' observations as one batch: an array, or for ``Dict`` observations (images
    and a vector) a dict key -> array, as SB3's VecEnvs give them."""
    if isinstance(obs[0], dict):
        return {k: np.stack([o[k] for o in obs]) for k in obs[0]}
    return np.stack(obs)


class TimedSubprocVecEnv(SubprocVecEnv):
    """SB3's ``SubprocVecEnv`` (spawned workers) whose every wait for a worker ends after
    ``timeout_s`` seconds with a RuntimeError naming the worker (module docstring)."""

    def __init__(self, env_fns: Sequence[Callable], start_method: str = "spawn",
                 timeout_s: float = DEFAULT_WORKER_TIMEOUT):
        self.timeout_s = check_timeout(timeout_s)
        self.waiting = False
        self.closed = False
        ctx = mp.get_context(start_method)
        self.remotes, self.work_remotes = zip(*[ctx.Pipe() for _ in env_fns])
        self.processes = []
        with workers_ignore_sigint():
            for k, (work, remote, fn) in enumerate(zip(self.work_remotes, self.remotes, env_fns)):
                proc = ctx.Process(target=gym_worker, args=(work, remote, cloudpickle.dumps(fn)),
                                   daemon=True, name=f"mimo_social-env-{k}")
                proc.start()
                self.processes.append(proc)
                work.close()
        try:
            self.remotes[0].send(("get_spaces", None))
            obs_space, act_space = self.recv(0)
        except BaseException:
            self.kill()
            raise
        VecEnv.__init__(self, len(env_fns), obs_space, act_space)

    def recv(self, k: int):
        """Worker ``k``'s answer; RuntimeError if it dies or takes longer than the timeout."""
        remote, proc = self.remotes[k], self.processes[k]
        deadline = time.monotonic() + self.timeout_s
        while True:
            left = deadline - time.monotonic()
            if remote.poll(max(0.0, min(1.0, left))):
                try:
                    return remote.recv()
                except (EOFError, OSError):
                    break
            if not proc.is_alive():
                if remote.poll(0):
                    continue
                break
            if left <= 0:
                raise RuntimeError(
                    f"env worker {k} (pid {proc.pid}) did not answer within {self.timeout_s:g} s "
                    "(alive: stopped or stuck); raise --worker-timeout if its env is that slow")
        proc.join(0.5)
        raise RuntimeError(f"env worker {k} (pid {proc.pid}) died (exit code {proc.exitcode})")

    def step_wait(self):
        results = [self.recv(k) for k in range(len(self.remotes))]
        self.waiting = False
        obs, rews, dones, infos, self.reset_infos = zip(*results)
        return stack_obs(obs), np.stack(rews), np.stack(dones), infos

    def reset(self):
        for k, remote in enumerate(self.remotes):
            remote.send(("reset", (self._seeds[k], self._options[k])))
        results = [self.recv(k) for k in range(len(self.remotes))]
        obs, self.reset_infos = zip(*results)
        self._reset_seeds()
        self._reset_options()
        return stack_obs(obs)

    def kill(self) -> None:
        """End every worker without asking (one that is stuck or dead)."""
        for proc in self.processes:
            if proc.is_alive():
                proc.terminate()
            proc.join(1)
        for remote in self.remotes:
            remote.close()
        self.closed = True

    def close(self) -> None:
        if self.closed:
            return
        try:
            if self.waiting:
                for k in range(len(self.remotes)):
                    self.recv(k)
            for remote in self.remotes:
                remote.send(("close", None))
            for proc in self.processes:
                proc.join(10)
        except (RuntimeError, OSError):
            pass
        self.kill()


def one_learner_vec_env(env_fn: Callable, n_envs: int = 1,
                        worker_timeout: float = DEFAULT_WORKER_TIMEOUT) -> VecEnv:
    """``n_envs`` copies of ``env_fn()`` (picklable by cloudpickle) as one SB3 VecEnv: in this
    process for one, else one spawned worker each (module docstring)."""
    n_envs = int(n_envs)
    if n_envs < 1:
        raise ValueError(f"n_envs={n_envs}; allowed: a positive integer")
    check_timeout(worker_timeout)
    if n_envs == 1:
        return DummyVecEnv([env_fn])
    return TimedSubprocVecEnv([env_fn] * n_envs, timeout_s=worker_timeout)
