"""A batched env with its task: N worlds of a task's env on MuJoCo Warp that return rewards,
terminations, truncations and the task's infos, and reset finished worlds by themselves.

:class:`BatchedTaskEnv` takes a CPU env of the catalogue: a ParallelEnv (every agent learns)
or its one-learner form with scripted partners (``high_five_v0.scripted_env()``: the partners
act on the device, :mod:`mimo_social.gpu.partners`). Each step: the partners' commands from
the current data, the task's per-step hook, the physics (:class:`BatchedEnv`), the senses, the
task's rewards and terminations (:mod:`mimo_social.gpu.tasks`), truncation at the env's
``max_steps`` (per world) and, with ``autoreset``, the finished worlds reset in the same step.

**Resets** are the CPU env's: world ``w``'s ``e``-th episode (from 0) is the CPU env reset with
seed ``seed + w + e * nworld`` (its partners reset as the one-learner env resets them), its
state and the draws of the task's reset (reach: the ball, the head and eyes on it; high five:
the arms' start postures; the partner's targets and gains) copied into the world. That is host
work (a CPU reset per finished world: about 1 to 5 ms each), and the step that resets worlds
waits for the device to say which; the steps between resets stay on the device.

With ``reset_bank=K`` the ``K`` CPU resets of seeds ``seed`` .. ``seed + K - 1`` are made
once (at construction and at ``reset(seed=...)``) and kept: the episode that would take seed
``seed + n`` takes the kept start ``n mod K`` (:meth:`BatchedTaskEnv.seed_of` names it). No
CPU env is reset while stepping; while fewer than ``K`` episodes have started the episodes are
those of host resets, after that the starts repeat (``K`` distinct starts in all). The kept
starts live on the device, stacked (:mod:`mimo_social.gpu.stacking`): a reset copies its
worlds' rows there; the host only names which worlds and which starts (small integers).
"""

from __future__ import annotations

import numpy as np

from ..util.checks import check_int, check_seed
from .reset_bank import ResetBank
from .stacking import rows_to, stack_rows
from .batched import BatchedEnv
from .partners import batched_partner
from .tasks import task_class

__all__ = ["BatchedTaskEnv"]


