"""What step() does with the caller's action: reads it, never writes it or keeps it; rejects
what is not an array of numbers with an error naming the agent and the field; refuses to run
before the first reset()."""

from __future__ import annotations

import numpy as np
import pytest

from mimo_social.envs import free_play_v0, high_five_v0
from mimo_social.envs.catalog import CATALOG


def _env():
    env = free_play_v0.parallel_env(n_agents=1, expressions=False)
    env.reset(seed=0)
    return env


def test_a_read_only_float64_action_is_accepted_and_left_as_it_was():
    env = _env()
    n = env.action_space("infant_0").shape[0]
    u = np.full(n, 3.0)                      # out of range: the env clips its own copy
    u.flags.writeable = False
    env.step({"infant_0": u})
    np.testing.assert_array_equal(u, np.full(n, 3.0))
    assert env.controls[0].max() <= 1.0


def test_the_env_keeps_no_reference_to_the_callers_array():
    env = _env()
    n = env.action_space("infant_0").shape[0]
    u = np.full(n, 0.5)
    env.step({"infant_0": u})
    u[:] = -0.9                              # the caller reuses its buffer
    np.testing.assert_array_equal(env.controls[0], np.full(n, 0.5))
    assert env.controls[0] is not u


@pytest.mark.parametrize("bad, words", [
    ("abc", "not numbers"),
    (["0.5"] * 3, "not numbers"),            # numeric strings are not numbers
    ([[0.1, 0.2], [0.3]], "not an array of numbers"),
    ({"a": 1}, "not numbers"),
    (np.ones(3, bool), "not numbers"),
])
def test_what_is_not_an_array_of_numbers_names_agent_and_field(bad, words):
    env = _env()
    with pytest.raises(ValueError, match=rf"infant_0: action field 'motors' .*{words}.*allowed"):
        env.step({"infant_0": bad})


def test_a_dict_action_with_expressions_names_the_motors_field():
    env = high_five_v0.parallel_env()
    env.reset(seed=0)
    acts = {a: env.action_space(a).sample() for a in env.agents}
    acts["infant_1"] = {"motors": ["x"] * 8, "expression": 0}
    with pytest.raises(ValueError, match=r"infant_1: action field 'motors'"):
        env.step(acts)


@pytest.mark.parametrize("e", CATALOG, ids=[e.name for e in CATALOG])
def test_step_before_reset_says_to_reset(e):
    env = e.parallel_env()
    acts = {a: env.action_space(a).sample() for a in env.possible_agents}
    with pytest.raises(RuntimeError, match=r"before reset\(\)"):
        env.step(acts)
    env.reset(seed=0)
    env.step(acts)                            # and works once reset
