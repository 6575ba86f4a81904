"""Multi-agent training for ``mimo-social train | eval | compare`` (see docs/training_multi.md).

The social tasks of :data:`mimo_social.train.runner.MULTI_TASKS` are PettingZoo modules
``mimo_social.envs.<task>_v0`` with ``parallel_env(**kwargs)`` and ``scripted_env(partner=None,
**kwargs)``. Three ways to train them (``--mode``):

``shared`` (default): parameter sharing
    One SB3 policy acts for every agent. :func:`~mimo_social.train.vector.sb3_vec_env` turns
    ``n_envs`` worlds into one SB3 VecEnv with a slot per agent (SuperSuit underneath), so the
    policy sees each agent's observation as a separate sample. Every agent needs the same
    (flattened) observation and action space. ``--steps`` counts environment steps (summed over
    the worlds): SB3 runs ``steps * n_agents`` agent-transitions.

``independent``: one policy per agent, in the same world at the same time
    Each agent's SB3 model learns on a Gymnasium view of one shared ParallelEnv
    (:class:`AgentView`), all views stepped in lockstep by a :class:`Lockstep`: every model's
    ``learn()`` runs in its own thread, a view's ``step``/``reset`` posts the agent's request and
    blocks; once every agent that must act has posted, the main thread (the only one that touches
    the env, so renderers keep their GL context) steps (or resets) the env once and each agent
    gets its own result. Threads take turns (a baton passed in agent order), so exactly one of
    them runs at any moment: the global random generators of numpy and torch are used in the
    same order every run (deterministic under a seed as far as SB3 is), and evaluations and
    checkpoints run in the main thread while every model is parked between two env steps.
    Any SB3 algorithm works unchanged. An exception in one thread (or a model that stops
    early) aborts the others with :class:`LockstepAborted` / :class:`LockstepError`; nothing hangs.

``scripted``: one learner, the partner scripted
    ``SingleAgentEnv(module.scripted_env(**env_kwargs))`` through
    :func:`~mimo_social.core.wrappers.make_sb3_single`: the one-agent path with the task's
    default scripted partner.

Evaluation (every ``--eval-every`` steps and at the end) runs ``--eval-episodes`` deterministic
episodes on a separate env in which every learning agent acts with its own policy (scripted
partners keep their script). It gives per-agent returns and success rates (``is_success`` of the
agent's info on its last step); the summary columns average them across agents.
"""

from __future__ import annotations

import csv
import functools
import importlib
import importlib.util
import json
import math
import threading
import time
from pathlib import Path
from typing import Any, Callable, Mapping

import gymnasium as gym
import numpy as np

from .runner import (MULTI_TASKS, TASKS, EvalOutputs, TrainInputError, _algo_class, _json_default,
                     plot_learning_curve, write_progress)

__all__ = ["MODES", "DEFAULT_MODE", "task_module", "check_mode", "make_parallel_env",
           "make_scripted_env", "evaluate_agents", "train_multi", "evaluate_multi", "Lockstep",
           "AgentView", "LockstepError", "LockstepAborted", "run_lockstep", "agent_columns"]

MODES = ("shared", "independent", "scripted")
DEFAULT_MODE = "shared"


# -- tasks and modes -----------------------------------------------------------------------------
def task_module(task: str):
    """The PettingZoo module of a multi-agent task, else a TrainInputError naming the allowed
    tasks."""
    if task not in MULTI_TASKS:
        raise TrainInputError(f"multi-agent task {task!r} not allowed; allowed: "
                              f"{', '.join(MULTI_TASKS)}")
    name = MULTI_TASKS[task]
    try:
        module = importlib.import_module(name)
    except ModuleNotFoundError as e:
        if e.name is None or not name.startswith(e.name):
            raise  # the module exists but one of its own imports is missing
        here = [t for t, m in MULTI_TASKS.items() if importlib.util.find_spec(m) is not None]
        raise TrainInputError(f"task {task!r}: its module {name} is not in this checkout; "
                              f"multi-agent tasks available here: {', '.join(here) or 'none'} "
                              f"(allowed: {', '.join(MULTI_TASKS)}; one-agent: "
                              f"{', '.join(TASKS)})") from None
    missing = [f for f in ("parallel_env", "scripted_env")
               if not callable(getattr(module, f, None))]
    if missing:
        raise TrainInputError(f"task {task!r}: module {name} lacks {', '.join(missing)} "
                              "(a multi-agent task module needs parallel_env and scripted_env)")
    return module


