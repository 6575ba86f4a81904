"""Several envs of one learner in worker processes: :class:`TimedSubprocVecEnv`.

``one_learner_vec_env(env_fn, n_envs, worker_timeout, n_workers=None)``
    ``n_envs=1`` or ``n_workers=0``: SB3's ``DummyVecEnv`` in this process. Otherwise a
    :class:`TimedSubprocVecEnv`: ``n_workers`` spawned worker processes (default one per core,
    never more than the envs; ``spawn``: a GL context does not survive ``fork``), each stepping
    a contiguous block of the envs one after the other, so that a pipe round trip and a policy
    call serve several env steps. The workers run
    :func:`~mimo_social.train.gym_worker.gym_worker` (imports neither SB3 nor torch) and ignore
    SIGINT (Ctrl-C stops the run through its parent, :mod:`.interrupt`).
``default_n_envs()``
    The default number of envs: :data:`ENVS_PER_WORKER` (1) per worker, one worker per CPU core
    this process may use (at most :data:`MAX_DEFAULT_WORKERS`). More envs per worker
    (``--n-envs``) run PPO faster per env step but learn less per step with its rollout of
    2048: on reach (300k steps, 20 held-out episodes) the mean action of seed 1 succeeded 19/20
    with 2 envs, 7/20 with 4 and 2/20 with 8 (docs/training/issue29/README.md).

A worker that dies or does not answer within ``worker_timeout`` seconds is a RuntimeError naming
it (its process id and exit code), never a hang.
"""

from __future__ import annotations

import multiprocessing as mp
import time
from typing import Callable, Sequence

import cloudpickle
import numpy as np
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv
from stable_baselines3.common.vec_env.base_vec_env import VecEnvIndices

from ..util.cores import cpu_cores
from .gym_worker import gym_worker
from .interrupt import workers_ignore_sigint

__all__ = ["TimedSubprocVecEnv", "one_learner_vec_env", "default_n_envs", "default_workers",
           "MAX_DEFAULT_WORKERS", "ENVS_PER_WORKER",
           "DEFAULT_WORKER_TIMEOUT"]

MAX_DEFAULT_WORKERS = 16
ENVS_PER_WORKER = 1
DEFAULT_WORKER_TIMEOUT = 600.0


def default_n_envs() -> int:
    """:data:`ENVS_PER_WORKER` envs for each of :func:`default_workers` workers."""
    return ENVS_PER_WORKER * default_workers(MAX_DEFAULT_WORKERS)


def default_workers(n_envs: int) -> int:
    """Worker processes for ``n_envs`` envs: one per core (at most
    :data:`MAX_DEFAULT_WORKERS`), never more than the envs."""
    return max(1, min(int(n_envs), cpu_cores(), MAX_DEFAULT_WORKERS))


def check_timeout(timeout_s) -> float:
    if isinstance(timeout_s, bool) or not isinstance(timeout_s, (int, float)) or not timeout_s > 0:
        raise ValueError(f"worker_timeout={timeout_s!r}; allowed: a positive number of seconds")
    return float(timeout_s)


def blocks(n_envs: int, n_workers: int) -> list[range]:
    """Env indices ``0 .. n_envs-1`` in ``n_workers`` contiguous blocks, sizes differing by at
    most one (the first blocks the larger)."""
    counts = [n_envs // n_workers + (1 if w < n_envs % n_workers else 0)
              for w in range(n_workers)]
    starts = [sum(counts[:w]) for w in range(n_workers)]
    return [range(a, a + c) for a, c in zip(starts, counts)]


