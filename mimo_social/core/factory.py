"""The env factories every task offers: ``parallel_env``, ``env`` (AEC) and the options helper of
``scripted_env`` (each task's ``task.py`` calls these with its Task class)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

from pettingzoo.utils.conversions import parallel_to_aec

from .env import MimoParallelEnv
from ..util.checks import ConfigError

TASK_ARGS = ("physics", "per_agent", "render_mode", "max_steps", "render_size", "scene")


def make_parallel(task_cls, n_agents=None, task_options=None, **kwargs) -> MimoParallelEnv:
    """The task (``task_options``: a dict or the task's ``Options`` instance) in a ParallelEnv;
    ``kwargs``: the env's settings and the agents' settings."""
    task = task_cls(task_cls.default_n_agents if n_agents is None else n_agents, task_options)
    return MimoParallelEnv(task, **max_cycles_alias(kwargs))


def max_cycles_alias(kwargs: dict) -> dict:
    """``max_cycles`` (PettingZoo's name for the episode cap, e.g. its max_cycles_test) is taken
    as ``max_steps``; both at once is a ConfigError unless they agree."""
    if "max_cycles" not in kwargs:
        return kwargs
    kwargs = dict(kwargs)
    cycles = kwargs.pop("max_cycles")
    if kwargs.get("max_steps") is not None and kwargs["max_steps"] != cycles:
        raise ConfigError(f"env: max_cycles={cycles!r} and max_steps={kwargs['max_steps']!r} "
                          "given; give one (max_cycles is another name for max_steps)")
    kwargs["max_steps"] = cycles
    return kwargs


def make_aec(task_cls, **kwargs):
    return parallel_to_aec(make_parallel(task_cls, **kwargs))


def with_options(task_cls, task_options, **values):
    """``task_options`` (a dict, the task's ``Options`` or None) with ``values`` set: a dict's
    own entries win over ``values``; an ``Options`` instance gets them (checked)."""
    if isinstance(task_options, task_cls.Options):
        return dataclasses.replace(task_options, **values)
    if task_options is not None and not isinstance(task_options, Mapping):
        return task_options   # not options at all: the task's Options.of says what is allowed
    return {**values, **(task_options or {})}