def check_mode(task: str, mode: str | None) -> str | None:
    """The mode to use: ``None`` for one-agent tasks, one of :data:`MODES` for the others."""
    if task in TASKS:
        if mode not in (None, DEFAULT_MODE):
            raise TrainInputError(f"--mode {mode!r} is for the multi-agent tasks "
                                  f"({', '.join(MULTI_TASKS)}); {task!r} has one agent: leave "
                                  "--mode out")
        return None
    if task not in MULTI_TASKS:
        raise TrainInputError(f"task {task!r} not allowed; allowed: "
                              f"{', '.join([*TASKS, *MULTI_TASKS])}")
    mode = DEFAULT_MODE if mode is None else mode
    if mode not in MODES:
        raise TrainInputError(f"mode {mode!r} not allowed; allowed: {', '.join(MODES)}")
    return mode


def _with_render(env_kwargs: Mapping[str, Any], render_mode: str | None) -> dict:
    kw = dict(env_kwargs)
    if render_mode is not None:
        kw["render_mode"] = render_mode
    return kw


def make_parallel_env(task: str, render_mode: str | None = None, **env_kwargs):
    """``FlattenParallel(parallel_env(...))``: all agents, Box observations and actions."""
    from ..core.wrappers import FlattenParallel
    return FlattenParallel(task_module(task).parallel_env(**_with_render(env_kwargs, render_mode)))


def make_scripted_env(task: str, render_mode: str | None = None, **env_kwargs):
    """``FlattenParallel(scripted_env(...))``: the learner only (its partner scripted)."""
    from ..core.wrappers import FlattenParallel
    return FlattenParallel(task_module(task).scripted_env(**_with_render(env_kwargs, render_mode)))


def _scripted_gym(task: str, **env_kwargs):
    """The scripted task as a Gymnasium env for SB3 (the one-agent path)."""
    from ..core.gym_adapter import SingleAgentEnv
    from ..core.wrappers import make_sb3_single
    return make_sb3_single(SingleAgentEnv(task_module(task).scripted_env(**env_kwargs)))


def _check_shared_spaces(env, task: str) -> None:
    agents = env.possible_agents
    first = agents[0]
    for a in agents[1:]:
        for kind, space in (("observation", env.observation_space), ("action", env.action_space)):
            s0, s1 = space(first), space(a)
            if s0.shape != s1.shape or not (np.array_equal(s0.low, s1.low)
                                            and np.array_equal(s0.high, s1.high)):
                what = (f"shape {s0.shape} vs {s1.shape}" if s0.shape != s1.shape
                        else f"same shape {s0.shape}, different bounds")
                raise TrainInputError(
                    f"--mode shared needs every agent to have the same observation and action "
                    f"space; in {task!r} the flat {kind} spaces of {first} and {a} differ "
                    f"({what}). "
                    "Use --mode independent (one policy per agent) instead")


# -- evaluation ----------------------------------------------------------------------------------
def _motor_slicer(env) -> Callable[[str, np.ndarray], dict]:
    """Flat action -> ``{"motors": ...}`` for the recorder (its action-norm scalar)."""
    inner = env.unwrapped
    counts = {}
    for a in env.possible_agents:
        space = inner.action_space(a)
        motors = space["motors"] if hasattr(space, "spaces") and "motors" in space.spaces else space
        counts[a] = int(np.prod(motors.shape))
    return lambda a, act: {"motors": np.asarray(act).ravel()[:counts[a]]}


def run_episode(policies: Mapping[str, Any], env, seed: int | None, deterministic: bool = True,
                on_step=None) -> dict[str, tuple[float, int, bool | None]]:
    """One episode of a (flat) ParallelEnv; each agent acts with ``policies[agent]``.
    Returns ``{agent: (return, length, success or None)}``."""
    obs, infos = env.reset(seed=seed)
    if on_step is not None:
        on_step(None, None, obs, reset=True)
    out = {a: [0.0, 0, None] for a in env.possible_agents}
    while env.agents:
        actions = {a: policies[a].predict(obs[a], deterministic=deterministic)[0]
                   for a in env.agents}
        obs, rewards, terms, truncs, infos = env.step(actions)
        for a, r in rewards.items():
            out[a][0] += float(r)
            out[a][1] += 1
            if terms.get(a) or truncs.get(a):
                s = infos.get(a, {}).get("is_success")
                out[a][2] = None if s is None else bool(s)
        if on_step is not None:
            on_step(actions, rewards, obs, reset=False)
    return {a: tuple(v) for a, v in out.items()}


