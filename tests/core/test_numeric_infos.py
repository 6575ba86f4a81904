"""Infos are numbers by default: every agent's the same float keys at reset and at every step
(``env.info_keys(agent)``), the encoding of the text infos that ``info_text=True`` gives."""

from __future__ import annotations

import pickle

import gymnasium as gym
import numpy as np
import pytest

import mimo_social  # noqa: F401  (registers the Gymnasium ids)
from mimo_social.core.infos import InfoEncoder
from mimo_social.envs import high_five_v0, selfbody_v0, social_touch_v0
from mimo_social.util.checks import ConfigError

STEPS = 6


def _actions(env, rng):
    return {a: rng.uniform(-1, 1, env.action_space(a).shape).astype(np.float32)
            for a in env.agents}


def test_the_env_as_made_has_the_same_float_keys_at_reset_and_every_step():
    env = social_touch_v0.parallel_env(max_steps=STEPS)
    assert env.info_text is False
    _, infos = env.reset(seed=0)
    seen = [infos]
    rng = np.random.default_rng(0)
    while env.agents:
        seen.append(env.step(_actions(env, rng))[-1])
    assert len(seen) == STEPS + 1
    for infos in seen:
        for agent, info in infos.items():
            assert tuple(info) == env.info_keys(agent)
            assert all(type(v) is float for v in info.values()), info
    keys = env.info_keys("infant_0")
    assert {"expression", "instability", "touch/parts", "target_part", "is_success"} <= set(keys)
    assert seen[0]["infant_0"]["expression"] == 0.0 and seen[0]["infant_0"]["instability"] == 0.0


def test_numeric_infos_are_the_encoding_of_the_text_infos():
    text = social_touch_v0.parallel_env(max_steps=STEPS, info_text=True)
    numeric = social_touch_v0.parallel_env(max_steps=STEPS)
    enc = InfoEncoder({a: text.info_spec(a) for a in text.possible_agents})
    _, t_infos = text.reset(seed=4)
    _, n_infos = numeric.reset(seed=4)
    assert t_infos["infant_0"]["expression"] == "neutral"
    rng = np.random.default_rng(1)
    for _ in range(STEPS):
        assert enc.encode_all(t_infos) == n_infos
        acts = _actions(text, rng)
        t_infos = text.step(acts)[-1]
        n_infos = numeric.step(acts)[-1]
    assert isinstance(t_infos["infant_0"]["touch"], dict)
    assert isinstance(t_infos["infant_0"]["target_part"], str)
    assert n_infos["infant_0"]["target_part"] == float(
        numeric.task.targets.index(t_infos["infant_0"]["target_part"]))


def test_a_scripted_partners_rewards_are_numbers_too():
    env = high_five_v0.scripted_env(max_steps=STEPS, expressions=False)
    text = high_five_v0.scripted_env(max_steps=STEPS, expressions=False, info_text=True)
    (learner,) = env.possible_agents
    keys = env.info_keys(learner)
    assert keys[-1] == "partner_rewards/infant_1"
    _, info = env.reset(seed=2)
    text.reset(seed=2)
    assert tuple(info[learner]) == keys and info[learner]["partner_rewards/infant_1"] == 0.0
    rng = np.random.default_rng(2)
    for _ in range(3):
        act = _actions(env, rng)
        *_, info = env.step(act)
        *_, t_info = text.step(act)
        assert tuple(info[learner]) == keys
        assert info[learner]["partner_rewards/infant_1"] == \
            t_info[learner]["partner_rewards"]["infant_1"]


def test_the_gymnasium_ids_give_numeric_infos_and_take_info_text():
    env = gym.make("mimo_social/SelfBody-v0", max_steps=STEPS)
    _, info = env.reset(seed=0)
    assert info and all(type(v) is float for v in info.values())
    text = gym.make("mimo_social/SelfBody-v0", max_steps=STEPS, info_text=True)
    _, info = text.reset(seed=0)
    assert info["expression"] == "neutral" and isinstance(info["touch"], dict)


def test_info_text_is_a_bool_and_survives_pickling():
    with pytest.raises(ConfigError, match="info_text"):
        selfbody_v0.parallel_env(info_text="yes")
    env = pickle.loads(pickle.dumps(selfbody_v0.parallel_env(max_steps=STEPS, info_text=True)))
    _, infos = env.reset(seed=0)
    assert infos["infant_0"]["expression"] == "neutral"
    env = pickle.loads(pickle.dumps(selfbody_v0.parallel_env(max_steps=STEPS)))
    _, infos = env.reset(seed=0)
    assert tuple(infos["infant_0"]) == env.info_keys("infant_0")
