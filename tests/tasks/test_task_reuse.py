"""A task object carries over to a second env: its index tables are bound to each env's world
(``Task.bind``), and no per-episode counter shadows a method of the task."""

from __future__ import annotations

import numpy as np
import pytest

from mimo_social.core.env import MimoParallelEnv
from mimo_social.envs.catalog import CATALOG
from mimo_social.envs.task_docs import task_class


def _episode(env, seed: int, steps: int) -> list:
    """The observations, rewards and infos of ``steps`` steps with the same seeded actions."""
    obs, infos = env.reset(seed=seed)
    out = [obs, infos]
    spaces = {a: env.action_space(a) for a in env.agents}
    for k, s in enumerate(spaces.values()):
        s.seed(seed + k)
    for _ in range(steps):
        if not env.agents:
            break
        out.append(env.step({a: spaces[a].sample() for a in env.agents}))
    return out


def _same(a, b) -> bool:
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    return bool(np.array_equal(np.asarray(a), np.asarray(b)))


@pytest.mark.parametrize("entry", CATALOG, ids=lambda e: e.name)
def test_one_task_object_serves_two_envs(entry):
    """Every task (a Handover reused raised TypeError: its step counter shadowed a method)."""
    cls = task_class(entry)
    task = cls(cls.default_n_agents)
    first = MimoParallelEnv(task, max_steps=30)
    before = _episode(first, seed=3, steps=12)
    # a second env from the same task object (building it calls the task's setup again)
    second = MimoParallelEnv(task, max_steps=30)
    assert task.bound_world is second.world
    assert _same(_episode(second, seed=3, steps=12), before)
    # back to the first env: its reset binds the task to its world again
    again = _episode(first, seed=3, steps=12)
    assert task.bound_world is first.world
    assert _same(again, before)
    first.close()
    second.close()