def evaluate_agents(policies: Mapping[str, Any], env, episodes: int, seed: int,
                    deterministic: bool = True, on_step=None) -> dict:
    """``episodes`` episodes (seeds ``seed, seed+1, ...``): per-agent and across-agent numbers.

    ``res["agents"][agent]`` has ``returns, lengths, return_mean, return_std, length_mean,
    success_rate``; ``res`` itself the same averaged across agents (``returns[k]``: the agents'
    mean return in episode ``k``; ``success_rate``: mean of the agents' rates)."""
    agents = list(env.possible_agents)
    per = {a: {"returns": [], "lengths": [], "successes": []} for a in agents}
    for k in range(int(episodes)):
        for a, (r, n, s) in run_episode(policies, env, seed + k, deterministic, on_step).items():
            per[a]["returns"].append(r)
            per[a]["lengths"].append(n)
            if s is not None:
                per[a]["successes"].append(s)
    res_agents = {}
    for a, d in per.items():
        res_agents[a] = {"returns": d["returns"], "lengths": d["lengths"],
                         "return_mean": float(np.mean(d["returns"])),
                         "return_std": float(np.std(d["returns"])),
                         "length_mean": float(np.mean(d["lengths"])),
                         "success_rate": (float(np.mean(d["successes"])) if d["successes"]
                                          else float("nan"))}
    mean_returns = np.mean([per[a]["returns"] for a in agents], axis=0)
    rates = [res_agents[a]["success_rate"] for a in agents]
    rates = [r for r in rates if not math.isnan(r)]
    return {"agents": res_agents, "returns": [float(x) for x in mean_returns],
            "return_mean": float(np.mean(mean_returns)), "return_std": float(np.std(mean_returns)),
            "length_mean": float(np.mean([res_agents[a]["length_mean"] for a in agents])),
            "success_rate": float(np.mean(rates)) if rates else float("nan")}


def agent_columns(res: dict) -> dict:
    """``eval_return_mean_<agent>`` and ``eval_success_rate_<agent>`` of an evaluation."""
    row = {}
    for a, r in res["agents"].items():
        row[f"eval_return_mean_{a}"] = r["return_mean"]
        row[f"eval_success_rate_{a}"] = r["success_rate"]
    return row


# -- run log: progress.csv, episodes.csv, best model, learning curve -----------------------------
class _RunLog:
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


class _Schedule:
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


def _sb3_callback(log: _RunLog, schedule: _Schedule, slot_agents: list[str], per_env_step: int,
                  save_checkpoint: Callable[[int], None]):
    """SB3 callback of the shared and scripted modes: episodes by slot, evaluations, checkpoints.
    ``per_env_step``: SB3 timesteps per environment step (the number of agent slots a world)."""
    from stable_baselines3.common.callbacks import BaseCallback

    class MultiAgentLog(BaseCallback):
        def _on_step(self) -> bool:
            n = self.num_timesteps // per_env_step
            for i, info in enumerate(self.locals.get("infos", ())):
                ep = info.get("episode")
                if ep is not None:
                    log.episode(n, slot_agents[i % len(slot_agents)], float(ep["r"]), int(ep["l"]),
                                info.get("is_success"))
            if log.bar is not None:
                log.bar.update(n - log.bar.n)
            if schedule.checkpoint_due(n):
                save_checkpoint(n)
            if schedule.eval_due(n):
                log.evaluate(n)
            return True

        def _on_training_end(self) -> None:  # after the last update
            n = self.num_timesteps // per_env_step
            if log.bar is not None:
                log.bar.update(n - log.bar.n)
            if schedule.final_checkpoint_due(n):
                save_checkpoint(n)
            log.evaluate(n)

    return MultiAgentLog()


# -- independent learners: a ParallelEnv stepped in lockstep by one thread per agent -------------
class LockstepError(RuntimeError):
    """The agents' threads cannot go on together (e.g. one stopped while another still steps)."""


class LockstepAborted(RuntimeError):
    """Raised in an agent's thread because another thread failed or the run was aborted."""


