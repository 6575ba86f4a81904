"""Conformance: every env of the catalogue through the same PettingZoo and Gymnasium checks.

The envs come from :data:`mimo_social.envs.catalog.CATALOG` (a new entry is checked without
touching this file). Each check is short (tens of steps); task-specific behaviour lives in the
task's own test file.
"""

import pickle
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from pettingzoo.test import api_test, max_cycles_test, parallel_api_test, parallel_seed_test

import mimo_social  # noqa: F401  (registers the Gymnasium ids)
from mimo_social.core.random_actions import random_action_block
from mimo_social.envs.catalog import CATALOG

SHORT = 30   # max_steps of the API checks: a few episodes end within their cycles

#: (check, env name, form) -> why that check fails for a real bug of the env (strict xfail);
#: empty now: the pickled copies of standup, catch, joint attention and the HandOffer partner
#: stepped on differently until World pickled its MjData (with its model) whole
KNOWN_BUGS: dict[tuple[str, str, str], str] = {}


def _cases(check, entries=CATALOG, forms=("parallel",)):
    """One pytest parameter per (entry, form); known bugs are strict xfails."""
    cases = []
    for e in entries:
        for form in forms:
            if form == "scripted" and not e.social:
                continue
            reason = KNOWN_BUGS.get((check, e.name, form))
            marks = [pytest.mark.xfail(strict=True, reason=reason)] if reason else []
            name = e.name if len(forms) == 1 else f"{e.name}-{form}"
            cases.append(pytest.param(e, form, id=name, marks=marks))
    return cases


def _make(entry, form, **kwargs):
    return entry.scripted_env(**kwargs) if form == "scripted" else entry.parallel_env(**kwargs)


def _actions(env, n_steps, seed):
    """Seeded smooth random actions for the learners of ``env`` (its scripted partners act for
    themselves)."""
    block = random_action_block(env.unwrapped, n_steps, seed)
    return [{a: act[a] for a in env.possible_agents} for act in block]


def _step(env, actions):
    """One step with the actions of the live agents; a new episode (no new seed) when the last
    one ended, so a run has a fixed number of steps."""
    if not env.agents:
        return env.reset()
    return env.step({a: actions[a] for a in env.agents})


def assert_same(a, b, where="result"):
    """Nested dicts / sequences / arrays / scalars are equal, bit for bit."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), f"{where}: keys {a.keys()} != {b}"
        for k in a:
            assert_same(a[k], b[k], f"{where}[{k!r}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), f"{where}: lengths {len(a)} != {len(b)}"
        for k, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, f"{where}[{k}]")
    elif isinstance(a, (np.ndarray, np.generic, float, int)) and not isinstance(a, bool):
        np.testing.assert_array_equal(a, b, err_msg=where)
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"


# -- PettingZoo --------------------------------------------------------------------------------
@pytest.mark.parametrize("entry, form", _cases("parallel_api"))
def test_parallel_api(entry, form):
    env = entry.parallel_env(max_steps=SHORT)
    parallel_api_test(env, num_cycles=2 * SHORT)
    env.close()


@pytest.mark.parametrize("entry, form", _cases("aec_api"))
def test_aec_api(entry, form):
    env = entry.module.env(max_steps=SHORT)
    api_test(env, num_cycles=2 * SHORT)
    env.close()


@pytest.mark.parametrize("entry, form", _cases("parallel_seed"))
def test_parallel_seed(entry, form):
    parallel_seed_test(lambda: entry.parallel_env(max_steps=SHORT), num_cycles=SHORT + 10)


@pytest.mark.parametrize("entry, form", _cases("max_cycles"))
def test_max_cycles(entry, form):
    """PettingZoo's max_cycles test; the envs call the limit ``max_steps``."""
    class Module:
        @staticmethod
        def parallel_env(max_cycles):
            return entry.parallel_env(max_steps=max_cycles)

        @staticmethod
        def env(max_cycles):
            return entry.module.env(max_steps=max_cycles)

    max_cycles_test(Module)


