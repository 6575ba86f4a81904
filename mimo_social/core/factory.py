"""The env factories every task offers: ``parallel_env``, ``env`` (AEC) and the options helper of
``scripted_env`` (each task's ``task.py`` calls these with its Task class)."""

from __future__ import annotations

import dataclasses
import difflib
from collections.abc import Mapping

from pettingzoo.utils.conversions import parallel_to_aec

from .config import AgentConfig
from .env import MimoParallelEnv
from ..util.checks import ConfigError, show

TASK_ARGS = ("physics", "per_agent", "render_mode", "max_steps", "render_size", "scene",
             "info_text")
#: what ``parallel_env(**kwargs)`` takes besides the agents' settings (:func:`agent_settings`)
ENV_KEYWORDS = ("n_agents", "task_options", *TASK_ARGS, "max_cycles")


def agent_settings() -> tuple[str, ...]:
    """The agents' settings ``parallel_env`` takes (given to every agent; ``per_agent`` gives
    them one agent at a time): the fields of :class:`~mimo_social.core.config.AgentConfig`."""
    return tuple(f.name for f in dataclasses.fields(AgentConfig))


def check_env_keywords(task_name: str, kwargs: Mapping) -> None:
    """A ConfigError for a keyword of ``parallel_env`` that is neither an env keyword
    (:data:`ENV_KEYWORDS`) nor an agent setting: it names the keyword and its value, the
    closest allowed name, and both lists."""
    allowed = (*ENV_KEYWORDS, *agent_settings())
    unknown = [k for k in kwargs if k not in allowed]
    if not unknown:
        return
    key = unknown[0]
    close = difflib.get_close_matches(str(key), allowed, n=1, cutoff=0.6)
    hint = f" (did you mean {close[0]}?)" if close else ""
    more = "".join(f"; also unknown: {k}={show(kwargs[k])}" for k in unknown[1:])
    raise ConfigError(
        f"{task_name}: unknown keyword {key}={show(kwargs[key])}{hint}{more}; allowed env "
        f"keywords: {', '.join(ENV_KEYWORDS)}; allowed agent settings (for every agent, or "
        f"one agent's in per_agent): {', '.join(agent_settings())}")


def make_parallel(task_cls, n_agents=None, task_options=None, **kwargs) -> MimoParallelEnv:
    """The task (``task_options``: a dict or the task's ``Options`` instance) in a ParallelEnv;
    ``kwargs``: the env's settings and the agents' settings (anything else: a ConfigError
    naming the allowed ones, :func:`check_env_keywords`)."""
    check_env_keywords(task_cls.name, kwargs)
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
