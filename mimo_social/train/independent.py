"""``--mode independent``: one SB3 policy per agent, all acting in the same worlds at the same time.

``n_envs`` worlds (:class:`WorldBatch`: in this process, or in ``n_cpus`` spawned worker processes
running :func:`world_worker`, each a contiguous block of worlds) are stepped in lockstep by a
:class:`~mimo_social.train.lockstep.VecLockstep`: every model's ``learn()`` runs in its own
thread on an SB3 VecEnv view of the batch (:func:`agent_vec_env`: slot ``w`` is the agent in
world ``w``, with the agent's own spaces: the agents may differ), the main thread steps the
worlds once every agent has posted its actions. The worlds are seeded once, from the first
agent's model seed (world ``w`` with ``seed + w``), so a run is the same with the worlds in this
process or in workers. Episodes (each agent's, from every world's ``episode`` infos),
evaluations and checkpoints are handled in the stepping thread while every model is parked; the
step counter is env steps summed over the worlds (``n_envs`` a batch step). Writes
``model_<agent>.zip``, ``best_model_<agent>.zip`` and
``checkpoints/model_<agent>_<steps>_steps.zip``.
A stop signal (:mod:`mimo_social.train.interrupt`; it reaches the main thread, which steps the
worlds) ends every learner at the same env step: the stepping thread raises :class:`Interrupted`,
which aborts the learner threads, and the models are saved as they stand. A world worker that
dies or hangs is a RuntimeError naming it.
"""

from __future__ import annotations

import functools
import multiprocessing as mp
import time
import traceback
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import cloudpickle
import numpy as np

from .envs import call_world, make_parallel_env, stop_workers
from .interrupt import Interrupted, workers_ignore_sigint
from .lockstep import LockstepError, VecLockstep, run_lockstep
from .progress import write_config
from .rollouts import evaluate_agents
from .runlog import RunLog, Schedule, first_update, rounding_note
from .single import warn

__all__ = ["train_independent", "world_batch", "WorldBlock", "WorldBatch", "world_worker",
           "agent_vec_env"]


# -- the worlds ---------------------------------------------------------------------------------
class WorldBlock:
    """Worlds (ParallelEnvs with Box or Discrete spaces, e.g. ``FlattenParallel``) stepped one
    after the other in this process: :class:`WorldBatch`'s worlds, or one worker's block of them.
    The agents of a world must end their episodes together (a LockstepError otherwise); a world
    whose episode ended is reset at once (seed None: its own random stream goes on), its agents'
    infos then hold ``terminal_observation`` and ``TimeLimit.truncated`` (SB3's keys)."""

    def __init__(self, worlds: Sequence):
        self.worlds = list(worlds)
        first = self.worlds[0]
        self.agents = list(first.possible_agents)
        self.obs_spaces = {a: first.observation_space(a) for a in self.agents}
        self.act_spaces = {a: first.action_space(a) for a in self.agents}
        self.render_mode = getattr(first, "render_mode", None)

    def describe(self) -> tuple:
        """(agents, observation spaces, action spaces, render mode)."""
        return self.agents, self.obs_spaces, self.act_spaces, self.render_mode

    def stack(self, per_world: Sequence[Mapping]) -> dict:
        """Each agent's observations, one row per world, in its space's dtype."""
        return {a: np.stack([np.asarray(o[a], dtype=self.obs_spaces[a].dtype) for o in per_world])
                for a in self.agents}

    def infos(self, infos: Mapping) -> dict:
        return {a: dict(infos.get(a) or {}) for a in self.agents}

    def reset(self, seeds: Sequence[int | None], options: dict | None = None):
        """``(obs, infos)`` after resetting world ``i`` with ``seeds[i]``."""
        out = [w.reset(seed=s, options=options) for w, s in zip(self.worlds, seeds)]
        return self.stack([o for o, _ in out]), [self.infos(i) for _, i in out]

    def step(self, actions: Mapping[str, np.ndarray]):
        """``(obs, rewards, dones, infos, reset_infos)``; ``actions``: each agent's, one row per
        world; ``rewards``: float64 (worlds, agents); ``dones``: the worlds that ended."""
        k, agents = len(self.worlds), self.agents
        rewards = np.zeros((k, len(agents)))
        terms, truncs = np.zeros((k, len(agents)), bool), np.zeros((k, len(agents)), bool)
        all_obs, all_infos, resets = [], [], []
        for i, world in enumerate(self.worlds):
            obs, rew, term, trunc, info = world.step({a: actions[a][i] for a in agents})
            rewards[i] = [rew[a] for a in agents]
            terms[i] = [bool(term.get(a, False)) for a in agents]
            truncs[i] = [bool(trunc.get(a, False)) for a in agents]
            info, reset_info = self.infos(info), {}
            ended = terms[i] | truncs[i]
            if ended.all():
                for j, a in enumerate(agents):
                    info[a]["terminal_observation"] = np.asarray(obs[a],
                                                                 self.obs_spaces[a].dtype)
                    info[a]["TimeLimit.truncated"] = bool(truncs[i, j] and not terms[i, j])
                obs, reset_info = world.reset()
                reset_info = self.infos(reset_info)
            elif ended.any():
                raise LockstepError(
                    f"world {i}: {[a for a, e in zip(agents, ended) if e]} ended their episode "
                    f"while {[a for a, e in zip(agents, ended) if not e]} go on; independent "
                    "learners need a world's agents to end their episodes together")
            all_obs.append(obs)
            all_infos.append(info)
            resets.append(reset_info)
        dones = (terms | truncs).all(axis=1)
        return self.stack(all_obs), rewards, dones, all_infos, resets

    def call(self, kind: str, name: str, args: tuple = (), kwargs: dict | None = None) -> list:
        """:func:`~mimo_social.train.envs.call_world` on every world."""
        return [call_world(w, kind, name, args, kwargs) for w in self.worlds]

    def close(self) -> None:
        for w in self.worlds:
            w.close()