class Lockstep:
    """One ParallelEnv shared by one learner thread per agent (see the module docstring).

    Learner threads: ``enter(agent)`` first (waits for the agent's turn); ``call(agent, "step",
    action)`` / ``call(agent, "reset", (seed, options))`` post a request and return the agent's
    result once the env was stepped/reset; ``leave(agent, error)`` at the end. The thread that
    made the env runs :meth:`serve` until every learner has left: it alone steps and resets the env
    (renderers and GL contexts stay in that thread) and runs ``on_step(obs, rewards, terms,
    truncs, infos)`` / ``on_reset(obs, infos)`` while every learner waits. One thread runs at a
    time; :func:`run_lockstep` does all of this.
    """

    ENV = "<env>"   # the turn of the serving thread

    def __init__(self, env, on_step=None, on_reset=None, poll_s: float = 1.0):
        self.env = env
        self.order = list(env.possible_agents)
        self.on_step, self.on_reset, self.poll_s = on_step, on_reset, poll_s
        self.cond = threading.Condition()
        self.turn: str | None = self.order[0]
        self.request: dict[str, tuple | None] = {a: None for a in self.order}
        self.result: dict[str, Any] = {a: None for a in self.order}
        self.finished: set[str] = set()
        self.error: BaseException | None = None
        self.env_steps = 0

    def view(self, agent: str) -> "AgentView":
        return AgentView(self, agent)

    # learner threads
    def enter(self, agent: str) -> None:
        with self.cond:
            self._wait_turn(agent)

    def call(self, agent: str, kind: str, payload) -> Any:
        with self.cond:
            if self.error is not None:
                raise LockstepAborted(f"{agent}: lockstep aborted ({self.error!r})")
            if self.turn != agent or agent in self.finished:
                raise LockstepError(f"{agent} called {kind} out of turn (turn: {self.turn}); the "
                                    "views of a Lockstep must be used from its agents' threads")
            self.request[agent] = (kind, payload)
            self._pass_turn()
            self._wait_turn(agent)
            result, self.result[agent] = self.result[agent], None
            return result

    def leave(self, agent: str, error: BaseException | None = None) -> None:
        with self.cond:
            self.finished.add(agent)
            self.request[agent] = None
            if error is not None and self.error is None:
                self.error = error
            if self.turn == agent:
                self._pass_turn()
            self.cond.notify_all()

    def abort(self, reason: str = "aborted") -> None:
        with self.cond:
            if self.error is None:
                self.error = LockstepAborted(reason)
            self.cond.notify_all()

    # the serving thread
    def serve(self) -> None:
        """Step/reset the env whenever every running learner has posted; return once all have
        left or on an error (kept in :attr:`error`, every learner then gets LockstepAborted)."""
        with self.cond:
            while True:
                while self.turn != self.ENV and self.error is None and \
                        len(self.finished) < len(self.order):
                    self.cond.wait(self.poll_s)
                if self.error is not None or len(self.finished) == len(self.order):
                    self.cond.notify_all()
                    return
                try:
                    recipients = self._operate()
                except BaseException as e:  # noqa: BLE001 (handed to run_lockstep)
                    self.error = e
                    self.turn = None
                    self.cond.notify_all()
                    return
                self.turn = recipients[0] if recipients else None
                self.cond.notify_all()

    # internals (the lock is held)
    def _wait_turn(self, agent: str) -> None:
        while self.turn != agent and self.error is None:
            self.cond.wait(self.poll_s)
        if self.error is not None:
            raise LockstepAborted(f"{agent}: lockstep aborted ({self.error!r})")

    def _pass_turn(self) -> None:
        """To the next agent in order still owing a request, else to the serving thread."""
        self.turn = self.ENV
        for a in self.order:
            if a not in self.finished and self.request[a] is None:
                self.turn = a
                break
        if self.turn == self.ENV and len(self.finished) == len(self.order):
            self.turn = None
        self.cond.notify_all()

    def _operate(self) -> list[str]:
        """Every running agent has posted: step or reset the env, hand out the results."""
        active = [a for a in self.order if a not in self.finished]
        live = set(self.env.agents)
        stepping = [a for a in active if self.request[a][0] == "step"]
        resetting = [a for a in active if self.request[a][0] == "reset"]
        if self.finished:
            gone = sorted(self.finished)
            raise LockstepError(
                f"{', '.join(gone)} stopped learning at env step {self.env_steps} while "
                f"{', '.join(active)} still want to {'step' if stepping else 'reset'}: every "
                "agent must train for the same number of steps with the same algorithm settings")
        if stepping:
            if set(stepping) != live or not set(resetting).isdisjoint(live):
                raise LockstepError(
                    f"agents {stepping} want to step and {resetting} to reset, but the live "
                    f"agents of the episode are {sorted(live)}: agents must reset together")
            actions = {a: self.request[a][1] for a in stepping}
            obs, rewards, terms, truncs, infos = self.env.step(actions)
            self.env_steps += 1
            for a in stepping:
                self.result[a] = (obs[a], float(rewards[a]), bool(terms[a]), bool(truncs[a]),
                                  infos[a])
                self.request[a] = None
            if self.on_step is not None:
                self.on_step(obs, rewards, terms, truncs, infos)
            return stepping
        seeds = [self.request[a][1][0] for a in self.order if self.request[a][1][0] is not None]
        options = [self.request[a][1][1] for a in self.order if self.request[a][1][1]]
        obs, infos = self.env.reset(seed=seeds[0] if seeds else None,
                                    options=options[0] if options else None)
        for a in self.order:
            self.result[a] = (obs[a], infos[a])
            self.request[a] = None
        if self.on_reset is not None:
            self.on_reset(obs, infos)
        return list(self.order)


