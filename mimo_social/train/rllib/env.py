"""The envs RLlib samples from: every task of the training catalogue as an RLlib
``MultiAgentEnv``, made from a name of Ray's tune registry inside each env runner.

``env_name(task)``
    ``"mimo_social/<task>"``, the name :func:`register_rllib_envs` gives each task (of
    :data:`~mimo_social.train.tasks.ALL_TASKS`) in Ray's tune registry.
``make_rllib_env(config)``
    The env creator registered under those names. ``config`` (RLlib's ``env_config``, an
    ``EnvContext`` in a runner) holds ``task``, ``mode`` (``shared``, ``independent``,
    ``scripted``, or None for a one-agent task), ``env_kwargs`` and optionally ``flat`` (default
    False) and ``frame_stack`` (default 1). It returns a :class:`MimoMultiAgentEnv` around
    :func:`learner_env`. :class:`CatalogEnv` is the same as a class (``CatalogEnv(env_config)``):
    what ``build_config`` hands RLlib.
``learner_env(task, mode, *, flat=False, frame_stack=1, **env_kwargs)``
    ``FlattenParallel`` of the task's ParallelEnv: every agent (``shared``, ``independent``), the
    learner with its scripted partner (``scripted``: the module's ``scripted_env()``), or the
    one agent of a one-agent task. An agent with eyes sees the image ``Dict`` of
    :class:`~mimo_social.core.wrappers.ImageDict` (each eye ``uint8`` channel-first
    ``(3 * frame_stack, H, W)``, the other senses one float32 ``"vector"``: what the CNN module
    :mod:`~mimo_social.train.rllib.module` takes) unless ``flat``; every other observation is
    one float32 Box (with ``flat``, eye images scaled to [0, 1] in it, as the SB3 path's
    ``--flat-obs``). Actions are a Box (``Discrete`` for a face-only agent).
``flat_env(task, mode, **env_kwargs)``
    :func:`learner_env` with ``flat=True``: every observation one Box.

Ray starts each env runner as its own process and calls the creator there, so each env (and
its renderer's GL context, with vision on) is made in the process that steps it. This module
imports ray (only the runners and :mod:`mimo_social.train.rllib` users load it).
"""

from __future__ import annotations

from typing import Any, Mapping

from gymnasium import spaces
from ray.rllib.env.multi_agent_env import MultiAgentEnv

from ...core.wrappers import FlattenParallel
from ...envs.catalog import entry
from ..tasks import ALL_TASKS, TASKS, check_mode, task_module

__all__ = ["EPISODE_KEY", "CatalogEnv", "MimoMultiAgentEnv", "env_name", "flat_env",
           "learner_env", "make_rllib_env", "register_rllib_envs"]

PREFIX = "mimo_social/"
#: the info key under which an agent's last step carries its episode's (return, length)
EPISODE_KEY = "rllib_episode"


def env_name(task: str) -> str:
    """The tune-registry name of a task's RLlib env."""
    return PREFIX + task


def learner_env(task: str, mode: str | None = None, render_mode: str | None = None, *,
                flat: bool = False, frame_stack: int = 1, **env_kwargs) -> FlattenParallel:
    """The ParallelEnv a mode learns on: image Dicts for agents with eyes unless ``flat`` (see
    the module docstring)."""
    mode = check_mode(task, mode)
    kw = dict(env_kwargs)
    if render_mode is not None:
        kw["render_mode"] = render_mode
    if task in TASKS:  # one agent: its ParallelEnv (what the Gymnasium id wraps)
        e = entry(task)
        par = e.scripted_env(**{**dict(e.gym_defaults), **kw})
    else:
        module = task_module(task)
        make = module.scripted_env if mode == "scripted" else module.parallel_env
        par = make(**kw)
    try:
        return FlattenParallel(par, keep_images=not flat, frame_stack=int(frame_stack))
    except (TypeError, ValueError):
        par.close()
        raise