def world_worker(conn, payload: bytes, n_worlds: int) -> None:
    """Process entry point of :class:`WorldBatch`: a :class:`WorldBlock` of ``n_worlds`` worlds
    built by the cloudpickled ``env_fn`` in ``payload``. Messages ``(command, args)``:
    ``reset``, ``step``, ``call`` (the block's methods) and ``close``; every answer is
    ``(status, value)``. Ignores SIGINT (the parent stops the run and closes the worker)."""
    import signal
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        env_fn = cloudpickle.loads(payload)
        block = WorldBlock([env_fn() for _ in range(n_worlds)])
        conn.send(("ok", block.describe()))
    except BaseException:  # noqa: BLE001 (reported to the parent)
        conn.send(("error", traceback.format_exc()))
        conn.close()
        return
    try:
        while True:
            try:
                cmd, args = conn.recv()
            except EOFError:        # the parent is gone
                break
            if cmd == "close":
                block.close()
                conn.send(("ok", None))
                break
            try:
                if cmd not in ("reset", "step", "call"):
                    raise ValueError(f"unknown command {cmd!r}")
                out = getattr(block, cmd)(*args)
            except Exception:  # noqa: BLE001 (reported to the parent)
                conn.send(("error", traceback.format_exc()))
            else:
                conn.send(("ok", out))
    finally:
        conn.close()


