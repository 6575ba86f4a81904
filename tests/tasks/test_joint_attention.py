"""The joint attention task (gaze following) through its public API."""

import numpy as np
import pytest
from gymnasium import spaces

from mimo_social.envs import joint_attention_v0
from mimo_social.core.gym_adapter import SingleAgentEnv
from mimo_social.core.wrappers import FlattenParallel
from mimo_social.train.envs import make_sb3_single
from mimo_social.partners.gaze import GazeAtTarget

STILL = np.zeros(9, np.float32)


@pytest.mark.parametrize("kwargs, match", [
    ({"n_agents": 3}, "n_agents=3; allowed: 2 to 2"),
    ({"task_options": {"n_toys": 5}}, "n_toys=5"),
    ({"task_options": {"margin_deg": -1}}, "margin_deg"),
    ({"task_options": {"shaping": "on"}}, "shaping"),
    ({"task_options": {"distance": 0.3}}, "distance"),
    ({"task_options": {"min_separation_deg": 60}}, "min_separation_deg"),
    ({"task_options": {"head_support": 1}}, "head_support"),
    ({"task_options": {"toys": 3}}, "unknown task option"),
])
def test_bad_input_raises_clear_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        joint_attention_v0.parallel_env(**kwargs)


def test_spaces():
    env = joint_attention_v0.parallel_env()
    for a in env.possible_agents:
        assert set(env.observation_space(a).spaces) == {"proprioception", "eye_left", "eye_right"}
        assert env.observation_space(a)["eye_left"].shape == (96, 96, 3)
        assert env.action_space(a) == spaces.Box(-1, 1, (9,), np.float32)
    scripted = joint_attention_v0.scripted_env()
    assert scripted.possible_agents == ["infant_0"]
    assert isinstance(scripted.partners["infant_1"], GazeAtTarget)
    assert scripted.unwrapped.agent_configs[1].vision is None


def _toys(env):
    w = env.unwrapped.world
    return w.data.xpos[env.unwrapped.task.toy_bodies].copy()


def test_toys_are_placed_at_random_per_episode_seeded_and_apart():
    env = joint_attention_v0.parallel_env(vision=False)
    env.reset(seed=1)
    a = _toys(env)
    env.reset(seed=2)
    b = _toys(env)
    env.reset(seed=1)
    np.testing.assert_array_equal(a, _toys(env))
    assert not np.allclose(a, b)
    assert np.all(np.abs(a[:, 1]) >= 0.25) and np.all(a[:, 2] < 0.05)  # beside, on the floor
    w = env.unwrapped.world
    for head in w.data.site_xpos[[ag.head_site for ag in w.agents]]:
        u = a - head
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        cos = u @ u.T
        assert np.all(np.rad2deg(np.arccos(np.clip(cos[np.triu_indices(4, 1)], -1, 1))) >= 25.0)


def _drive(env, gazers, targets, steps=100):
    """Both agents turn to the given toys with GazeAtTarget used as a controller."""
    inner = env.unwrapped
    rng = np.random.default_rng(0)
    for agent, g in gazers.items():
        g.reset(inner, agent, rng)
        g.target = targets[agent]
    for _ in range(steps):
        out = env.step({a: gazers[a].act(inner, a, None) if a in gazers else STILL
                        for a in env.agents})
    return out


def test_shared_reward_when_both_look_at_the_same_toy():
    env = joint_attention_v0.parallel_env(vision=False)
    env.reset(seed=3)
    # at rest both look at each other: no toy, no reward
    _, rew, _, _, info = env.step({a: STILL for a in env.agents})
    assert rew == {"infant_0": 0.0, "infant_1": 0.0}
    assert info["infant_0"]["looked_at"] == -1 and info["infant_0"]["target"] == -1
    assert info["infant_0"]["is_success"] is False
    gazers = {a: GazeAtTarget(hold_s=(99, 99)) for a in env.possible_agents}
    _, rew, term, trunc, info = _drive(env, gazers, {"infant_0": 2, "infant_1": 2})
    assert rew == {"infant_0": 1.0, "infant_1": 1.0}
    for a, other in (("infant_0", "infant_1"), ("infant_1", "infant_0")):
        assert info[a]["looked_at"] == 2 and info[a]["target"] == 2
        assert info[a]["is_success"] is True and info[a]["gaze_error_deg"] < 3.0
        assert not term[a] and not trunc[a]
    _, rew, _, _, info = _drive(env, gazers, {"infant_0": 0, "infant_1": 2})
    assert rew == {"infant_0": 0.0, "infant_1": 0.0}
    assert info["infant_0"]["looked_at"] == 0 and info["infant_0"]["target"] == 2
    assert info["infant_1"]["looked_at"] == 2 and info["infant_1"]["target"] == 0
    assert info["infant_0"]["is_success"] is False


