"""Random sequences of ``reset(seed)``, ``step``, bad steps, ``close``, pickling, ``render`` and
``state`` against every env of the catalogue (and mirror with 8x8 eyes): each call does what is
documented or raises a clear error, whatever came before.

The documented behaviour held here:

* ``step()`` before the first ``reset()``: RuntimeError saying to reset; after the episode ended
  (every agent terminated or truncated): RuntimeError saying to reset; a bad action: ValueError
  naming the agent, the env unchanged;
* ``reset(seed=s)`` gives the same observations for the same ``s`` whatever happened before
  (steps, closes, pickled copies); a seed that is not None or an integer >= 0: ValueError naming
  ``seed``, the env unchanged;
* ``close()`` frees the renderers (GL contexts) and can be called any number of times; an env
  used after ``close()`` makes them again (reset, step, render all work);
* a pickled copy (taken at any point: before a reset, mid-episode, after the end or a close)
  continues exactly as the original would;
* ``render()`` returns None without ``render_mode``, else an RGB image of ``render_size``;
  ``state()`` is a float32 vector of ``state_space``'s shape.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings, strategies as st

from mimo_social.envs.catalog import CATALOG, entry

_COMMON = dict(deadline=None, derandomize=True, database=None,
               phases=[Phase.explicit, Phase.generate, Phase.shrink],
               suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
FAST = settings(max_examples=10, **_COMMON)
DEEP = settings(max_examples=150, **_COMMON)

MAX_STEPS = 3            # episodes end within a few calls
RENDER_SIZE = (12, 16)
#: every env of the catalogue without eyes (every second one with render_mode="rgb_array"),
#: mirror with 8x8 eyes (rendered too), and the one-learner form of each social task (its
#: partner scripted)
ENVS = ([e.name for e in CATALOG] + ["mirror_8x8_eyes"]
        + [f"{e.name}/scripted" for e in CATALOG if e.social])



def make_env(name: str):
    render = {"render_mode": "rgb_array", "render_size": RENDER_SIZE} \
        if name == "mirror_8x8_eyes" or ENVS.index(name) % 2 else {}
    if name == "mirror_8x8_eyes":
        return entry("mirror").parallel_env(vision={"width": 8, "height": 8},
                                            max_steps=MAX_STEPS, **render)
    if name.endswith("/scripted"):
        return entry(name.split("/")[0]).scripted_env(vision=False, max_steps=MAX_STEPS,
                                                      **render)
    return entry(name).parallel_env(vision=False, max_steps=MAX_STEPS, **render)


class Model:
    """What the env must be like: reset yet or not; the observations each seed gave."""

    def __init__(self, env):
        self.pristine = pickle.dumps(env)      # never reset: what "fresh" starts from
        self.env = env
        self.was_reset = False
        self.by_seed: dict[int, dict] = {}


@pytest.fixture(scope="module", params=ENVS)
def model(request):
    env = make_env(request.param)
    m = Model(env)
    yield m
    m.env.close()


def good_actions(env, seed=0):
    acts = {}
    for k, a in enumerate(env.agents):
        space = env.action_space(a)
        space.seed(seed + k)
        acts[a] = space.sample()
    return acts


def bad_actions(env):
    acts = good_actions(env)
    a = env.agents[0] if env.agents else env.possible_agents[0]
    acts[a] = float("nan")
    return acts, a


def assert_same_obs(x, y):
    assert x.keys() == y.keys()
    for a in x:
        assert x[a].keys() == y[a].keys()
        for k in x[a]:
            np.testing.assert_array_equal(x[a][k], y[a][k], err_msg=f"{a} {k}")


def assert_finite(obs, env=None):
    """Finite float observations, each in its declared space (``env`` given)."""
    for a, o in obs.items():
        for k, v in o.items():
            v = np.asarray(v)
            if v.dtype.kind == "f":
                assert np.isfinite(v).all(), f"{a}: {k} not finite"
            if env is not None:
                assert env.observation_space(a)[k].contains(v), f"{a}: {k} outside its space"


# -- the operations -------------------------------------------------------------------------------
def op_reset(m: Model, seed):
    env = m.env
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
        before = (env.steps, list(env.agents))
        with pytest.raises(ValueError, match="seed"):
            env.reset(seed=seed)
        assert (env.steps, list(env.agents)) == before
        return
    obs, infos = env.reset(seed=seed)
    m.was_reset = True
    assert env.agents == env.possible_agents and env.steps == 0
    assert list(obs) == env.possible_agents and list(infos) == env.possible_agents
    for a in env.agents:
        assert obs[a].keys() == env.observation_space(a).spaces.keys()
    assert_finite(obs, env)
    if seed is not None:
        if seed in m.by_seed:
            assert_same_obs(m.by_seed[seed], obs)
        else:
            m.by_seed[seed] = obs


def op_step(m: Model, seed):
    env = m.env
    acts = good_actions(env, seed)
    if not m.was_reset:
        with pytest.raises(RuntimeError, match=r"before reset\(\)"):
            env.step(acts)
        return
    if not env.agents:
        with pytest.raises(RuntimeError, match=r"episode ended.*reset\(\)"):
            env.step(acts)
        return
    alive, steps = list(env.agents), env.steps
    obs, rew, term, trunc, infos = env.step(acts)
    assert env.steps == steps + 1
    assert set(obs) == set(rew) == set(term) == set(trunc) == set(infos) == set(alive)
    assert all(isinstance(r, float) and math.isfinite(r) for r in rew.values())
    assert env.agents == [a for a in alive if not (term[a] or trunc[a])]
    if env.steps >= MAX_STEPS:
        assert env.agents == []
    if not any(i["instability"] for i in infos.values()):
        assert_finite(obs, env)


def op_bad_step(m: Model, _):
    env = m.env
    acts, agent = bad_actions(env)
    before = (env.steps, list(env.agents), env.world.data.qpos.copy())
    with pytest.raises((ValueError, RuntimeError)) as e:
        env.step(acts)
    msg = str(e.value)
    if not m.was_reset:
        assert "before reset()" in msg
    elif not env.agents:
        assert "episode ended" in msg
    else:
        assert isinstance(e.value, ValueError) and agent in msg and "'motors'" in msg, msg
    assert (env.steps, list(env.agents)) == before[:2]
    np.testing.assert_array_equal(env.world.data.qpos, before[2])


def op_close(m: Model, _):
    m.env.close()


def op_pickle(m: Model, switch):
    """A pickled copy continues as the original: one step (or the same error) on both; then the
    sequence goes on with the copy or the original."""
    env = m.env
    copy = pickle.loads(pickle.dumps(env))
    assert copy.agents == env.agents and copy.steps == env.steps
    if m.was_reset and env.agents:
        acts = good_actions(env, 7)
        a = env.step(acts)
        b = copy.step(acts)
        assert_same_obs(a[0], b[0])
        for x, y in zip(a[1:], b[1:4]):
            assert x == y
    if switch:
        env.close()
        m.env = copy
    else:
        copy.close()


def op_render(m: Model, _):
    env = m.env
    img = env.render()
    if env.render_mode is None:
        assert img is None
    else:
        assert img.shape == (*RENDER_SIZE, 3) and img.dtype == np.uint8


def op_state(m: Model, _):
    env = m.env
    s = env.state()
    space = env.state_space() if callable(env.state_space) else env.state_space
    assert s.shape == space.shape and s.dtype == np.float32


def op_fresh(m: Model, _):
    """A new env (a copy of one never reset): its first step must ask for a reset."""
    m.env.close()
    m.env = pickle.loads(m.pristine)
    m.was_reset = False


SEEDS = st.one_of(st.integers(0, 3), st.integers(0, 2 ** 32 - 1), st.none(),
                  st.sampled_from([-1, 1.5, "0", True, np.float64(2.0)]))
OPS = st.one_of(
    st.tuples(st.just(op_reset), SEEDS),
    st.tuples(st.just(op_step), st.integers(0, 3)),
    st.tuples(st.just(op_step), st.integers(0, 3)),
    st.tuples(st.just(op_step), st.integers(0, 3)),
    st.tuples(st.just(op_bad_step), st.none()),
    st.tuples(st.just(op_close), st.none()),
    st.tuples(st.just(op_pickle), st.booleans()),
    st.tuples(st.just(op_render), st.none()),
    st.tuples(st.just(op_state), st.none()),
    st.tuples(st.just(op_fresh), st.none()),
)


def run(m: Model, ops):
    for op, arg in ops:
        op(m, arg)


@FAST
@given(ops=st.lists(OPS, max_size=12))
def test_random_call_sequences_do_what_is_documented(model, ops):
    run(model, ops)


@pytest.mark.slow
@DEEP
@given(ops=st.lists(OPS, max_size=30))
def test_deep_random_call_sequences(model, ops):
    run(model, ops)


@pytest.mark.parametrize("name", ["reach", "mirror_8x8_eyes"])
def test_a_fixed_sequence_through_every_state(name):
    """The states one by one (what the random sequences mix): new, reset, mid-episode, ended,
    closed twice, used again, pickled while closed."""
    m = Model(make_env(name))
    run(m, [(op_step, 0), (op_bad_step, None), (op_render, None), (op_pickle, True),
            (op_step, 0), (op_reset, 5), (op_bad_step, None), (op_step, 1), (op_pickle, False),
            (op_step, 2), (op_step, 3), (op_step, 0), (op_bad_step, None), (op_close, None),
            (op_close, None), (op_render, None), (op_pickle, True), (op_reset, 5),
            (op_reset, -1), (op_reset, "0"), (op_step, 0), (op_state, None), (op_fresh, None),
            (op_step, 1), (op_reset, 5), (op_close, None)])
    assert m.was_reset and 5 in m.by_seed
