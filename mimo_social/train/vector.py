"""SB3 vector envs with parameter sharing: every agent of every world is one slot of the VecEnv.

``sb3_vec_env(env_fn, n_envs=1, n_cpus=0, start_method="spawn")``
    ``env_fn()`` builds one ParallelEnv (e.g. ``high_five_v0.parallel_env``). The result is an SB3
    ``VecEnv`` with ``n_envs * n_agents`` slots, float32 Box observations and actions (see
    :class:`~mimo_social.core.wrappers.FlattenParallel`); slot ``w * n_agents + j`` is agent ``j`` of
    world ``w``. Every world's agents must share one observation space and one action space.

    * ``n_cpus=0``: in-process, built as SuperSuit does it:
      ``concat_vec_envs_v1(pettingzoo_env_to_vec_env_v1(FlattenParallel(env_fn())), n_envs,
      num_cpus=0, base_class="stable_baselines3")``.
    * ``n_cpus>=1``: ``min(n_cpus, n_envs)`` worker processes started with ``start_method``
      (default ``"spawn"``), each running SuperSuit's in-process vector env for its share of the
      worlds (:class:`SpawnConcatVecEnv`). SuperSuit 3.11's own multi-process env
      (``concat_vec_envs_v1(num_cpus>=2)`` -> ``ProcConcatVec``) takes no start method: it calls
      ``multiprocessing.Process`` / ``Pipe`` / ``Array`` of the default context, which on Linux with
      Python 3.11 is ``fork`` (unsafe once a GL context exists), so it is not used. ``env_fn`` must
      be picklable by cloudpickle (module functions, lambdas, ``functools.partial`` are), and a
      script using workers needs the usual ``if __name__ == "__main__":`` guard. Seeds give the
      same worlds as the in-process env (world ``w`` is reset with ``seed + w`` either way).

Seeding (the SuperSuit/SB3 mismatch this module fixes)
    SB3 2.9 seeds through ``VecEnv.seed(seed)`` (called by ``BaseAlgorithm.set_random_seed``, i.e.
    by ``PPO(..., seed=0)``, and by ``make_vec_env``): it only stores ``_seeds = [seed + i]`` and the
    next ``reset()`` must pass them to the envs. SuperSuit's ``SB3VecEnvWrapper`` never calls
    ``VecEnv.__init__`` (no ``_seeds`` / ``_options``), inherits ``VecEnvWrapper.seed`` which calls
    ``seed`` on the gymnasium-1.x vector env underneath, which has none (``AttributeError``: PPO with
    a ``seed`` crashes), and its ``reset()`` never passes a seed or options on. It also folds
    ``truncated`` into ``dones`` without ``info["TimeLimit.truncated"]``, so SB3 cannot bootstrap
    time-limit ends, and forwards ``get_attr`` to a method gymnasium 1.x vector envs lack.
    :class:`SeededVecEnv` wraps it and takes over those parts: ``seed`` / ``set_options`` store
    (SB3 semantics), ``reset()`` passes the stored seed (and options) once to the SuperSuit vector
    env (world ``w`` gets ``seed + w``) and returns the observations only (infos in
    ``reset_infos``), ``step_wait()`` returns ``(obs, rewards, dones, infos)`` with
    ``terminal_observation`` (set by SuperSuit) and ``TimeLimit.truncated`` in the infos of
    finished slots.

    SuperSuit merges the reset infos into the infos of the last step of an episode (keys such as
    ``step`` then hold the reset values); ``terminal_observation`` and the task's keys are kept.
"""

from __future__ import annotations

import multiprocessing as mp
import time
import warnings
from typing import Any, Callable, Sequence

import cloudpickle
import gymnasium
import numpy as np
import supersuit as ss
from pettingzoo import ParallelEnv
from stable_baselines3.common.vec_env import VecEnv, VecEnvWrapper
from stable_baselines3.common.vec_env.base_vec_env import VecEnvIndices
from supersuit.vector.sb3_vector_wrapper import SB3VecEnvWrapper