class AgentView(gym.Env):
    """Gymnasium view of one agent of a :class:`Lockstep`: ``reset``/``step`` block until every
    agent has posted, then return this agent's part of the result."""

    metadata = {"render_modes": []}

    def __init__(self, hub: Lockstep, agent: str):
        self.hub, self.agent = hub, agent
        self.observation_space = hub.env.observation_space(agent)
        self.action_space = hub.env.action_space(agent)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return self.hub.call(self.agent, "reset", (seed, options))

    def step(self, action):
        return self.hub.call(self.agent, "step", np.asarray(action, dtype=np.float32))

    def __repr__(self):
        return f"AgentView({self.agent})"


def run_lockstep(hub: Lockstep, jobs: Mapping[str, Callable[[], None]]) -> None:
    """Run ``jobs[agent]()`` (e.g. ``model.learn``) in one thread per agent while this thread
    serves the env of ``hub``; return when all have ended, else raise the first real error."""
    errors: dict[str, BaseException] = {}

    def target(agent, job):
        try:
            hub.enter(agent)
            job()
        except BaseException as e:  # noqa: BLE001 (handed to the serving thread)
            errors[agent] = e
            hub.leave(agent, e)
        else:
            hub.leave(agent)

    threads = [threading.Thread(target=target, args=(a, j), daemon=True, name=f"learn-{a}")
               for a, j in jobs.items()]
    for t in threads:
        t.start()
    try:
        hub.serve()
        for t in threads:
            while t.is_alive():
                t.join(0.2)
    except BaseException:
        hub.abort("interrupted")
        for t in threads:
            t.join(10)
        raise
    real = [e for e in errors.values() if not isinstance(e, LockstepAborted)]
    if not real and hub.error is not None and not isinstance(hub.error, LockstepAborted):
        real = [hub.error]   # raised by the env, a hook, or a learner stopping early
    if real or errors:
        raise (real or list(errors.values()))[0]


