"""Proprioception reads the simulation: each part of the observation equals MuJoCo's data for the
agent's own joints (found here by name in the compiled model, not through the sense's own
tables), and the limit sensors have the documented sign: +1 at a joint's upper limit, -1 at its
lower one, rising linearly over the last ``limit_margin_deg``, 0 in between."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from mimo_social.core.random_actions import random_action_block
from mimo_social.envs import free_play_v0
from mimo_social.senses.proprioception import COMPONENTS, DEFAULT_COMPONENTS

AGENTS = ("infant_0", "infant_1")


def _env(**kwargs):
    env = free_play_v0.parallel_env(n_agents=2, expressions=False, **kwargs)
    env.reset(seed=3)
    return env


def _joints(env, i):
    """Per joint of agent ``i`` (the documented order of the observation): model joint id,
    qpos address, dof address, found by the joint's name in the compiled model."""
    m = env.world.model
    agent = env.possible_agents[i]
    ids = []
    for name in env.world.agents[i].joint_names:
        jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{agent}/{name}")
        assert jid >= 0, f"{agent}/{name} not in the model"
        ids.append(jid)
    ids = np.array(ids)
    return ids, m.jnt_qposadr[ids], m.jnt_dofadr[ids]


def _parts(env, i, obs, components=DEFAULT_COMPONENTS):
    """The observation cut into its parts: the components in the order of COMPONENTS, one value
    per joint each (``face``: 7, the expressions; ``actuation``: the rest)."""
    n = len(env.world.agents[i].joint_names)
    out, start = {}, 0
    for c in COMPONENTS:
        if c not in components:
            continue
        size = {"face": 7, "actuation": len(obs) - start - 7 * ("face" in components)}.get(c, n)
        out[c] = obs[start:start + size]
        start += size
    assert start == len(obs)
    return out


def _expected_limits(q, lo, hi, margin):
    return np.maximum(1 - (hi - q) / margin, 0) - np.maximum(1 - (q - lo) / margin, 0)


def _drive(env, n_steps=25, seed=1):
    obs = None
    for act in random_action_block(env, n_steps, seed):
        obs = env.step(act)[0]
    return obs


@pytest.mark.parametrize("actuation", ["spring_damper", "muscle"])
def test_qpos_qvel_torque_are_the_simulations_data_of_each_agents_joints(actuation):
    env = _env(actuation=actuation)
    obs = _drive(env)
    d = env.world.data
    for i, agent in enumerate(AGENTS):
        ids, qadr, dadr = _joints(env, i)
        p = _parts(env, i, obs[agent]["proprioception"])
        # the observation is float32 of the simulation's float64: exactly the cast values
        np.testing.assert_array_equal(p["qpos"], d.qpos[qadr].astype(np.float32))
        np.testing.assert_array_equal(p["qvel"], d.qvel[dadr].astype(np.float32))
        np.testing.assert_array_equal(p["torque"], d.qfrc_actuator[dadr].astype(np.float32))
        # the parts are different things (a part filled with another's data is seen)
        assert np.abs(d.qvel[dadr]).max() > 1e-3
        assert np.abs(d.qfrc_actuator[dadr]).max() > 1e-3
        assert not np.allclose(p["qvel"], p["torque"])
        assert not np.allclose(p["qpos"], p["qvel"])


def test_a_subset_of_components_keeps_the_documented_order_and_values():
    comps = ("torque", "qpos")                     # given out of order: laid out as COMPONENTS
    env = _env(proprioception={"components": list(comps)})
    obs = _drive(env, 10)
    d = env.world.data
    for i, agent in enumerate(AGENTS):
        ids, qadr, dadr = _joints(env, i)
        p = _parts(env, i, obs[agent]["proprioception"], comps)
        np.testing.assert_array_equal(p["qpos"], d.qpos[qadr].astype(np.float32))
        np.testing.assert_array_equal(p["torque"], d.qfrc_actuator[dadr].astype(np.float32))


def _sense(env, i):
    return next(s for s in env.senses[i] if s.name == "proprioception")