def flat_env(task: str, mode: str | None = None, render_mode: str | None = None,
             **env_kwargs) -> FlattenParallel:
    """The ParallelEnv a mode learns on with every observation one flat Box."""
    return learner_env(task, mode, render_mode, flat=True, **env_kwargs)


class MimoMultiAgentEnv(MultiAgentEnv):
    """A :func:`learner_env` as an RLlib ``MultiAgentEnv``: ``agents`` follows the live agents,
    ``"__all__"`` ends the episode once every agent is done, ``render()`` is the env's frame. An
    agent's info on its last step adds ``EPISODE_KEY: (return, length)`` of its episode."""

    def __init__(self, par_env: FlattenParallel):
        super().__init__()
        self.par_env = par_env
        self.possible_agents = list(par_env.possible_agents)
        self.agents = list(self.possible_agents)
        self.observation_spaces = {a: par_env.observation_space(a) for a in self.possible_agents}
        self.action_spaces = {a: par_env.action_space(a) for a in self.possible_agents}
        self.observation_space = spaces.Dict(self.observation_spaces)
        self.action_space = spaces.Dict(self.action_spaces)
        self.render_mode = getattr(par_env, "render_mode", None)
        self.metadata = dict(getattr(par_env, "metadata", {}))
        self._sums: dict[str, list] = {}

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        obs, infos = self.par_env.reset(seed=seed, options=options)
        self.agents = list(self.par_env.agents)
        self._sums = {a: [0.0, 0] for a in self.agents}
        return obs, dict(infos or {})

    def step(self, action_dict: Mapping[str, Any]):
        obs, rewards, terms, truncs, infos = self.par_env.step(dict(action_dict))
        self.agents = list(self.par_env.agents)
        terms, truncs, infos = dict(terms), dict(truncs), dict(infos)
        for a, r in rewards.items():
            s = self._sums.setdefault(a, [0.0, 0])
            s[0] += float(r)
            s[1] += 1
            if terms.get(a) or truncs.get(a):  # the agent's whole episode, for the run log
                infos[a] = {**infos.get(a, {}), EPISODE_KEY: (s[0], s[1])}
        over = not self.agents
        terms["__all__"] = over and all(terms.values())
        truncs["__all__"] = over and not terms["__all__"]
        return obs, rewards, terms, truncs, dict(infos)

    def render(self):
        return self.par_env.render()

    def close(self):
        self.par_env.close()


def _env_from_config(config: Mapping[str, Any] | None) -> FlattenParallel:
    config = dict(config or {})
    return learner_env(config["task"], config.get("mode"), render_mode=config.get("render_mode"),
                       flat=bool(config.get("flat", False)),
                       frame_stack=int(config.get("frame_stack", 1)),
                       **dict(config.get("env_kwargs") or {}))


def make_rllib_env(config: Mapping[str, Any] | None = None) -> MimoMultiAgentEnv:
    """The env creator of the tune registry: ``config`` holds ``task``, ``mode``, ``env_kwargs``
    (and optionally ``flat``, ``frame_stack``, ``render_mode``)."""
    return MimoMultiAgentEnv(_env_from_config(config))


class CatalogEnv(MimoMultiAgentEnv):
    """:func:`make_rllib_env` as a class (``CatalogEnv(env_config)``), what
    :func:`~mimo_social.train.rllib.config.build_config` gives RLlib: a class travels to the
    env runners by value, so it does not depend on the tune registry, whose names are kept per
    Ray job (a process that joins a cluster a second time would look them up under the old
    job)."""

    def __init__(self, config: Mapping[str, Any] | None = None):
        super().__init__(_env_from_config(config))


def register_rllib_envs() -> list[str]:
    """Register :func:`make_rllib_env` under :func:`env_name` for every task (idempotent; the
    registry lives in the Ray cluster, so call it after ``ray.init``)."""
    from ray.tune.registry import register_env

    names = []
    for task in ALL_TASKS:
        register_env(env_name(task), make_rllib_env)
        names.append(env_name(task))
    return names
