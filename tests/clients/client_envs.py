"""The cheap form of every catalogue env that the client tests run (imported by the test files
of this folder): vision off except one tiny-vision env (mirror: its learner sees its partner's
face through 16x16 eyes), short episodes."""

from __future__ import annotations

import numpy as np
import pytest

from mimo_social.envs.catalog import CATALOG

#: env name -> keyword arguments that keep it cheap (vision is off by default elsewhere)
CHEAP = {e.name: {} for e in CATALOG}
CHEAP["mirror"] = {"vision": {"width": 16, "height": 16}}
CHEAP["joint_attention"] = {"vision": False}
SHORT = 12   # max_steps of the client checks


def entries():
    """One pytest parameter per catalogue env."""
    return [pytest.param(e, id=e.name) for e in CATALOG]


def parallel(entry, **kwargs):
    """The cheap ParallelEnv of ``entry`` (every agent learning)."""
    return entry.parallel_env(**{"max_steps": SHORT, **CHEAP[entry.name], **kwargs})


def aec(entry, **kwargs):
    """The cheap AEC env of ``entry``."""
    return entry.module.env(**{"max_steps": SHORT, **CHEAP[entry.name], **kwargs})


class Module:
    """A stand-in for a ``<task>_v0`` module with the cheap settings put in: what PettingZoo's
    tests that take a module or an env function call (``parallel_env(**kw)``, ``env(**kw)``)."""

    def __init__(self, entry):
        self.entry = entry

    def parallel_env(self, **kwargs):
        return self.entry.parallel_env(**{**CHEAP[self.entry.name], **kwargs})

    def env(self, **kwargs):
        return self.entry.module.env(**{**CHEAP[self.entry.name], **kwargs})


def bang_bang(env, rng):
    """Actions of every live agent at the corners of its space (the hardest pushes)."""
    out = {}
    for a in env.agents:
        space = env.action_space(a)
        out[a] = _corner(space, rng)
    return out


def _corner(space, rng):
    from gymnasium import spaces
    if isinstance(space, spaces.Dict):
        return {k: _corner(s, rng) for k, s in space.spaces.items()}
    if isinstance(space, spaces.Discrete):
        return np.int64(space.start + rng.integers(space.n))
    return np.where(rng.random(space.shape) < 0.5, space.low, space.high).astype(space.dtype)
