"""Bad input gets an error that names the agent, the field and what is allowed."""

import numpy as np
import pytest

from mimo_social.envs import free_play_v0, high_five_v0
from mimo_social.core.config import ConfigError


@pytest.fixture
def env():
    e = free_play_v0.parallel_env(n_agents=2)
    e.reset(seed=0)
    return e


def good(env):
    return {a: {"motors": np.zeros(44, np.float32), "expression": 0} for a in env.agents}


def test_wrong_action_shape(env):
    act = good(env)
    act["infant_1"]["motors"] = np.zeros(43)
    with pytest.raises(ValueError, match=r"infant_1.*shape \(43,\).*\(44,\)"):
        env.step(act)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_nan_and_inf_actions(env, bad):
    act = good(env)
    act["infant_0"]["motors"][3] = bad
    with pytest.raises(ValueError, match=r"infant_0.*NaN/inf.*finite"):
        env.step(act)


def test_out_of_range_controls_are_clipped(env):
    act = good(env)
    act["infant_0"]["motors"][:] = 5.0
    env.step(act)
    a = env.world.agents[0]
    np.testing.assert_allclose(env.world.data.ctrl[a.actuator_ids],
                               env.world.model.actuator_ctrlrange[a.actuator_ids, 1])


def test_unknown_and_missing_agents(env):
    act = good(env)
    act["infant_7"] = act["infant_0"]
    with pytest.raises(ValueError, match=r"unknown agent.*infant_7.*infant_0"):
        env.step(act)
    act = good(env)
    del act["infant_1"]
    with pytest.raises(ValueError, match=r"no action for live agent.*infant_1"):
        env.step(act)
    with pytest.raises(KeyError, match="unknown agent"):
        env.action_space("baby")


@pytest.mark.parametrize("expr", [7, -1, 2.5, "happy"])
def test_expression_out_of_range(env, expr):
    act = good(env)
    act["infant_0"]["expression"] = expr
    with pytest.raises(ValueError, match=r"infant_0: expression.*0\.\.6.*neutral"):
        env.step(act)


def test_action_without_expression_when_expressions_are_on(env):
    act = good(env)
    act["infant_0"] = np.zeros(44, np.float32)
    with pytest.raises(ValueError, match="'motors' and 'expression'"):
        env.step(act)


@pytest.mark.parametrize("kwargs, pattern", [
    ({"hands": "claws"}, r"hands='claws'.*mitten"),
    ({"actuation": "hydraulic"}, r"actuation.*spring_damper"),
    ({"posture": "flying"}, r"posture.*standing"),
    ({"colour": 3}, r"unknown keyword colour=3.*allowed"),
    ({"proprioception": {"components": ["qpos", "smell"]}}, r"proprioception.*smell"),
    ({"proprioception": {"rate": 3}}, r"unknown setting.*rate"),
    ({"vestibular": 3}, r"vestibular=3.*allowed"),
    ({"touch": {"density": 100}}, r"touch: density=100.*0.05 to 8"),
    ({"touch": {"response": "gaussian"}}, r"response.*spread_linear"),
    ({"vision": {"width": 3}}, r"vision: width=3.*8 to 2048"),
    ({"vision": {"every": 0}}, r"every=0"),
    ({"vision": {"fov": 90}}, r"infant_0: vision: unknown setting.*fov.*allowed.*width"),
    ({"touch": "yes"}, r"infant_0: touch='yes'; allowed: False, True or a mapping of.*density"),
    ({"physics": {"timestep": 1.0}}, r"timestep.*0.0001 to 0.006"),
    ({"physics": {"integrator": "rk4"}}, r"unknown setting.*integrator"),
    ({"physics": {"jacobian": "fast"}}, r"jacobian.*dense"),
    ({"per_agent": [{}]}, r"per_agent must be a list of 2"),
    ({"per_agent": [{}, {"hands": "x"}]}, r"infant_1.*hands"),
    ({"n_agents": 9}, r"n_agents=9.*1 to 8"),
    ({"task_options": {"props": True, "pets": 2}}, r"unknown task option.*pets"),
    ({"max_steps": 0}, r"max_steps"),
    ({"proprioception": False, "vestibular": False}, r"every sense is off"),
])
def test_bad_configuration(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        free_play_v0.parallel_env(**kwargs)


def test_config_error_is_a_value_error():
    assert issubclass(ConfigError, ValueError)
    with pytest.raises(ValueError, match=r"n_agents=3.*2 to 2"):
        high_five_v0.parallel_env(n_agents=3)


def test_step_after_the_end_needs_a_reset():
    e = free_play_v0.parallel_env(n_agents=1, max_steps=2, expressions=False)
    e.reset(seed=0)
    for _ in range(2):
        e.step({"infant_0": np.zeros(44, np.float32)})
    with pytest.raises(RuntimeError, match="reset"):
        e.step({"infant_0": np.zeros(44, np.float32)})
