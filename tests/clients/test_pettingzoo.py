"""PettingZoo's own test battery (pettingzoo.test) on every catalogue env, as its users run it:
the parallel API, seeding, ``max_cycles`` (PettingZoo's name for the episode cap), rendering
(``render_test`` builds the env with ``render_mode="human"`` first) and ``state_test`` (which reads
``state_space`` as a space attribute). The AEC API test runs in tests/conformance."""

import warnings

import numpy as np
import pytest
from gymnasium import spaces
from pettingzoo.test import (max_cycles_test, parallel_api_test, parallel_seed_test,
                             performance_benchmark, render_test, state_test)

from client_envs import SHORT, Module, aec, entries, parallel


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # PettingZoo's advice (infinite bounds ...)
        yield


@pytest.mark.parametrize("entry", entries())
def test_parallel_api_and_seed(entry):
    env = parallel(entry)
    parallel_api_test(env, num_cycles=2 * SHORT)
    env.close()
    parallel_seed_test(lambda: parallel(entry), num_cycles=SHORT + 4)


@pytest.mark.parametrize("entry", entries())
def test_max_cycles(entry):
    """``max_cycles`` is taken as ``max_steps`` (was: TypeError, an unknown agent setting)."""
    max_cycles_test(Module(entry))
    assert parallel(entry, max_steps=None, max_cycles=3).max_steps == 3


@pytest.mark.parametrize("entry", entries())
def test_render(entry):
    render_test(lambda **kw: aec(entry, render_size=(24, 32), **kw))


@pytest.mark.parametrize("entry", entries())
def test_state(entry):
    """PettingZoo's state_test: ``state_space`` a Box attribute holding every ``state()``."""
    state_test(aec(entry), parallel(entry), num_cycles=4)
    env = parallel(entry)
    assert isinstance(env.state_space, spaces.Box) and env.state_space is env.state_space
    assert env.state_space.shape == env.state().shape


def test_state_space_bounds_unit_quaternions():
    """The free joints' quaternions are bounded by [-1, 1]; positions are not."""
    from mimo_social.envs import free_play_v0
    env = free_play_v0.parallel_env(n_agents=2, max_steps=SHORT)
    m = env.world.model
    space = env.state_space
    free = np.flatnonzero(m.jnt_type == 0)            # mjJNT_FREE
    assert len(free) >= 2
    for j in free:
        adr = m.jnt_qposadr[j]
        assert np.all(space.low[adr + 3:adr + 7] == -1) and np.all(space.high[adr + 3:adr + 7] == 1)
        assert np.all(np.isinf(space.low[adr:adr + 3]))


@pytest.mark.slow
@pytest.mark.parametrize("entry", entries())
def test_performance_benchmark(entry):
    performance_benchmark(aec(entry, max_steps=1000))