from .envs import call_world, stop_workers, vec_worker, world_vec_env

# Worker processes run ``envs.vec_worker``: importing that module pulls in neither SB3 nor
# torch, so a spawned worker starts (and exits) in about a second instead of several.

__all__ = ["sb3_vec_env", "SeededVecEnv", "SpawnConcatVecEnv"]


class SpawnConcatVecEnv(gymnasium.vector.VectorEnv):
    """SuperSuit-style vector env (``reset -> (obs, infos)``, 5-tuple ``step``, single-slot
    ``observation_space`` / ``action_space``) whose worlds live in worker processes started with
    ``start_method`` (``"spawn"`` by default). Worker ``p`` holds a contiguous block of worlds.
    A worker that dies, or does not answer within ``timeout_s`` seconds (stopped, stuck), is a
    RuntimeError naming it, its process id and exit code, never a raw pipe error or a hang.
    """

    def __init__(self, env_fn: Callable[[], ParallelEnv], n_envs: int, n_procs: int,
                 start_method: str = "spawn", timeout_s: float = 600.0):
        if not (isinstance(timeout_s, (int, float)) and not isinstance(timeout_s, bool)
                and timeout_s > 0):
            raise ValueError(f"vector env: timeout_s={timeout_s!r}; allowed: a positive number "
                             "of seconds")
        self.timeout_s = float(timeout_s)
        if start_method == "fork":
            warnings.warn("start_method='fork': a process forked after a GL context was made "
                          "(any rendering) can crash; prefer 'spawn'", stacklevel=3)
        ctx = mp.get_context(start_method)
        n_procs = max(1, min(int(n_procs), int(n_envs)))
        counts = [n_envs // n_procs + (1 if p < n_envs % n_procs else 0) for p in range(n_procs)]
        self.world_starts = [sum(counts[:p]) for p in range(n_procs)]
        self.n_worlds = int(n_envs)
        self.closed = False
        self._conns, self._procs = [], []
        payload = cloudpickle.dumps(env_fn)
        try:
            for p, k in enumerate(counts):
                parent_end, child_end = ctx.Pipe()
                proc = ctx.Process(target=vec_worker, args=(child_end, payload, k), daemon=True,
                                   name=f"mimo_social-vec-{p}")
                proc.start()
                child_end.close()
                self._conns.append(parent_end)
                self._procs.append(proc)
            hello = self._gather()
        except BaseException:
            self.close()
            raise
        sizes = [h[0] for h in hello]
        self.slot_starts = [sum(sizes[:p]) for p in range(n_procs)] + [sum(sizes)]
        self.num_envs = sum(sizes)
        _, self.observation_space, self.action_space, self.metadata, self.render_mode = hello[0]
        self.single_observation_space = self.observation_space
        self.single_action_space = self.action_space

    def _gather(self) -> list:
        results, errors = [], []
        deadline = time.monotonic() + self.timeout_s
        for p, conn in enumerate(self._conns):  # read every answer, so the pipes stay in step
            try:
                if not self._answer_ready(p, conn, deadline):
                    errors.append(f"worker {p} (pid {self._procs[p].pid}) did not answer within "
                                  f"{self.timeout_s:g} s (alive: stopped or stuck); close this "
                                  "env and make a new one")
                    results.append(None)
                    continue
                status, value = conn.recv()
            except (EOFError, OSError):
                errors.append(self._died(p))
                results.append(None)
                continue
            if status == "error":
                errors.append(f"worker {p} failed:\n{value}")
            results.append(value)
        if errors:
            raise RuntimeError("vector env " + "\n".join(errors))
        return results

    def _answer_ready(self, p: int, conn, deadline: float) -> bool:
        """Wait for worker ``p``'s answer until ``deadline``, in short slices, so that a worker
        that dies meanwhile is seen at once (its pipe then reads EOF)."""
        while True:
            left = deadline - time.monotonic()
            if conn.poll(max(0.0, min(1.0, left))):
                return True
            if not self._procs[p].is_alive():
                return True            # recv() reads EOF: reported as died
            if left <= 0:
                return False

    def _died(self, p: int) -> str:
        proc = self._procs[p]
        proc.join(0.5)
        return (f"worker {p} (pid {proc.pid}) died (exit code {proc.exitcode}); close this env "
                "and make a new one")

    def _send_all(self, messages) -> None:
        dead = []
        for p, (conn, msg) in enumerate(zip(self._conns, messages)):
            try:
                conn.send(msg)
            except (BrokenPipeError, EOFError, OSError):
                dead.append(self._died(p))
        if dead:
            raise RuntimeError("vector env " + "\n".join(dead))

    def reset(self, seed: int | None = None, options: dict | None = None):
        self._send_all(("reset", (None if seed is None else int(seed) + start, options))
                       for start in self.world_starts)
        out = self._gather()
        obs = np.concatenate([o for o, _ in out])
        infos = [info for _, part in out for info in part]
        return obs, infos

    def step_async(self, actions) -> None:
        actions = np.asarray(actions)
        s = self.slot_starts
        self._send_all(("step", actions[s[p]:s[p + 1]]) for p in range(len(self._conns)))

    def step_wait(self):
        out = self._gather()
        obs, rews, terms, truncs, infos = zip(*out)
        return (np.concatenate(obs), np.concatenate(rews), np.concatenate(terms),
                np.concatenate(truncs), [info for part in infos for info in part])

    def step(self, actions):
        self.step_async(actions)
        return self.step_wait()

    def call_worlds(self, kind: str, name: str, args: tuple = (), kwargs: dict | None = None):
        """``call_world`` on every world, in world order."""
        self._send_all(("world", (kind, name, args, kwargs)) for _ in self._conns)
        return [r for part in self._gather() for r in part]

    def render(self):
        self._conns[0].send(("world", ("call", "render", (), None)))
        status, value = self._conns[0].recv()
        if status == "error":
            raise RuntimeError(f"vector env worker 0 failed:\n{value}")
        return value[0]

    def close_extras(self, **kwargs) -> None:
        stop_workers(self._conns, self._procs)
        self._conns, self._procs = [], []

    def close(self, **kwargs) -> None:
        if not self.closed:
            self.closed = True
            self.close_extras()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass


# -- the SB3 side -------------------------------------------------------------------------------
class SeededVecEnv(VecEnvWrapper):
    """SB3 ``VecEnv`` over SuperSuit's ``SB3VecEnvWrapper`` with working seeds (module docstring)."""

    def __init__(self, venv: SB3VecEnvWrapper):
        gym_venv = getattr(venv, "venv", None)
        if gym_venv is None or not hasattr(gym_venv, "step_wait"):
            raise TypeError("SeededVecEnv wraps SuperSuit's SB3VecEnvWrapper (its .venv is the "
                            f"gymnasium vector env); got {type(venv).__name__}")
        self.gym_venv = gym_venv
        if isinstance(gym_venv, SpawnConcatVecEnv):
            n_worlds = gym_venv.n_worlds
        elif hasattr(gym_venv, "vec_envs"):  # SuperSuit's ConcatVecEnv
            n_worlds = len(gym_venv.vec_envs)
        else:
            raise TypeError(f"unsupported vector env {type(gym_venv).__name__}")
        self.n_worlds = n_worlds
        self.agents_per_world = venv.num_envs // n_worlds
        self._closed = False
        super().__init__(venv)  # VecEnv.__init__: _seeds, _options, reset_infos, render_mode

    # seeds and options: stored, used by the next reset (SB3 2.9 semantics)
    def seed(self, seed: int | None = None) -> Sequence[int | None]:
        return VecEnv.seed(self, seed)

    def set_options(self, options: list[dict] | dict | None = None) -> None:
        VecEnv.set_options(self, options)

    def reset(self):
        seed = self._seeds[0]
        options = self._options[0] or None
        obs, infos = self.gym_venv.reset(seed=seed, options=options)
        self.reset_infos = [dict(info) for info in infos]
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self.gym_venv.step_async(actions)

    def step_wait(self):
        obs, rewards, terms, truncs, infos = self.gym_venv.step_wait()
        terms = np.asarray(terms, dtype=bool)
        truncs = np.asarray(truncs, dtype=bool)
        dones = terms | truncs
        infos = [dict(info) for info in infos]
        for i in np.flatnonzero(dones):
            infos[i]["TimeLimit.truncated"] = bool(truncs[i] and not terms[i])
        return obs, np.asarray(rewards, dtype=np.float32), dones, infos

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self.gym_venv.close()

    # per-world attributes and methods, repeated for each agent slot of the world
    def _worlds(self, kind: str, name: str, args: tuple = (), kwargs: dict | None = None) -> list:
        g = self.gym_venv
        if isinstance(g, SpawnConcatVecEnv):
            return g.call_worlds(kind, name, args, kwargs)
        return [call_world(m.par_env, kind, name, args, kwargs) for m in g.vec_envs]

    def _slots(self, per_world: list, indices: VecEnvIndices) -> list:
        k = self.agents_per_world
        return [per_world[i // k] for i in self._get_indices(indices)]

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        if attr_name == "render_mode":
            return [self.gym_venv.render_mode for _ in self._get_indices(indices)]
        return self._slots(self._worlds("get", attr_name), indices)

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        if indices is not None:
            raise NotImplementedError("set_attr sets a world's attribute for all its agents; "
                                      "pass indices=None")
        self._worlds("set", attr_name, (value,))

    def env_method(self, method_name: str, *method_args, indices: VecEnvIndices = None,
                   **method_kwargs) -> list[Any]:
        """Calls the method once per world; every agent slot of a world gets that result."""
        return self._slots(self._worlds("call", method_name, method_args, method_kwargs), indices)

    def env_is_wrapped(self, wrapper_class, indices: VecEnvIndices = None) -> list[bool]:
        # the slots are agents of PettingZoo worlds: no gymnasium wrapper is around them
        return [False for _ in self._get_indices(indices)]

    def get_images(self) -> Sequence[np.ndarray | None]:
        """One image per world (``render_mode="rgb_array"``)."""
        return self._worlds("call", "render")

    def render(self, mode: str | None = None) -> np.ndarray | None:
        return VecEnv.render(self, mode=mode)


def sb3_vec_env(env_fn: Callable[[], ParallelEnv], n_envs: int = 1, n_cpus: int = 0,
                start_method: str = "spawn") -> SeededVecEnv:
    """An SB3 VecEnv of ``n_envs`` worlds from ``env_fn`` with one slot per agent (module docstring).

    ``n_cpus=0`` runs the worlds in this process; ``n_cpus>=1`` in ``min(n_cpus, n_envs)`` worker
    processes started with ``start_method``.
    """
    if int(n_envs) != n_envs or n_envs < 1:
        raise ValueError(f"n_envs={n_envs!r}; allowed: an integer >= 1")
    if int(n_cpus) != n_cpus or n_cpus < 0:
        raise ValueError(f"n_cpus={n_cpus!r}; allowed: 0 (in-process) or the number of processes")
    n_envs, n_cpus = int(n_envs), int(n_cpus)
    if n_cpus == 0:
        venv = ss.concat_vec_envs_v1(world_vec_env(env_fn), num_vec_envs=n_envs, num_cpus=0,
                                     base_class="stable_baselines3")
    else:
        venv = SB3VecEnvWrapper(SpawnConcatVecEnv(env_fn, n_envs, n_cpus, start_method))
    return SeededVecEnv(venv)