# -- training ------------------------------------------------------------------------------------
def train_multi(task: str, algo: str, steps: int, seed: int, out: Path, *, mode: str | None,
                eval_every: int, eval_episodes: int, checkpoint_every: int, progress: bool,
                env_kwargs: dict, algo_kwargs: dict, n_envs: int = 1, n_cpus: int = 0,
                verbose: int = 0, config: dict) -> dict:
    """The multi-agent part of :func:`mimo_social.train.runner.train` (arguments checked there)."""
    mode = check_mode(task, mode)
    if mode != "shared" and (n_envs != 1 or n_cpus != 0):
        raise TrainInputError(f"--n-envs/--n-cpus are for --mode shared; got n_envs={n_envs}, "
                              f"n_cpus={n_cpus} with --mode {mode}")
    cls = _algo_class(algo)
    module = task_module(task)
    config.update({"env_module": module.__name__, "mode": mode, "n_envs": n_envs,
                   "n_cpus": n_cpus})
    eval_env = (make_scripted_env if mode == "scripted" else make_parallel_env)(task, **env_kwargs)
    if mode == "shared":
        try:
            _check_shared_spaces(eval_env, task)
        except TrainInputError:
            eval_env.close()
            raise
    agents = list(eval_env.possible_agents)
    config["agents"] = agents
    if (mode == "shared" and algo == "sac"
            and algo_kwargs.get("buffer_size") == min(1_000_000, steps)
            and "buffer_size" not in config.get("algo_kwargs_given", ())):
        # SB3 counts every agent's transition: room for all of them (train's default is steps)
        algo_kwargs["buffer_size"] = min(1_000_000, steps * len(agents))
    config.pop("algo_kwargs_given", None)
    if mode == "independent":
        config["models"] = {a: f"model_{a}.zip" for a in agents}
    else:
        config["models"] = {a: "model.zip" for a in agents}
    (out / "config.json").write_text(json.dumps(config, indent=2, default=_json_default))
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=steps, unit="step", desc=f"{out.name}", dynamic_ncols=True)
    eval_seed = 10_000 + seed
    schedule = _Schedule(eval_every, checkpoint_every, steps)
    t0 = time.perf_counter()
    try:
        if mode == "independent":
            models, done = _train_independent(cls, algo_kwargs, task, env_kwargs, steps, seed, out,
                                              eval_env, eval_episodes, eval_seed, schedule, bar,
                                              t0, verbose)
            rows = done.rows
        else:
            model, log, venv = _train_one_policy(cls, algo_kwargs, module, task, mode, env_kwargs,
                                                 steps, seed, out, eval_env, eval_episodes,
                                                 eval_seed, schedule, bar, t0, verbose, n_envs,
                                                 n_cpus)
            rows = log.rows
    finally:
        eval_env.close()
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - t0
    timesteps = rows[-1]["timesteps"]
    config.update({"wall_time_s": round(wall, 1), "timesteps_done": int(timesteps)})
    (out / "config.json").write_text(json.dumps(config, indent=2, default=_json_default))
    models_out = ({a: str(out / f"model_{a}.zip") for a in agents} if mode == "independent"
                  else {a: str(out / "model.zip") for a in agents})
    return {"out": str(out), "model": models_out[agents[0]], "models": models_out,
            "mode": mode, "agents": agents, "wall_time_s": wall, "timesteps": int(timesteps),
            "last_eval": rows[-1], "rows": rows}


def _train_one_policy(cls, algo_kwargs, module, task, mode, env_kwargs, steps, seed, out, eval_env,
                      eval_episodes, eval_seed, schedule, bar, t0, verbose, n_envs, n_cpus):
    """shared (one policy, one VecEnv slot per agent) and scripted (one learner) modes."""
    from stable_baselines3.common.vec_env import DummyVecEnv, VecMonitor

    agents = list(eval_env.possible_agents)
    if mode == "shared":
        from .vector import sb3_vec_env
        env_fn = functools.partial(module.parallel_env, **env_kwargs)
        venv = VecMonitor(sb3_vec_env(env_fn, n_envs=n_envs, n_cpus=n_cpus))
        per_env_step = len(agents)
    else:
        from stable_baselines3.common.monitor import Monitor
        venv = DummyVecEnv([lambda: Monitor(_scripted_gym(task, **env_kwargs))])
        per_env_step = 1
    try:
        model = cls("MlpPolicy", venv, seed=seed, device="cpu", verbose=verbose, **algo_kwargs)

        def evaluate():
            return evaluate_agents({a: model for a in agents}, eval_env, eval_episodes, eval_seed)

        def checkpoint(n):
            (out / "checkpoints").mkdir(exist_ok=True)
            model.save(out / "checkpoints" / f"model_{n}_steps.zip")

        log = _RunLog(out, agents, evaluate, lambda: model.save(out / "best_model.zip"), t0, bar)
        try:
            cb = _sb3_callback(log, schedule, agents, per_env_step, checkpoint)
            model.learn(total_timesteps=steps * per_env_step, callback=cb)
        finally:
            log.close()
        model.save(out / "model.zip")
    finally:
        venv.close()
    return model, log, venv