@pytest.mark.parametrize("entry, form", _cases("state"))
def test_state_is_in_state_space(entry, form):
    """``state()`` lies in ``state_space`` after reset and every step, in the parallel and the
    AEC form (PettingZoo's own state_test runs in tests/clients)."""
    env = entry.parallel_env(max_steps=SHORT)
    space = env.state_space
    assert isinstance(space, gym.spaces.Box)
    env.reset(seed=0)
    assert space.contains(env.state())
    for actions in _actions(env, 10, seed=0):
        _step(env, actions)
        state = env.state()
        assert state.shape == space.shape and space.contains(state) and np.isfinite(state).all()
    aec = entry.module.env(max_steps=SHORT)
    aec.reset(seed=0)
    for agent in aec.agent_iter(2 * len(aec.possible_agents)):
        _, _, term, trunc, _ = aec.last(observe=False)
        aec.step(None if term or trunc else aec.action_space(agent).sample())
        assert space.contains(aec.state())
    env.close()
    aec.close()


# -- determinism and pickling ------------------------------------------------------------------
FORMS = ("parallel", "scripted")


@pytest.mark.parametrize("entry, form", _cases("determinism", forms=FORMS))
def test_same_seed_same_200_steps(entry, form):
    """Two envs reset with one seed and driven by the same seeded random actions give identical
    observations, rewards, ends and infos for 200 steps."""
    envs = [_make(entry, form), _make(entry, form)]
    actions = _actions(envs[0], 200, seed=5)
    assert_same(envs[0].reset(seed=5), envs[1].reset(seed=5), "reset")
    for k, act in enumerate(actions):
        assert_same(_step(envs[0], act), _step(envs[1], act), f"step {k}")
    for env in envs:
        env.close()


@pytest.mark.parametrize("entry, form", _cases("pickle", forms=FORMS))
def test_pickle_mid_episode(entry, form):
    """Pickled after 20 steps, the copy and the original step on identically for 30 more."""
    env = _make(entry, form)
    actions = _actions(env, 50, seed=2)
    env.reset(seed=2)
    for act in actions[:20]:
        _step(env, act)
    clone = pickle.loads(pickle.dumps(env))
    for k, act in enumerate(actions[20:], start=20):
        assert_same(_step(env, act), _step(clone, act), f"step {k}")
    env.close()
    clone.close()


# -- observations ------------------------------------------------------------------------------
@pytest.mark.parametrize("entry, form", _cases("observations", forms=FORMS))
def test_no_observation_is_an_empty_array(entry, form):
    """After a reset no agent observes an array of size 0 (a client reducing over every key,
    ``np.max`` say, fails on one: an agent whose joints are all held has no proprioception key
    at all), every observation lies in its agent's space with the same keys, and no agent of
    the world (scripted partners too) has a space of size 0."""
    env = _make(entry, form)
    obs, _ = env.reset(seed=0)
    inner = env.unwrapped
    for agent in inner.possible_agents:
        for key, space in inner.observation_space(agent).spaces.items():
            assert 0 not in space.shape, f"{agent}: space {key!r} is {space}"
    assert set(obs) == set(env.possible_agents)
    for agent, o in obs.items():
        space = env.observation_space(agent)
        assert set(o) == set(space.spaces), agent
        assert space.contains(o), agent
        for key, value in o.items():
            assert np.asarray(value).size > 0, f"{agent}: {key!r} has size 0"
            assert np.isfinite(np.max(value)), (agent, key)
    env.close()


# -- rendering ---------------------------------------------------------------------------------
@pytest.mark.parametrize("entry, form", _cases("render"))
def test_render_rgb_array(entry, form):
    env = entry.parallel_env(render_mode="rgb_array", render_size=(48, 64))
    env.reset(seed=0)
    env.step(_actions(env, 1, seed=0)[0])
    image = env.render()
    assert isinstance(image, np.ndarray) and image.dtype == np.uint8 and image.shape == (48, 64, 3)
    assert image.std() > 5                       # a scene, not a blank frame
    env.close()
    assert entry.parallel_env().render() is None  # no render_mode: nothing drawn


# -- Gymnasium ---------------------------------------------------------------------------------
@pytest.mark.parametrize("entry, form", _cases("check_env"))
def test_gymnasium_check_env(entry, form):
    env = gym.make(entry.gym_id).unwrapped
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # unbounded Box observations
        check_env(env, skip_render_check=True)
    env.close()


def test_every_registered_id_is_in_the_catalogue():
    ours = sorted(i for i in gym.registry if i.startswith("mimo_social/"))
    assert ours == sorted(i for e in CATALOG for i in e.gym_ids)
    assert len({e.name for e in CATALOG}) == len(CATALOG)
