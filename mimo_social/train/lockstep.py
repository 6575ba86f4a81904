"""Independent learners in shared worlds: one learner thread per agent, the worlds stepped in
lockstep by the thread that made them.

Two hubs share the turn-taking (the baton) below:

* :class:`Lockstep`: one ParallelEnv; each agent's learner sees a Gymnasium view of it
  (:class:`AgentView`).
* :class:`VecLockstep`: a batch of ``n_envs`` worlds (``possible_agents``, per-agent spaces,
  ``reset(seed, options)`` and ``step(actions)`` with one row per world); each agent's learner
  sees an SB3 VecEnv with one slot per world (:mod:`mimo_social.train.independent` builds both:
  its ``WorldBatch`` steps the worlds in this process or in spawned worker processes).

Every model's ``learn()`` runs in its own thread, a view's ``step``/``reset`` posts the agent's
request and blocks; once every agent that must act has posted, the main thread (the only one that
touches the worlds, so renderers keep their GL context) steps (or resets) them once and each agent
gets its own result. Threads take turns (a baton passed in agent order), so exactly one of them
runs at any moment: the global random generators of numpy and torch are used in the same order
every run (deterministic under a seed as far as SB3 is), and evaluations and checkpoints run in
the main thread while every model is parked between two env steps. Any SB3 algorithm works
unchanged. An exception in one thread (or a model that stops early) aborts the others with
:class:`LockstepAborted` / :class:`LockstepError`; nothing hangs.
"""

from __future__ import annotations

import threading
from typing import Any, Callable, Mapping

import gymnasium as gym
import numpy as np

__all__ = ["Lockstep", "VecLockstep", "AgentView", "LockstepError", "LockstepAborted",
           "run_lockstep"]


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

    def _posted(self) -> tuple[list[str], list[str]]:
        """(agents asking to step, agents asking to reset); a LockstepError if an agent has
        stopped while others still post."""
        active = [a for a in self.order if a not in self.finished]
        stepping = [a for a in active if self.request[a][0] == "step"]
        resetting = [a for a in active if self.request[a][0] == "reset"]
        if self.finished:
            gone = sorted(self.finished)
            raise LockstepError(
                f"{', '.join(gone)} stopped learning at env step {self.env_steps} while "
                f"{', '.join(active)} still want to {'step' if stepping else 'reset'}: every "
                "agent must train for the same number of steps with the same algorithm settings")
        return stepping, resetting

    def _reset_args(self) -> tuple[int | None, dict | None]:
        """The seed and options of a reset: the first given, in agent order."""
        seeds = [self.request[a][1][0] for a in self.order if self.request[a][1][0] is not None]
        options = [self.request[a][1][1] for a in self.order if self.request[a][1][1]]
        return (seeds[0] if seeds else None), (options[0] if options else None)

    def _operate(self) -> list[str]:
        """Every running agent has posted: step or reset the env, hand out the results."""
        stepping, resetting = self._posted()
        live = set(self.env.agents)
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
        seed, options = self._reset_args()
        obs, infos = self.env.reset(seed=seed, options=options)
        for a in self.order:
            self.result[a] = (obs[a], infos[a])
            self.request[a] = None
        if self.on_reset is not None:
            self.on_reset(obs, infos)
        return list(self.order)


class VecLockstep(Lockstep):
    """``n_envs`` worlds shared by one learner thread per agent: :class:`Lockstep`'s turns over a
    batch of worlds (``batch``: ``possible_agents``, ``n_worlds``, ``reset(seed, options) ->
    (obs, infos)`` and ``step(actions) -> (obs, rewards, dones, infos, reset_infos)`` with
    ``obs`` / ``rewards`` / ``actions`` dicts agent -> one row per world, ``dones`` one flag per
    world and ``infos`` / ``reset_infos`` one dict agent -> info per world; a world whose
    episode ended is reset by the batch itself).

    ``call(agent, "step", actions)`` (the agent's actions, one row per world) returns the
    agent's ``(obs, rewards, dones, infos, reset_infos)`` (one row or entry per world);
    ``call(agent, "reset", (seed, options))`` returns its ``(obs, infos)``. Every agent must ask
    for the same thing: all step or all reset (SB3 resets its VecEnv once, when ``learn()``
    starts). The reset's seed is the first one given, in agent order (world ``w`` gets ``seed +
    w``). :attr:`env_steps` counts env steps summed over the worlds (``n_envs`` a batch step).
    ``on_step(obs, rewards, dones, infos)`` / ``on_reset(obs, infos)`` run in the serving
    thread after each batch step / reset, every learner waiting.
    """

    def __init__(self, batch, on_step=None, on_reset=None, poll_s: float = 1.0):
        super().__init__(batch, on_step=on_step, on_reset=on_reset, poll_s=poll_s)
        self.n_envs = int(batch.n_worlds)
        self.batch_steps = 0
        self.owner = threading.current_thread()

    def call_worlds(self, kind: str, name: str, args: tuple = (), kwargs: dict | None = None):
        """``get`` / ``set`` an attribute of, or ``call`` a method of, every world (one result
        each), from the thread that made the hub only (the one that touches the worlds)."""
        if threading.current_thread() is not self.owner:
            raise LockstepError(f"{kind} {name!r} of the worlds from thread "
                                f"{threading.current_thread().name}: only the thread that made "
                                "the hub touches the worlds")
        return self.env.call_worlds(kind, name, args, kwargs)

    def _operate(self) -> list[str]:
        """Every agent has posted: step or reset every world once, hand out each agent's part."""
        stepping, resetting = self._posted()
        if stepping and resetting:
            raise LockstepError(
                f"agents {stepping} want to step and {resetting} to reset: the agents' vector "
                "envs must reset together (once, when every learn() starts)")
        if stepping:
            obs, rewards, dones, infos, reset_infos = self.env.step(
                {a: self.request[a][1] for a in self.order})
            self.env_steps += self.n_envs
            self.batch_steps += 1
            for a in self.order:
                self.result[a] = (obs[a], rewards[a], dones.copy(), [i[a] for i in infos],
                                  [r.get(a, {}) for r in reset_infos])
                self.request[a] = None
            if self.on_step is not None:
                self.on_step(obs, rewards, dones, infos)
            return list(self.order)
        seed, options = self._reset_args()
        obs, infos = self.env.reset(seed=seed, options=options)
        for a in self.order:
            self.result[a] = (obs[a], [i[a] for i in infos])
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