class TimedSubprocVecEnv(VecEnv):
    """SB3 VecEnv of ``len(env_fns)`` envs in ``n_workers`` spawned worker processes (default:
    one each), each worker stepping its contiguous block of envs one after the other per
    message (:mod:`~mimo_social.train.gym_worker`). Every wait for a worker ends after
    ``timeout_s`` seconds with a RuntimeError naming the worker (module docstring)."""

    def __init__(self, env_fns: Sequence[Callable], start_method: str = "spawn",
                 timeout_s: float = DEFAULT_WORKER_TIMEOUT, n_workers: int | None = None):
        self.timeout_s = check_timeout(timeout_s)
        n = len(env_fns)
        n_workers = n if n_workers is None else int(n_workers)
        if not 1 <= n_workers <= n:
            raise ValueError(f"n_workers={n_workers}; allowed: 1 to the number of envs ({n})")
        self.blocks = blocks(n, n_workers)
        self.where = [(w, i) for w, b in enumerate(self.blocks) for i in range(len(b))]
        self.waiting = False
        self.closed = False
        ctx = mp.get_context(start_method)
        self.remotes, self.work_remotes = zip(*[ctx.Pipe() for _ in self.blocks])
        self.processes = []
        with workers_ignore_sigint():
            for k, (work, remote, b) in enumerate(zip(self.work_remotes, self.remotes,
                                                      self.blocks)):
                payload = cloudpickle.dumps([env_fns[i] for i in b])
                proc = ctx.Process(target=gym_worker, args=(work, remote, payload),
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
        super().__init__(n, obs_space, act_space)

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

    def _gather(self) -> list:
        return [self.recv(k) for k in range(len(self.remotes))]

    def step_async(self, actions) -> None:
        for remote, b in zip(self.remotes, self.blocks):
            remote.send(("step", actions[b.start:b.stop]))
        self.waiting = True

    def step_wait(self):
        results = self._gather()
        self.waiting = False
        obs, rews, dones, infos, resets = zip(*results)
        self.reset_infos = [r for block in resets for r in block]
        return (join_obs(obs), np.concatenate(rews), np.concatenate(dones),
                [i for block in infos for i in block])

    def reset(self):
        for remote, b in zip(self.remotes, self.blocks):
            remote.send(("reset", [(self._seeds[i], self._options[i]) for i in b]))
        obs, infos = zip(*self._gather())
        self.reset_infos = [r for block in infos for r in block]
        self._reset_seeds()
        self._reset_options()
        return join_obs(obs)

    def _ask(self, cmd: str, indices: VecEnvIndices, rest=None) -> list:
        """``cmd`` for the envs ``indices``: one answer per env, in the order asked."""
        chosen = self._get_indices(indices)
        per_worker: dict[int, list[int]] = {}
        for i in chosen:
            w, local = self.where[i]
            per_worker.setdefault(w, []).append(local)
        for w, local in per_worker.items():
            self.remotes[w].send((cmd, (local, rest)))
        answers = {w: iter(self.recv(w)) for w in per_worker}
        return [next(answers[self.where[i][0]]) for i in chosen]

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list:
        return self._ask("get_attr", indices, attr_name)

    def set_attr(self, attr_name: str, value, indices: VecEnvIndices = None) -> None:
        self._ask("set_attr", indices, (attr_name, value))

    def env_method(self, method_name: str, *method_args, indices: VecEnvIndices = None,
                   **method_kwargs) -> list:
        return self._ask("env_method", indices, (method_name, method_args, method_kwargs))

    def env_is_wrapped(self, wrapper_class, indices: VecEnvIndices = None) -> list[bool]:
        return self._ask("is_wrapped", indices, wrapper_class)

    def has_attr(self, attr_name: str) -> bool:
        return bool(self._ask("has_attr", [0], attr_name)[0])

    def get_images(self) -> Sequence:
        return self._ask("render", None)

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
                self._gather()
            for remote in self.remotes:
                remote.send(("close", None))
            for proc in self.processes:
                proc.join(10)
        except (RuntimeError, OSError):
            pass
        self.kill()


def join_obs(parts: tuple):
    """The workers' stacked observations as one batch (arrays, or dicts of arrays)."""
    if isinstance(parts[0], dict):
        return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    return np.concatenate(parts)


def one_learner_vec_env(env_fn: Callable, n_envs: int = 1,
                        worker_timeout: float = DEFAULT_WORKER_TIMEOUT,
                        n_workers: int | None = None) -> VecEnv:
    """``n_envs`` copies of ``env_fn()`` (picklable by cloudpickle) as one SB3 VecEnv, in
    ``n_workers`` spawned worker processes (default: one per core, at most one per env; 0 or
    ``n_envs=1``: all in this process, SB3's ``DummyVecEnv``). Module docstring."""
    n_envs = int(n_envs)
    if n_envs < 1:
        raise ValueError(f"n_envs={n_envs}; allowed: a positive integer")
    check_timeout(worker_timeout)
    n_workers = default_workers(n_envs) if n_workers is None else int(n_workers)
    if not 0 <= n_workers <= n_envs:
        raise ValueError(f"n_workers={n_workers}; allowed: 0 (in this process) to n_envs "
                         f"({n_envs})")
    if n_envs == 1 or n_workers == 0:
        return DummyVecEnv([env_fn] * n_envs)
    return TimedSubprocVecEnv([env_fn] * n_envs, timeout_s=worker_timeout, n_workers=n_workers)