def test_shaping_subtracts_the_angle_to_the_partners_toy():
    env = joint_attention_v0.parallel_env(vision=False, task_options={"shaping": 0.5})
    env.reset(seed=3)
    gazers = {a: GazeAtTarget(hold_s=(99, 99)) for a in env.possible_agents}
    _, rew, _, _, info = _drive(env, gazers, {"infant_0": 0, "infant_1": 2})
    err = np.deg2rad(info["infant_0"]["gaze_error_deg"])
    assert err > np.deg2rad(20)
    assert rew["infant_0"] == pytest.approx(-0.5 * err)
    _, rew, _, _, info = _drive(env, gazers, {"infant_0": 2, "infant_1": 2})
    err = np.deg2rad(info["infant_0"]["gaze_error_deg"])
    assert rew["infant_0"] == pytest.approx(1.0 - 0.5 * err) and rew["infant_0"] > 0.95


def test_scripted_env_rewards_the_learner_for_following_the_partner():
    env = joint_attention_v0.scripted_env(vision=False)
    env.reset(seed=5)
    partner = env.partners["infant_1"]
    learner = GazeAtTarget(hold_s=(99, 99))
    inner = env.unwrapped
    learner.reset(inner, "infant_0", np.random.default_rng(0))
    hits = []
    for k in range(300):
        learner.target = partner.target  # a perfect (privileged) follower, for the test only
        _, rew, _, _, info = env.step({"infant_0": learner.act(inner, "infant_0", None)})
        i = info["infant_0"]
        assert rew["infant_0"] == float(i["is_success"])
        assert i["partner_rewards"] == {"infant_1": 0.0}
        hits.append(i["is_success"])
    assert np.mean(hits) > 0.6  # both are on the toy except while turning


def test_partner_head_only_in_the_eye_images():
    """The learner keeps still; only where the partner looks differs between two runs: the
    learner's observation differs only in its eye images (the head turn it sees)."""
    obs_by_target = []
    for target in (0, 1):
        partner = GazeAtTarget(hold_s=(99, 99))
        env = joint_attention_v0.scripted_env(partner)
        env.reset(seed=7)
        partner.target = target
        for _ in range(80):
            obs, _, _, _, info = env.step({"infant_0": STILL})
        assert info["infant_0"]["target"] == target
        obs_by_target.append(obs["infant_0"])
    a, b = obs_by_target
    assert set(a) == {"proprioception", "eye_left", "eye_right"}
    np.testing.assert_array_equal(a["proprioception"], b["proprioception"])
    for eye in ("eye_left", "eye_right"):
        diff = np.abs(a[eye].astype(int) - b[eye].astype(int))
        assert (diff.max(axis=2) > 30).sum() > 40  # dozens of pixels change, not noise


def test_flat_wrappers():
    flat = FlattenParallel(joint_attention_v0.parallel_env(vision=False))
    flat.reset(seed=0)
    _, rew, *_ = flat.step({a: np.zeros(9, np.float32) for a in flat.agents})
    assert set(rew) == {"infant_0", "infant_1"}
    single = make_sb3_single(SingleAgentEnv(joint_attention_v0.scripted_env()))
    assert isinstance(single.observation_space, spaces.Box)
    assert single.action_space.shape == (9,)
    obs, _ = single.reset(seed=0)
    obs, r, *_ = single.step(single.action_space.sample())
    assert obs.shape == single.observation_space.shape


def test_scripted_env_pickles_mid_episode():
    import pickle
    env = joint_attention_v0.scripted_env(vision=False)
    env.reset(seed=2)
    for _ in range(30):
        env.step({"infant_0": STILL})
    copy = pickle.loads(pickle.dumps(env))
    for _ in range(60):
        o1, r1, _, _, i1 = env.step({"infant_0": STILL})
        o2, r2, _, _, i2 = copy.step({"infant_0": STILL})
    np.testing.assert_array_equal(o1["infant_0"]["proprioception"],
                                  o2["infant_0"]["proprioception"])
    assert r1 == r2 and i1["infant_0"]["target"] == i2["infant_0"]["target"]
    assert copy.partners["infant_1"].target == env.partners["infant_1"].target
