"""Shared factory code of the versioned env modules (``free_play_v0`` ...)."""

from __future__ import annotations

from pettingzoo.utils.conversions import parallel_to_aec

from ..core.env import MimoParallelEnv

TASK_ARGS = ("physics", "per_agent", "render_mode", "max_steps", "render_size")


def make_parallel(task_cls, n_agents=None, task_options=None, **kwargs) -> MimoParallelEnv:
    task = task_cls(task_cls.default_n_agents if n_agents is None else n_agents,
                    **(task_options or {}))
    return MimoParallelEnv(task, **kwargs)


def make_aec(task_cls, **kwargs):
    return parallel_to_aec(make_parallel(task_cls, **kwargs))