class BatchedTaskEnv:
    """``nworld`` worlds of ``env``'s task on the Warp device ``device`` (None: a GPU when
    there is one, else the CPU). ``seed``: the first episodes' seeds (see the module); ``nconmax``
    / ``njmax``: :class:`BatchedEnv`'s. ``reset_bank``: None (a CPU reset per finished world)
    or the number of starts made once and kept (module docstring). ``learners``: the agents
    whose actions :meth:`step` takes; ``partners``: the scripted ones (batched)."""

    def __init__(self, env, nworld: int, device: str | None = None, seed: int = 0,
                 nconmax: int | None = None, njmax: int | None = None, touch: bool = True,
                 reset_bank: int | None = None):
        inner = env.unwrapped
        scripted = dict(getattr(env, "partners", {}) or {})
        self.env, self.inner = env, inner
        seed = check_int("BatchedTaskEnv", "seed", seed, 0)
        if reset_bank is not None:
            reset_bank = check_int("BatchedTaskEnv", "reset_bank", reset_bank, 1, 10 ** 7)
        task = task_class(inner.task.name)   # before the model goes to the device
        env.reset(seed=seed)
        self.batched = BatchedEnv(inner, nworld, device=device, seed=None, nconmax=nconmax,
                                  njmax=njmax, batch_fields=task.batch_fields, touch=touch)
        self.torch = self.batched.torch
        self.nworld = self.batched.nworld
        self.device_name = self.batched.device_name
        self.task = task(inner, self.batched)
        self.partners = {a: batched_partner(a, p, inner, self.batched)
                         for a, p in scripted.items()}
        self.agents = list(inner.possible_agents)
        self.learners = [a for a in self.agents if a not in self.partners]
        self.max_steps = int(inner.max_steps)
        self.dt = float(inner.dt)
        dev = self.batched.qpos.device
        self.steps = self.torch.zeros(self.nworld, dtype=self.torch.int64, device=dev)
        self._seed = seed
        self._episode = np.zeros(self.nworld, np.int64)
        self._was_reset = False
        self.bank = None if reset_bank is None else ResetBank(
            reset_bank, self._capture, lambda rows: rows_to(rows, self.torch, dev))
        if self.bank is not None:
            self.bank.fill(seed)

    # -- resets ----------------------------------------------------------------------------------
    def seed_of(self, world: int) -> int:
        """The seed of ``world``'s current episode (with a reset bank: of the kept start)."""
        n = int(world) + int(self._episode[world]) * self.nworld
        return self._seed + (n if self.bank is None else n % self.bank.size)

    def reset(self, seed: int | None = None, worlds=None):
        """Reset the worlds ``worlds`` (indices or a bool mask; None: all) with their seeds'
        CPU resets. ``seed`` (all worlds only): start the seeds over from it. Returns the
        observations (learner -> sense -> ``(nworld, size)``; rows of worlds not reset: not
        meaningful) and infos (the task's info keys, zeros)."""
        if seed is not None:
            if worlds is not None:
                raise ValueError("reset(seed=...) resets every world; give worlds=None")
            self._seed = check_seed(seed, "BatchedTaskEnv.reset")
            self._episode[:] = 0
            if self.bank is not None:
                self.bank.fill(self._seed)
        elif self._was_reset and worlds is None:
            self._episode += 1
        idx = np.arange(self.nworld) if worlds is None else self._indices(worlds)
        obs = self._load(idx)
        self._was_reset = True
        return self._learner_obs(obs), self._zero_infos()

    def _indices(self, worlds) -> np.ndarray:
        w = np.asarray(worlds.detach().cpu() if hasattr(worlds, "detach") else worlds)
        if w.dtype == bool:
            if w.shape != (self.nworld,):
                raise ValueError(f"worlds: a bool mask of shape {w.shape}; expected "
                                 f"({self.nworld},)")
            return np.flatnonzero(w)
        w = w.astype(np.int64).reshape(-1)
        if len(w) and (w.min() < 0 or w.max() >= self.nworld):
            raise ValueError(f"worlds {w.tolist()} not allowed; allowed: indices from 0 to "
                             f"{self.nworld - 1}")
        return w

    def _capture(self, seed: int) -> tuple:
        """The CPU env reset with ``seed``: its snapshot, the task's and each partner's draws."""
        self.env.reset(seed=seed)
        return (self.batched.snapshot(self.inner), self.task.capture(self.inner),
                {a: p.capture(self.inner) for a, p in self.partners.items()})

    def _load(self, idx: np.ndarray) -> dict:
        """Each world's start (its seed's CPU reset, or the kept one) copied into the world."""
        if not len(idx):
            return self.batched.load(idx, [])
        if self.bank is None:
            rows = stack_rows([self._capture(self.seed_of(w)) for w in idx.tolist()])
        else:
            kept = [self.seed_of(w) - self._seed for w in idx.tolist()]
            rows = self.bank.rows(self.torch.as_tensor(kept, dtype=self.torch.int64,
                                                       device=self.steps.device))
        snaps, task_caps, partner_caps = rows
        obs = self.batched.load_rows(idx, snaps)
        tidx = self.torch.as_tensor(idx, dtype=self.torch.int64, device=self.steps.device)
        self.task.load(tidx, task_caps)
        for a, p in self.partners.items():
            p.load(tidx, partner_caps[a])
        self.steps[tidx] = 0
        return obs

    # -- the loop --------------------------------------------------------------------------------
    def step(self, actions, autoreset: bool = True, expressions: dict | None = None):
        """One control step of every world. ``actions``: learner -> ``(nworld, n_controls)``
        motor values (torch or numpy); ``expressions``: learner -> ``(nworld,)`` expression ids
        (:meth:`BatchedEnv.step`; None: unchanged). Returns ``(obs, rewards, terminated, truncated,
        infos)``: obs learner -> sense -> ``(nworld, size)``; rewards learner -> ``(nworld,)``;
        terminated and truncated ``(nworld,)`` bool (the tasks end every agent together; an
        unstable world is terminated, ``infos["instability"]``); infos the task's keys ->
        ``(nworld,)`` (per-agent keys: learner -> ``(nworld,)``). With ``autoreset``, the
        worlds that finished are reset in this step (Gymnasium's same-step autoreset): their
        rows of obs are the new episode's first, ``infos["final_obs"]`` holds every world's
        obs of this step and ``infos["_final_obs"]`` which worlds finished."""
        if not self._was_reset:
            raise RuntimeError("step() called before reset(); call reset(seed=...) first")
        if not hasattr(actions, "keys") or set(actions) != set(self.learners):
            given = sorted(actions) if hasattr(actions, "keys") else type(actions).__name__
            extra = [a for a in (actions if hasattr(actions, "keys") else ())
                     if a in self.partners]
            why = f"; {extra} act by their scripted partners" if extra else ""
            raise ValueError(f"actions must be a dict with one (nworld, n_controls) array per "
                             f"learner of {self.learners}; got {given}{why}")
        full = dict(actions)
        for a, p in self.partners.items():
            full[a] = p.act()
        self.task.before_physics()
        if expressions and set(expressions) - set(self.learners):
            raise ValueError(f"expressions given for {sorted(set(expressions) - set(self.learners))}"
                             f"; allowed: the learners {self.learners}")
        obs, unstable = self.batched.step(full, reset_unstable=False, expressions=expressions)
        self.steps += 1
        rewards, terminated, task_infos = self.task.evaluate()
        terminated = terminated | unstable
        truncated = (self.steps >= self.max_steps) & ~terminated
        infos = self._infos(task_infos)
        infos["instability"] = unstable.to(self.torch.float32)
        obs = self._learner_obs(obs)
        rew = {a: rewards[:, self.agents.index(a)] for a in self.learners}
        if autoreset:
            done = terminated | truncated
            infos["_final_obs"] = done
            infos["final_obs"] = {a: {k: v.clone() for k, v in o.items()} for a, o in obs.items()}
            idx = np.flatnonzero(done.detach().cpu().numpy())
            if len(idx):
                self._episode[idx] += 1
                fresh = self._learner_obs(self._load(idx))
                rows = done
                for a in obs:
                    for k in obs[a]:
                        obs[a][k][rows] = fresh[a][k][rows]
        return obs, rew, terminated, truncated, infos

    def _learner_obs(self, obs: dict) -> dict:
        """The learners' senses and the task's own observations (self-body: its target)."""
        task = self.task.observe()
        return {a: {**obs[a], **task[self.agents.index(a)]} for a in self.learners}

    def _infos(self, task_infos: dict) -> dict:
        t = self.torch
        out = {}
        for k, v in task_infos.items():
            v = v.to(t.float32)
            if k in self.task.per_agent_infos:
                out[k] = {a: v[:, self.agents.index(a)] for a in self.learners}
            else:
                out[k] = v
        return out

    def _zero_infos(self) -> dict:
        t = self.torch
        z = t.zeros(self.nworld, dtype=t.float32, device=self.steps.device)
        out = {k: ({a: z.clone() for a in self.learners} if k in self.task.per_agent_infos
                   else z.clone()) for k in self.task.info_keys}
        out["instability"] = z.clone()
        return out

    def n_controls(self, agent: str) -> int:
        """The number of motor values in ``agent``'s actions."""
        return self.batched.n_controls(agent)
