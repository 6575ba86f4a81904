"""The step's quick paths (issue 28) behave as its general ones: a float32 or float64 action
array, an int expression id, a plain dict of actions, the proprioception's folded limit formula
and the actuation models' ``costs`` give what the general code gives, and what the quick checks
let through is still checked by the general path (errors name the agent and the field)."""

from __future__ import annotations

import collections
import types

import numpy as np
import pytest

from mimo_social.envs import free_play_v0
from mimo_social.expressions.faces import EXPRESSIONS
from mimo_social.util.indexing import as_slice


def _trajectory(kind: str, steps: int = 30):
    """qpos after ``steps`` steps of the same seeded actions, given as ``kind``."""
    env = free_play_v0.parallel_env(n_agents=1, vision=False, touch=False, expressions=False)
    env.reset(seed=3)
    rng = np.random.default_rng(3)
    n = env.action_space("infant_0").shape[0]
    for _ in range(steps):
        u = rng.uniform(-1.3, 1.3, n).astype(np.float32)     # some values beyond the bounds
        given = {"float32": u, "float64": u.astype(np.float64), "list": u.tolist(),
                 "big-endian": u.astype(">f8")}[kind]
        env.step({"infant_0": given})
    return env.world.data.qpos.copy()


@pytest.mark.parametrize("kind", ["float64", "list", "big-endian"])
def test_float32_actions_run_the_same_trajectory_as_any_other_form(kind):
    np.testing.assert_array_equal(_trajectory("float32"), _trajectory(kind))


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_non_finite_values_in_a_plain_float_array_are_refused(dtype, value):
    env = free_play_v0.parallel_env(n_agents=1, vision=False, touch=False, expressions=False)
    env.reset(seed=0)
    u = np.zeros(env.action_space("infant_0").shape[0], dtype)
    u[5] = value
    before = env.controls[0].copy()
    with pytest.raises(ValueError, match=r"infant_0: action field 'motors' has NaN/inf"):
        env.step({"infant_0": u})
    np.testing.assert_array_equal(env.controls[0], before)     # nothing applied


def test_a_float32_array_of_the_wrong_shape_is_refused():
    env = free_play_v0.parallel_env(n_agents=1, vision=False, touch=False, expressions=False)
    env.reset(seed=0)
    n = env.action_space("infant_0").shape[0]
    with pytest.raises(ValueError, match=rf"shape \({n + 1},\); expected \({n},\)"):
        env.step({"infant_0": np.zeros(n + 1, np.float32)})


def _expr_env():
    env = free_play_v0.parallel_env(n_agents=1, vision=False, touch=False, expressions=True,
                                    info_text=True)
    env.reset(seed=0)
    return env, np.zeros(env.action_space("infant_0")["motors"].shape[0], np.float32)


@pytest.mark.parametrize("given", [2, np.int64(2), np.uint8(2), np.int32(2), np.array(2),
                                   np.array([2])])
def test_every_integer_form_of_an_expression_is_read(given):
    env, u = _expr_env()
    _, _, _, _, infos = env.step({"infant_0": {"motors": u, "expression": given}})
    assert infos["infant_0"]["expression"] == EXPRESSIONS[2]
    assert env.world.expression_of(0) == 2


@pytest.mark.parametrize("given", [-1, 99, np.int8(-1), np.int64(7), True, 2.0, "2",
                                   np.array([1, 2])])
def test_an_expression_out_of_range_or_not_an_integer_is_refused(given):
    env, u = _expr_env()
    with pytest.raises(ValueError, match=r"infant_0: expression=.* not allowed; allowed: an "
                                         r"integer 0\.\."):
        env.step({"infant_0": {"motors": u, "expression": given}})


@pytest.mark.parametrize("wrap", [collections.OrderedDict, types.MappingProxyType,
                                  lambda d: collections.ChainMap(d)])
def test_actions_in_any_mapping_are_accepted(wrap):
    env, u = _expr_env()
    action = wrap({"motors": u, "expression": 1})
    env.step(wrap({"infant_0": action}))
    assert env.world.expression_of(0) == 1


def test_missing_and_unknown_agents_are_named():
    env = free_play_v0.parallel_env(n_agents=2, vision=False, touch=False, expressions=False)
    env.reset(seed=0)
    u = np.zeros(env.action_space("infant_0").shape[0], np.float32)
    with pytest.raises(ValueError, match=r"no action for live agent\(s\) \['infant_1'\]"):
        env.step({"infant_0": u})
    with pytest.raises(ValueError, match=r"unknown agent\(s\) \['infant_9'\]"):
        env.step({"infant_0": u, "infant_1": u, "infant_9": u})
    with pytest.raises(ValueError, match="actions must be a dict"):
        env.step([u, u])


@pytest.mark.parametrize("actuation", ["spring_damper", "muscle"])
def test_costs_equal_cost_and_weighted_cost(actuation):
    env = free_play_v0.parallel_env(n_agents=1, vision=False, touch=False, expressions=False,
                                    actuation=actuation)
    env.reset(seed=1)
    act = env.actuation[0]
    space = env.action_space("infant_0")
    space.seed(1)
    for _ in range(5):
        _, _, _, _, infos = env.step({"infant_0": space.sample()})
        u = env.controls[0]
        assert act.costs(u) == (act.cost(u), act.weighted_cost(u))
        assert (infos["infant_0"]["cost"], infos["infant_0"]["weighted_cost"]) == act.costs(u)
        other = np.linspace(-1, 1, len(u)) if actuation == "spring_damper" else u
        assert act.costs(other) == (act.cost(other), act.weighted_cost(other))


def test_proprioception_limit_sensors_match_their_definition():
    env = free_play_v0.parallel_env(n_agents=1, vision=False, touch=False)
    env.reset(seed=0)
    sense, d = env.senses[0][0], env.world.data
    lo, hi = env.world.agents[0].joint_range.T
    margin = np.deg2rad(sense.config.limit_margin_deg)
    rng = np.random.default_rng(0)
    adr = env.world.agents[0].qpos_adr
    for _ in range(20):
        d.qpos[adr] = rng.uniform(lo - 0.3, hi + 0.3)
        q = np.clip(d.qpos[adr], lo - np.pi / 2, hi + np.pi / 2)
        want = np.maximum(1 - (hi - q) / margin, 0) - np.maximum(1 - (q - lo) / margin, 0)
        got = sense.read(env.world.model, d)[sense.slices["limits"]]
        np.testing.assert_allclose(got, want.astype(np.float32), rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("ids, want", [([3, 4, 5], slice(3, 6)), ([7], slice(7, 8)),
                                       ([1, 3], None), ([5, 4], None), ([], None)])
def test_as_slice_reads_the_same_values(ids, want):
    got = as_slice(ids)
    if want is not None:
        assert got == want
    else:
        assert isinstance(got, np.ndarray)
    a = np.arange(10.0) * 1.5
    np.testing.assert_array_equal(a[got], a[np.asarray(ids, dtype=np.intp)])