class WorldBatch:
    """``n_envs`` worlds built by ``env_fn`` (a ParallelEnv with Box or Discrete spaces per agent,
    e.g. ``FlattenParallel``; picklable by cloudpickle when ``n_procs > 0``), the batch of a
    :class:`~.lockstep.VecLockstep`. ``n_procs=0``: every world in this process; otherwise
    ``min(n_procs, n_envs)`` worker processes started with ``start_method`` (``spawn``: a GL
    context does not survive ``fork``), each stepping a contiguous block of worlds; the same
    seeds give the same worlds either way (world ``w`` is reset with ``seed + w``). A worker
    that dies or does not answer within ``timeout_s`` seconds is a RuntimeError naming it, never
    a hang.

    :meth:`step` also keeps each agent's episode return and length (a Monitor's ``episode``
    info, ``{"r", "l", "t"}``, in the agent's info of a world whose episode ended)."""

    def __init__(self, env_fn: Callable, n_envs: int = 1, n_procs: int = 0,
                 timeout_s: float = 600.0, start_method: str = "spawn"):
        if isinstance(n_envs, bool) or int(n_envs) != n_envs or n_envs < 1:
            raise ValueError(f"n_envs={n_envs!r}; allowed: an integer >= 1")
        if isinstance(n_procs, bool) or int(n_procs) != n_procs or n_procs < 0:
            raise ValueError(f"n_procs={n_procs!r}; allowed: 0 (in this process) or a number")
        if isinstance(timeout_s, bool) or not isinstance(timeout_s, (int, float)) \
                or not timeout_s > 0:
            raise ValueError(f"timeout_s={timeout_s!r}; allowed: a positive number of seconds")
        self.n_worlds, self.timeout_s = int(n_envs), float(timeout_s)
        self.local: WorldBlock | None = None
        self.conns: list = []
        self.procs: list = []
        self.broken: set[int] = set()    # workers that died or did not answer
        self.closed = False
        if n_procs == 0:
            self.local = WorldBlock([env_fn() for _ in range(self.n_worlds)])
            self.starts = [0, self.n_worlds]
            described = self.local.describe()
        else:
            n = min(int(n_procs), self.n_worlds)
            counts = [self.n_worlds // n + (1 if p < self.n_worlds % n else 0) for p in range(n)]
            self.starts = [sum(counts[:p]) for p in range(n + 1)]
            ctx = mp.get_context(start_method)
            payload = cloudpickle.dumps(env_fn)
            try:
                for p, k in enumerate(counts):
                    parent_end, child_end = ctx.Pipe()
                    proc = ctx.Process(target=world_worker, args=(child_end, payload, k),
                                       daemon=True, name=f"mimo_social-worlds-{p}")
                    proc.start()
                    child_end.close()
                    self.conns.append(parent_end)
                    self.procs.append(proc)
                described = self.gather()[0]
            except BaseException:
                self.close()
                raise
        self.possible_agents, self.obs_spaces, self.act_spaces, self.render_mode = described
        self.possible_agents = list(self.possible_agents)
        shape = (self.n_worlds, len(self.possible_agents))
        self.returns, self.lengths = np.zeros(shape), np.zeros(shape, np.int64)
        self.t0 = time.perf_counter()

    def observation_space(self, agent: str):
        return self.obs_spaces[agent]

    def action_space(self, agent: str):
        return self.act_spaces[agent]

    # the blocks
    def run(self, cmd: str, args: Sequence[tuple]) -> list:
        """``cmd`` on every block (``args[p]``: block ``p``'s arguments): the answers in order."""
        if self.local is not None:
            return [getattr(self.local, cmd)(*args[0])]
        for p, (conn, a) in enumerate(zip(self.conns, args)):
            try:
                conn.send((cmd, a))
            except (BrokenPipeError, EOFError, OSError):
                raise RuntimeError(self.died(p)) from None
        return self.gather()

    def gather(self) -> list:
        """Every worker's answer (all read, so that the pipes stay in step)."""
        results, errors = [], []
        deadline = time.monotonic() + self.timeout_s
        for p, conn in enumerate(self.conns):
            answer = self.answer(p, conn, deadline)
            if isinstance(answer, str):
                errors.append(answer)
                results.append(None)
                continue
            status, value = answer
            if status == "error":
                errors.append(f"world worker {p} (pid {self.procs[p].pid}) failed:\n{value}")
            results.append(value)
        if errors:
            raise RuntimeError("\n".join(errors))
        return results

    def answer(self, p: int, conn, deadline: float):
        """Worker ``p``'s ``(status, value)``, or a message saying it died or timed out."""
        while True:
            left = deadline - time.monotonic()
            try:
                if conn.poll(max(0.0, min(1.0, left))):
                    return conn.recv()
            except (EOFError, OSError):
                return self.died(p)
            if not self.procs[p].is_alive() and not conn.poll(0):
                return self.died(p)
            if left <= 0:
                self.broken.add(p)
                return (f"world worker {p} (pid {self.procs[p].pid}) did not answer within "
                        f"{self.timeout_s:g} s (alive: stopped or stuck); raise --worker-timeout "
                        "if its worlds are that slow")

    def died(self, p: int) -> str:
        self.broken.add(p)
        proc = self.procs[p]
        proc.join(0.5)
        return f"world worker {p} (pid {proc.pid}) died (exit code {proc.exitcode})"

    # the worlds
    def reset(self, seed: int | None = None, options: dict | None = None):
        """``(obs, infos)``: every world reset, world ``w`` with ``seed + w``."""
        s = self.starts
        out = self.run("reset", [([None if seed is None else int(seed) + w
                                   for w in range(s[p], s[p + 1])], options)
                                 for p in range(len(s) - 1)])
        self.returns[:] = 0.0
        self.lengths[:] = 0
        return ({a: np.concatenate([o[a] for o, _ in out]) for a in self.possible_agents},
                [i for _, infos in out for i in infos])

    def step(self, actions: Mapping[str, Any]):
        """``(obs, rewards, dones, infos, reset_infos)`` (:class:`~.lockstep.VecLockstep` says
        what each is); ``actions``: each agent's, one row per world; ``rewards``: each agent's
        float32 row."""
        acts = {}
        for a in self.possible_agents:
            acts[a] = np.asarray(actions[a], dtype=self.act_spaces[a].dtype)
            if acts[a].shape[:1] != (self.n_worlds,):
                raise ValueError(f"{a}: actions of shape {acts[a].shape}; expected one row per "
                                 f"world ({self.n_worlds})")
        s = self.starts
        out = self.run("step", [({a: v[s[p]:s[p + 1]] for a, v in acts.items()},)
                                for p in range(len(s) - 1)])
        obs = {a: np.concatenate([o[0][a] for o in out]) for a in self.possible_agents}
        rewards = np.concatenate([o[1] for o in out])
        dones = np.concatenate([o[2] for o in out])
        infos = [i for o in out for i in o[3]]
        reset_infos = [r for o in out for r in o[4]]
        self.returns += rewards
        self.lengths += 1
        t = round(time.perf_counter() - self.t0, 6)
        for w in np.flatnonzero(dones):
            for j, a in enumerate(self.possible_agents):
                infos[w][a]["episode"] = {"r": round(float(self.returns[w, j]), 6),
                                          "l": int(self.lengths[w, j]), "t": t}
        self.returns[dones] = 0.0
        self.lengths[dones] = 0
        return (obs, {a: rewards[:, j].astype(np.float32)
                      for j, a in enumerate(self.possible_agents)}, dones, infos, reset_infos)

    def call_worlds(self, kind: str, name: str, args: tuple = (),
                    kwargs: dict | None = None) -> list:
        """``get`` / ``set`` an attribute of, or ``call`` a method of, every world, in order."""
        blocks = len(self.starts) - 1
        return [r for part in self.run("call", [(kind, name, args, kwargs)] * blocks)
                for r in part]

    def close(self) -> None:
        """Close the worlds (ask every worker, then wait for them together; end a worker that
        did not answer at once)."""
        if self.closed:
            return
        self.closed = True
        if self.local is not None:
            self.local.close()
        stop_workers(self.conns, self.procs, self.broken)
        self.conns, self.procs = [], []


# -- each agent's SB3 VecEnv ----------------------------------------------------------------------
@functools.cache
def _agent_vec_env_class():
    """The class of :func:`agent_vec_env`, made on first use (SB3 is imported then: importing
    this module imports neither SB3 nor torch, which keeps the spawned world workers light)."""
    from stable_baselines3.common.vec_env import VecEnv

    class AgentVecEnv(VecEnv):
        """One agent's SB3 VecEnv over a :class:`~.lockstep.VecLockstep`: slot ``w`` is the agent
        in world ``w``, with the agent's own spaces. ``step_wait`` blocks until every agent has
        posted its actions and the serving thread has stepped the worlds (which reset a finished
        world themselves: ``terminal_observation``, ``TimeLimit.truncated`` and a Monitor's
        ``episode`` are in the slot's info); ``reset`` resets every world, the seed stored by
        ``seed()`` (SB3's semantics) going to the hub, which uses the first agent's."""

        def __init__(self, hub: VecLockstep, agent: str):
            self.hub, self.agent = hub, agent
            self.actions = None
            super().__init__(hub.n_envs, hub.env.observation_space(agent),
                             hub.env.action_space(agent))

        def reset(self):
            seed, options = self._seeds[0], self._options[0] or None
            obs, infos = self.hub.call(self.agent, "reset", (seed, options))
            self.reset_infos = list(infos)
            self._reset_seeds()
            self._reset_options()
            return obs

        def step_async(self, actions) -> None:
            self.actions = actions

        def step_wait(self):
            if self.actions is None:
                raise RuntimeError(f"{self!r}: step_wait() without step_async()")
            actions, self.actions = self.actions, None
            obs, rewards, dones, infos, reset_infos = self.hub.call(self.agent, "step", actions)
            for w in np.flatnonzero(dones):
                self.reset_infos[w] = reset_infos[w]
            return obs, rewards, dones, infos

        def close(self) -> None:
            """Forgets a pending action; the worlds belong to the hub's maker, which closes
            them once every learner is done."""
            self.actions = None

        def get_attr(self, attr_name: str, indices=None) -> list:
            chosen = self._get_indices(indices)
            if attr_name == "render_mode":
                return [self.hub.env.render_mode for _ in chosen]
            worlds = self.hub.call_worlds("get", attr_name)
            return [worlds[i] for i in chosen]

        def set_attr(self, attr_name: str, value, indices=None) -> None:
            if sorted(self._get_indices(indices)) != list(range(self.num_envs)):
                raise ValueError(f"set_attr({attr_name!r}) sets an attribute of whole worlds, "
                                 "shared by their agents: pass indices=None")
            self.hub.call_worlds("set", attr_name, (value,))

        def env_method(self, method_name: str, *method_args, indices=None,
                       **method_kwargs) -> list:
            """The method called once per world; the agent's slot of a world gets its result."""
            worlds = self.hub.call_worlds("call", method_name, method_args, method_kwargs)
            return [worlds[i] for i in self._get_indices(indices)]

        def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
            # a slot is an agent of a PettingZoo world: no Gymnasium wrapper is around it
            return [False for _ in self._get_indices(indices)]

        def get_images(self) -> list:
            """One image per world (``render_mode="rgb_array"``)."""
            return self.hub.call_worlds("call", "render")

        def __repr__(self) -> str:
            return f"AgentVecEnv({self.agent}, {self.num_envs} worlds)"

    return AgentVecEnv


def agent_vec_env(hub: VecLockstep, agent: str):
    """``agent``'s SB3 VecEnv over ``hub`` (one slot per world; its ``learn()`` must run in the
    agent's thread of :func:`~.lockstep.run_lockstep`)."""
    return _agent_vec_env_class()(hub, agent)


# -- training -------------------------------------------------------------------------------------
class _IndependentLog:
    """Each agent's finished episodes in every world, evaluations and checkpoints of the
    independent mode (runs in the stepping thread, every model parked). The step counter is the
    hub's env steps, summed over the worlds."""

    def __init__(self, log: RunLog, schedule: Schedule, models: dict, out: Path, stop=None):
        self.log, self.schedule, self.models, self.out = log, schedule, models, out
        self.stop = stop
        self.hub: VecLockstep | None = None

    @property
    def rows(self):
        return self.log.rows

    @property
    def eval_steps(self):
        return self.log.eval_steps

    def on_step(self, obs, rewards, dones, infos):
        n = self.hub.env_steps
        for w in np.flatnonzero(dones):   # slot order: world by world, agents in order
            for a in self.hub.order:
                info = infos[w][a]
                ep = info["episode"]
                self.log.episode(n, a, float(ep["r"]), int(ep["l"]), info.get("is_success"))
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


def world_batch(task: str, env_kwargs: Mapping[str, Any], n_envs: int = 1, n_cpus: int = 0,
                worker_timeout: float = 600.0) -> WorldBatch:
    """``n_envs`` worlds of ``task`` (flat observations, one space per agent), in this process
    (``n_cpus=0``) or in ``n_cpus`` spawned workers that ignore SIGINT (Ctrl-C stops the run
    through its parent)."""
    env_fn = functools.partial(make_parallel_env, task, **env_kwargs)
    if n_cpus == 0:
        return WorldBatch(env_fn, n_envs)
    with workers_ignore_sigint():
        return WorldBatch(env_fn, n_envs, n_cpus, timeout_s=worker_timeout)


def train_independent(cls, algo_kwargs, task, env_kwargs, steps, seed, out, eval_env,
                      eval_episodes, eval_seed, schedule, bar, t0, verbose, stop=None,
                      config=None, n_envs: int = 1, n_cpus: int = 0,
                      worker_timeout: float = 600.0):
    """Train one model per agent in lockstep on ``n_envs`` worlds (``n_cpus`` worker processes,
    0: in this process); returns ``(models, state)`` (``state.log.rows``: the evaluations).
    ``stop``: a :class:`~mimo_social.train.interrupt.StopSignals`."""
    from .encoders import policy_for

    normalize_obs = bool((config or {}).get("normalize_obs"))
    batch = world_batch(task, env_kwargs, n_envs, n_cpus, worker_timeout)
    log = None
    try:
        agents = list(batch.possible_agents)
        models: dict[str, Any] = {}
        log = RunLog(out, agents,
                     lambda k, det: evaluate_agents(models, eval_env, k, eval_seed, det),
                     lambda: [m.save(out / f"best_model_{a}.zip") for a, m in models.items()],
                     t0, bar, schedule, eval_seed)
        state = _IndependentLog(log, schedule, models, out, stop)
        hub = VecLockstep(batch, on_step=state.on_step)
        state.hub = hub
        for k, a in enumerate(agents):  # built in order: each seeds the global RNGs (SB3)
            venv = agent_vec_env(hub, a)
            policy, kw = policy_for(venv.observation_space, algo_kwargs, normalize_obs,
                                    str((config or {}).get("algo")) == "recurrent_ppo",
                                    float((config or {}).get("obs_min_std", 0.0)))
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
        if log is not None:
            log.close()
        batch.close()
    return models, state