@pytest.mark.parametrize("margin_deg", [5.0, 12.0])
def test_limit_sensors_are_plus_one_at_the_upper_and_minus_one_at_the_lower_limit(margin_deg):
    env = _env(proprioception={"limit_margin_deg": margin_deg})
    m, d = env.world.model, env.world.data
    margin = np.deg2rad(margin_deg)
    for i, agent in enumerate(AGENTS):
        ids, qadr, dadr = _joints(env, i)
        lo, hi = m.jnt_range[ids, 0], m.jnt_range[ids, 1]
        wide = hi - lo > 2 * margin + 1e-6          # joints where the two stretches do not meet
        assert wide.sum() > 10
        sense = _sense(env, i)
        cases = {"at the upper limit": (hi, 1.0), "at the lower limit": (lo, -1.0),
                 "half the margin below the upper limit": (hi - margin / 2, 0.5),
                 "half the margin above the lower limit": (lo + margin / 2, -0.5),
                 "in the middle": ((lo + hi) / 2, 0.0),
                 "just outside the margin below the upper limit": (hi - 1.01 * margin, 0.0)}
        for what, (q, want) in cases.items():
            d.qpos[qadr] = q
            mujoco.mj_forward(m, d)
            out = {}
            sense.observe(m, d, out)
            limits = _parts(env, i, out["proprioception"])["limits"]
            np.testing.assert_allclose(limits[wide], want, atol=1e-5,
                                       err_msg=f"{agent}: limit sensors {what}")
            np.testing.assert_allclose(limits, _expected_limits(q, lo, hi, margin), atol=1e-5,
                                       err_msg=f"{agent}: limit sensors {what}")
        env.reset(seed=3)


def test_limit_sensors_in_the_observation_of_a_step_follow_the_joint_angles():
    """End to end: joints put at their limits before a step read near +-1 with the sign of the
    end they are at, and every value equals the documented formula of the stepped angles."""
    env = _env()
    m, d = env.world.model, env.world.data
    margin = np.deg2rad(5.0)
    upper, lower = {}, {}
    for i in range(2):
        ids, qadr, dadr = _joints(env, i)
        lo, hi = m.jnt_range[ids, 0], m.jnt_range[ids, 1]
        # odd joints at their upper limit, even ones at their lower limit, at rest
        q = np.where(np.arange(len(ids)) % 2, hi, lo)
        d.qpos[qadr] = q
        d.qvel[dadr] = 0.0
        upper[i], lower[i] = np.arange(len(ids)) % 2 == 1, np.arange(len(ids)) % 2 == 0
    mujoco.mj_forward(m, d)
    obs = env.step({a: np.zeros(env.action_space(a).shape, np.float32) for a in AGENTS})[0]
    for i, agent in enumerate(AGENTS):
        ids, qadr, dadr = _joints(env, i)
        lo, hi = m.jnt_range[ids, 0], m.jnt_range[ids, 1]
        limits = _parts(env, i, obs[agent]["proprioception"])["limits"]
        q = d.qpos[qadr]
        np.testing.assert_allclose(limits, _expected_limits(q, lo, hi, margin), atol=1e-5)
        # after one step most joints are still within the margin of the end they were put at
        # (a joint pushed past its limit reads beyond +-1)
        assert np.mean(limits[upper[i]] > 0) > 0.7, limits[upper[i]]
        assert np.mean(limits[lower[i]] < 0) > 0.7, limits[lower[i]]


def test_the_face_component_is_off_by_default_and_reads_the_face_the_agent_shows():
    plain = _env()
    assert plain.observation_space("infant_0")["proprioception"].shape[0] == \
        _sense(plain, 0).size and "face" not in _sense(plain, 0).slices
    env = free_play_v0.parallel_env(n_agents=2, proprioception={"components": ["qpos", "face"]})
    obs, _ = env.reset(seed=3)
    n = len(env.world.agents[0].joint_names)
    space = env.observation_space("infant_0")["proprioception"]
    assert space.shape == (n + 7,) and space.low[n:].tolist() == [0.0] * 7
    for faces in [(1, 4), (6, 0), (2, 2)]:
        actions = {}
        for i, agent in enumerate(AGENTS):
            a = env.action_space(agent).sample()
            a["motors"][:] = 0.0
            a["expression"] = faces[i]
            actions[agent] = a
        obs = env.step(actions)[0]
        for i, agent in enumerate(AGENTS):
            face = obs[agent]["proprioception"][n:]
            assert face.tolist() == np.eye(7)[faces[i]].tolist()     # its own face, one-hot
            assert env.world.expression_of(i) == faces[i]
            assert space.contains(obs[agent]["proprioception"])