class _IndependentLog:
    """Episode returns of the shared env, evaluations and checkpoints of the independent mode
    (runs in the stepping thread, every model parked)."""

    def __init__(self, log: _RunLog, schedule: _Schedule, models: dict, out: Path):
        self.log, self.schedule, self.models, self.out = log, schedule, models, out
        self.hub: Lockstep | None = None
        self.returns = {a: 0.0 for a in models}
        self.lengths = {a: 0 for a in models}

    @property
    def rows(self):
        return self.log.rows

    def on_reset(self, obs, infos):
        self.returns = {a: 0.0 for a in self.models}
        self.lengths = {a: 0 for a in self.models}

    def on_step(self, obs, rewards, terms, truncs, infos):
        n = self.hub.env_steps
        for a, r in rewards.items():
            self.returns[a] += float(r)
            self.lengths[a] += 1
            if terms.get(a) or truncs.get(a):
                self.log.episode(n, a, self.returns[a], self.lengths[a],
                                 infos.get(a, {}).get("is_success"))
        if self.log.bar is not None:
            self.log.bar.update(n - self.log.bar.n)
        if self.schedule.checkpoint_due(n):
            self.checkpoint(n)
        if self.schedule.eval_due(n):
            self.log.evaluate(n)

    def checkpoint(self, n: int) -> None:
        (self.out / "checkpoints").mkdir(exist_ok=True)
        for a, m in self.models.items():
            m.save(self.out / "checkpoints" / f"model_{a}_{n}_steps.zip")


def _train_independent(cls, algo_kwargs, task, env_kwargs, steps, seed, out, eval_env,
                       eval_episodes, eval_seed, schedule, bar, t0, verbose):
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv

    env = make_parallel_env(task, **env_kwargs)
    agents = list(env.possible_agents)
    models: dict[str, Any] = {}
    log = _RunLog(out, agents, lambda: evaluate_agents(models, eval_env, eval_episodes, eval_seed),
                  lambda: [m.save(out / f"best_model_{a}.zip") for a, m in models.items()], t0, bar)
    state = _IndependentLog(log, schedule, models, out)
    hub = Lockstep(env, on_step=state.on_step, on_reset=state.on_reset)
    state.hub = hub
    try:
        for k, a in enumerate(agents):  # built in order: each seeds the global RNGs (SB3)
            view = hub.view(a)
            venv = DummyVecEnv([lambda v=view: Monitor(v)])
            models[a] = cls("MlpPolicy", venv, seed=seed + k, device="cpu", verbose=verbose,
                            **algo_kwargs)
        run_lockstep(hub, {a: functools.partial(models[a].learn, total_timesteps=steps)
                           for a in agents})
        n = hub.env_steps   # every model has made its last update
        if schedule.final_checkpoint_due(n):
            state.checkpoint(n)
        log.evaluate(n)
        for a, m in models.items():
            m.save(out / f"model_{a}.zip")
    finally:
        log.close()
        env.close()
    return models, state


# -- evaluation of a saved run --------------------------------------------------------------------
def _load_policies(run: Path, config: dict, model: str) -> tuple[dict, dict]:
    cls = _algo_class(config["algo"])
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


def evaluate_multi(run: Path, config: dict, episodes: int, *, model: str, seed: int,
                   deterministic: bool, record, video, frames, frame_every: int,
                   env_kwargs: Mapping[str, Any] | None) -> dict:
    """The multi-agent part of :func:`mimo_social.train.runner.evaluate`."""
    policies, paths = _load_policies(run, config, model)
    kw = dict(config.get("env_kwargs", {}))
    kw.update(env_kwargs or {})
    want_frames = video is not None or frames is not None
    make = make_scripted_env if config["mode"] == "scripted" else make_parallel_env
    env = make(config["task"], render_mode="rgb_array" if want_frames else None, **kw)
    inner = env.unwrapped
    outputs = EvalOutputs(env, inner, record, video, frames, frame_every)
    motors = _motor_slicer(env)

    def on_step(actions, rewards, obs, reset):
        if reset:
            outputs.on_reset()
        else:
            outputs.on_step({a: motors(a, act) for a, act in actions.items()}, rewards)

    t0 = time.perf_counter()
    try:
        res = evaluate_agents(policies, env, episodes, seed, deterministic, on_step)
    finally:
        outputs.close()
        env.close()
    res.update({"task": config["task"], "algo": config["algo"], "mode": config["mode"],
                "model": paths[next(iter(paths))], "models": paths, "episodes": episodes,
                "deterministic": deterministic, "seed": seed,
                "wall_time_s": round(time.perf_counter() - t0, 2)})
    for key, value in (("record", record), ("video", video), ("frames", frames)):
        if value is not None:
            res[key] = str(value)
    (run / "eval_results.json").write_text(json.dumps(res, indent=2, default=float))
    return res
