"""The motor age (``AgentConfig.motor_age_months``): a joint's motor strength at body age B and
motor age M is the volume-law strength of the body grown to M. The motor age changes torques and
muscle forces (and the developmental delays), never sizes, masses or passive joint parameters;
the body age changes sizes, masses and inertias, never the torques of a fixed motor age; the
default (None: the body's age) leaves every body bit for bit as it was."""

from __future__ import annotations

import numpy as np
import pytest

from mimo_social.body.tables import load_body
from mimo_social.core.config import AgentConfig, ConfigError
from mimo_social.core.delays import delay_steps, delays_ms
from mimo_social.envs import free_play_v0


def _model(**kw):
    env = free_play_v0.parallel_env(n_agents=1, **kw)
    return env.world.model, env.world.agents[0]


@pytest.mark.parametrize("hands", ["mitten", "five_fingers"])
def test_motor_age_changes_torques_not_sizes(hands):
    body = load_body(hands, age_months=6)
    both = load_body(hands, age_months=6, motor_age_months=12)
    motors = load_body(hands, age_months=12)
    assert both.geoms == body.geoms and both.segments == body.segments
    for j, b, m in zip(both.joints, body.joints, motors.joints):
        assert (j.stiffness, j.damping, j.armature, j.frictionloss) == (
            b.stiffness, b.damping, b.armature, b.frictionloss)
        assert (j.gear, j.fmax_neg, j.fmax_pos) == (m.gear, m.fmax_neg, m.fmax_pos)
    assert any(j.gear != b.gear for j, b in zip(both.joints, body.joints) if j.gear)
    m6, a = _model(hands=hands, age_months=6)
    m612, _ = _model(hands=hands, age_months=6, motor_age_months=12)
    m12, _ = _model(hands=hands, age_months=12)
    np.testing.assert_array_equal(m612.body_mass, m6.body_mass)
    np.testing.assert_array_equal(m612.body_inertia, m6.body_inertia)
    np.testing.assert_array_equal(m612.geom_size, m6.geom_size)
    np.testing.assert_array_equal(m612.jnt_stiffness, m6.jnt_stiffness)
    np.testing.assert_array_equal(m612.actuator_forcerange, m12.actuator_forcerange)
    assert not np.array_equal(m612.actuator_forcerange, m6.actuator_forcerange)


def test_body_age_changes_sizes_not_torques_at_a_fixed_motor_age():
    m6, _ = _model(age_months=6, motor_age_months=12)
    m12, _ = _model(age_months=12, motor_age_months=12)
    np.testing.assert_array_equal(m6.actuator_forcerange, m12.actuator_forcerange)
    np.testing.assert_array_equal(m6.actuator_ctrlrange, m12.actuator_ctrlrange)
    assert (m6.body_mass[1:] < m12.body_mass[1:]).sum() > 0.9 * (m6.nbody - 1)
    assert m6.body_mass.sum() < m12.body_mass.sum()
    assert not np.allclose(m6.body_inertia, m12.body_inertia)
    assert not np.allclose(m6.geom_size, m12.geom_size)


def test_muscle_forces_follow_the_motor_age():
    env = free_play_v0.parallel_env(n_agents=1, actuation="muscle", age_months=3,
                                    motor_age_months=24)
    fresh = free_play_v0.parallel_env(n_agents=1, actuation="muscle", age_months=24)
    body = free_play_v0.parallel_env(n_agents=1, actuation="muscle", age_months=3)
    np.testing.assert_array_equal(env.actuation[0].fmax, fresh.actuation[0].fmax)
    np.testing.assert_array_equal(env.actuation[0].stiffness, body.actuation[0].stiffness)
    assert (env.actuation[0].fmax > body.actuation[0].fmax).all()


def test_the_default_is_the_body_age_bit_for_bit():
    assert AgentConfig().motor_age_months is None
    assert load_body("mitten", motor_age_months=18) is load_body("mitten")
    assert load_body("mitten", age_months=7, motor_age_months=7) is load_body("mitten",
                                                                              age_months=7)
    assert AgentConfig(age_months=7).motor_age == 7
    assert AgentConfig().motor_age == 18
    assert AgentConfig(body="adult").motor_age is None


def test_developmental_delays_follow_the_motor_age():
    young = AgentConfig(age_months=0, motor_age_months=12, delays="developmental")
    assert delays_ms(young) == delays_ms(AgentConfig(age_months=12, delays="developmental"))
    assert delay_steps(young, 0.01)["vision"] < delay_steps(
        AgentConfig(age_months=0, delays="developmental"), 0.01)["vision"]


def test_bad_motor_ages_are_named():
    with pytest.raises(ConfigError, match=r"motor_age_months=40 not allowed; allowed: .*33"):
        AgentConfig(motor_age_months=40)
    with pytest.raises(ConfigError, match=r"motor_age_months=6 is for infant bodies; "
                                          r"body='adult' takes None"):
        AgentConfig(body="adult", motor_age_months=6)
    with pytest.raises(ConfigError, match=r"agent infant_0: motor_age_months=-2 not allowed"):
        free_play_v0.parallel_env(n_agents=1, motor_age_months=-2)
    with pytest.raises(ValueError, match="motor_age_months"):
        load_body("mitten", motor_age_months=50)
