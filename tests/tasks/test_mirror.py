"""The mirror task (facial mimicry) through its public API."""

import numpy as np
import pytest
from gymnasium import spaces

from mimo_social.envs import mirror_v0
from mimo_social.core.gym_adapter import SingleAgentEnv
from mimo_social.core.wrappers import FlattenParallel
from mimo_social.train.envs import make_sb3_single
from mimo_social.expressions.faces import EXPRESSIONS
from mimo_social.partners import Partner
from mimo_social.partners.expression import ExpressionShow

NO_MOTORS = np.zeros(0, np.float32)


def act(expression):
    return {"motors": NO_MOTORS, "expression": np.int64(expression)}


class Shows(Partner):
    """A fixed face, motors at rest (the test's own scripted partner)."""

    def __init__(self, expression):
        self.expression = expression

    def act(self, env, agent, observation):
        return act(self.expression)


def test_three_agents_and_bad_options_raise_clear_errors():
    with pytest.raises(ValueError, match="n_agents=3; allowed: 2 to 2"):
        mirror_v0.parallel_env(n_agents=3)
    with pytest.raises(ValueError, match="distance"):
        mirror_v0.parallel_env(task_options={"distance": 0.1})
    with pytest.raises(ValueError, match="scripted_partner"):
        mirror_v0.parallel_env(task_options={"scripted_partner": "yes"})
    with pytest.raises(ValueError, match="unknown task option"):
        mirror_v0.parallel_env(task_options={"reward": 2})


def test_spaces_eyes_and_expression_action():
    env = mirror_v0.parallel_env()
    for a in env.possible_agents:
        obs_space = env.observation_space(a)
        assert set(obs_space.spaces) == {"proprioception", "eye_left", "eye_right"}
        assert obs_space["eye_left"].shape == (64, 64, 3)
        assert env.action_space(a)["expression"].n == len(EXPRESSIONS)
        assert env.action_space(a)["motors"].shape == (0,)
    assert env.max_steps == 500


def test_match_reward_both_learners():
    env = mirror_v0.parallel_env()
    env.reset(seed=0)
    for e0, e1 in [(1, 1), (1, 2), (6, 6), (0, 3)]:
        _, rew, term, trunc, info = env.step({"infant_0": act(e0), "infant_1": act(e1)})
        want = float(e0 == e1)
        assert rew == {"infant_0": want, "infant_1": want}
        for a in env.possible_agents:
            assert info[a]["match"] is (e0 == e1)
            assert info[a]["is_success"] is (e0 == e1)
            assert not term[a] and not trunc[a]


def test_episode_is_500_steps_without_termination():
    env = mirror_v0.parallel_env(vision=False)
    env.reset(seed=0)
    for k in range(500):
        _, _, term, trunc, _ = env.step({a: act(0) for a in env.agents})
        assert not any(term.values())
        assert all(trunc.values()) == (k == 499)
    assert env.agents == []


def test_scripted_env_rewards_only_the_learner():
    env = mirror_v0.scripted_env(Shows(4))
    assert env.possible_agents == ["infant_0"]
    inner = env.unwrapped
    assert inner.agent_configs[1].vision is None  # a scripted partner needs no eyes
    env.reset(seed=1)
    for e in (4, 2, 4):
        _, rew, _, _, info = env.step({"infant_0": act(e)})
        assert rew["infant_0"] == float(e == 4)
        assert info["infant_0"]["is_success"] is (e == 4)
        assert info["infant_0"]["partner_rewards"] == {"infant_1": 0.0}


def test_scripted_env_default_partner_is_expression_show():
    env = mirror_v0.scripted_env()
    partner = env.partners["infant_1"]
    assert isinstance(partner, ExpressionShow)
    env.reset(seed=3)
    for _ in range(50):
        _, rew, _, _, info = env.step({"infant_0": act(2)})
        assert env.unwrapped.world.expression_of(1) == partner.current
        assert rew["infant_0"] == float(partner.current == 2)


def test_partner_expression_only_in_the_eye_images():
    """Change only the partner's face: every observation value of the learner stays the same
    except its eye images, which change (the expression is seen, never given)."""
    env = mirror_v0.parallel_env()
    images, others = [], []
    for e in range(len(EXPRESSIONS)):
        obs, _ = env.reset(seed=5)
        obs, *_ = env.step({"infant_0": act(0), "infant_1": act(e)})
        o = obs["infant_0"]
        assert set(o) == {"proprioception", "eye_left", "eye_right"}
        images.append(np.concatenate([o["eye_left"], o["eye_right"]]).astype(int))
        others.append(o["proprioception"])
    for e in range(1, len(EXPRESSIONS)):
        np.testing.assert_array_equal(others[e], others[0])
    # every pair of faces differs clearly (hundreds of pixel levels summed, not noise)
    for e in range(len(EXPRESSIONS)):
        for f in range(e):
            assert np.abs(images[e] - images[f]).sum() > 5000, (EXPRESSIONS[e], EXPRESSIONS[f])


def test_flat_wrappers_work_with_the_empty_motor_box():
    """A face-only agent's flat action is the expression id (Discrete(7)) in both wrappers."""
    flat = FlattenParallel(mirror_v0.parallel_env())
    assert flat.action_space("infant_0") == spaces.Discrete(7)
    flat.reset(seed=0)
    _, rew, *_ = flat.step({a: 3 for a in flat.agents})
    assert rew["infant_0"] == 1.0
    _, rew, *_ = flat.step({"infant_0": 3, "infant_1": 4})
    assert rew["infant_0"] == 0.0
    single = make_sb3_single(SingleAgentEnv(mirror_v0.scripted_env()))
    assert isinstance(single.observation_space, spaces.Box)
    assert single.action_space == spaces.Discrete(7)
    obs, _ = single.reset(seed=0)
    assert obs.shape == single.observation_space.shape
    obs, r, term, trunc, info = single.step(single.action_space.sample())
    assert r in (0.0, 1.0) and "is_success" in info
