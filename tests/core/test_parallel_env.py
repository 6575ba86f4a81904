"""The PettingZoo env through its public API."""

import gymnasium as gym
import numpy as np
import pytest
from pettingzoo.test import parallel_api_test, parallel_seed_test

import mimo_social  # noqa: F401
from mimo_social.envs import free_play_v0, high_five_v0


@pytest.mark.parametrize("n_agents", [3])   # 2: tests/conformance
def test_free_play_api(n_agents):
    parallel_api_test(free_play_v0.parallel_env(n_agents=n_agents, max_steps=60), num_cycles=80)


@pytest.mark.parametrize("n_agents", [3])   # 2: tests/conformance
def test_free_play_seed(n_agents):
    parallel_seed_test(lambda: free_play_v0.parallel_env(n_agents=n_agents, max_steps=60))


def _rollout(seed, steps=200):
    env = free_play_v0.parallel_env(n_agents=2)
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    traj = []
    for _ in range(steps):
        actions = {a: {"motors": rng.uniform(-1, 1, 44).astype(np.float32),
                       "expression": int(rng.integers(7))} for a in env.agents}
        obs, *_ = env.step(actions)
        traj.append(np.concatenate([obs[a]["proprioception"] for a in env.possible_agents]))
    return np.array(traj), env.world.data.qpos.copy()


def test_same_seed_same_trajectory_over_200_steps():
    t1, q1 = _rollout(7)
    t2, q2 = _rollout(7)
    np.testing.assert_array_equal(t1, t2)
    np.testing.assert_array_equal(q1, q2)
    t3, _ = _rollout(8)
    assert not np.array_equal(t1, t3)


def test_reach_gym_spaces():
    env = gym.make("mimo_social/Reach-v0")
    obs, info = env.reset(seed=0)
    assert set(obs) == {"proprioception"}
    assert env.action_space.shape == (8,)


def test_reach_reward_is_minus_distance_and_success_ends():
    env = gym.make("mimo_social/Reach-v0").unwrapped
    env.reset(seed=1)
    _, r, term, trunc, info = env.step(np.zeros(8, np.float32))
    assert r == pytest.approx(-info["distance"]) and not term
    # put the hand on the ball: the episode ends with the success reward
    w = env.parallel.world
    env.parallel.task.place_ball(env.parallel, w.data.site_xpos[w.agents[0].palm_sites[0]])
    _, r, term, _, info = env.step(np.zeros(8, np.float32))
    assert term and r == 100.0 and info["is_success"]


def test_motor_torques_at_plus_and_minus_one():
    """A motor at +1 and -1 (joint held by the other motors' irrelevance) gives Table I torques."""
    env = free_play_v0.parallel_env(n_agents=1, expressions=False)
    env.reset(seed=0)
    a = env.world.agents[0]
    knee = a.actuated_names.index("right_knee")
    dof = a.dof_adr[a.joint_names.index("right_knee")]
    for u, torque in ((1.0, 10.0), (-1.0, -6.5), (0.5, 5.0), (-0.5, -3.25)):
        action = np.zeros(44, np.float32)
        action[knee] = u
        env.step({"infant_0": action})
        assert env.world.data.qfrc_actuator[dof] == pytest.approx(torque, rel=1e-6)
        obs = env._observe(0)["proprioception"]
        assert torque in obs  # the actuation state reports the torque


def test_actions_move_the_joint():
    env = high_five_v0.parallel_env(expressions=False)
    env.reset(seed=0)
    a = env.world.agents[0]
    k = a.joint_names.index("right_elbow")
    before = env.world.data.qpos[a.qpos_adr[k]]
    act = {n: np.zeros(8, np.float32) for n in env.agents}
    act["infant_0"][a.actuated_names.index("right_elbow")] = -1.0  # flex
    for _ in range(30):
        env.step(act)
    assert env.world.data.qpos[a.qpos_adr[k]] < before - 0.3


def test_gravity_makes_an_unactuated_infant_settle():
    env = free_play_v0.parallel_env(n_agents=1, expressions=False, max_steps=2000)
    env.reset(seed=0)
    d = env.world.data
    root = env.world.agents[0].root_body
    z0 = d.xpos[root, 2]
    zero = {"infant_0": np.zeros(44, np.float32)}
    for _ in range(400):
        env.step(zero)
    assert d.xpos[root, 2] < z0 - 0.05                 # it sagged or fell
    for _ in range(200):
        env.step(zero)
    assert np.abs(d.qvel).max() < 0.5                  # and came to rest


def test_spaces_follow_configuration():
    env = free_play_v0.parallel_env(n_agents=2, vestibular=False,
                                    per_agent=[{}, {"proprioception": {"components": ["qpos"]}}])
    s0 = env.observation_space("infant_0")
    s1 = env.observation_space("infant_1")
    assert "vestibular" not in s0.spaces
    assert s1["proprioception"].shape == (47,)
    assert env.observation_space("infant_0") is s0
    obs, _ = env.reset(seed=0)
    assert s0.contains(obs["infant_0"]) and s1.contains(obs["infant_1"])


def test_senses_come_from_the_registry():
    from dataclasses import fields

    from mimo_social.core.config import AgentConfig
    from mimo_social.core.env import TIMING_KEYS
    from mimo_social.senses import SENSES, Sense, SharedSystem

    assert list(SENSES) == ["proprioception", "vestibular", "touch", "vision", "audition", "faces"]
    assert set(SENSES) <= {f.name for f in fields(AgentConfig)}
    assert set(SENSES) <= set(TIMING_KEYS)
    for name, entry in SENSES.items():
        assert entry.name == name and (entry.per_agent is None) != (entry.shared is None)
    env = free_play_v0.parallel_env(n_agents=2, touch=True, per_agent=[{}, {"vestibular": False}])
    assert sorted(env.systems) == ["touch"] and env.system("touch") is env.systems["touch"]
    assert all(isinstance(s, SharedSystem) for s in env.systems.values())
    assert [s.name for s in env.senses[0]] == ["proprioception", "vestibular", "touch"]
    assert [s.name for s in env.senses[1]] == ["proprioception", "touch"]
    assert all(isinstance(s, Sense) for senses in env.senses for s in senses)
    with pytest.raises(ValueError, match="vision=True"):
        env.system("vision")


def test_instability_ends_the_episode_with_a_reason():
    env = free_play_v0.parallel_env(n_agents=2, expressions=False)
    env.reset(seed=0)
    env.world.data.qvel[7] = np.nan
    _, _, term, _, infos = env.step({a: np.zeros(44, np.float32) for a in env.agents})
    assert all(term.values())
    assert all(i["instability"] for i in infos.values())
    assert env.agents == []


def test_gaze_fixates_the_target():
    """In reach, both eye cameras look at the ball; in high five with the privileged cue
    ``assisted_gaze``, at the partner's right hand."""
    env = gym.make("mimo_social/Reach-v0").unwrapped
    for seed in range(3):
        env.reset(seed=seed)
        w = env.parallel.world
        d = w.data
        ball = d.xpos[w.prop_bodies["ball"]]
        for cam in w.agents[0].eye_cameras:
            look = -d.cam_xmat[cam].reshape(3, 3)[:, 2]
            to_ball = ball - d.cam_xpos[cam]
            cos = look @ to_ball / np.linalg.norm(to_ball)
            assert cos > np.cos(np.deg2rad(2.0))
    hf = high_five_v0.parallel_env(expressions=False, task_options={"assisted_gaze": True})
    hf.reset(seed=0)
    for _ in range(10):
        hf.step({a: np.full(8, 0.4, np.float32) for a in hf.agents})
    hf.task.before_physics(hf)
    import mujoco
    mujoco.mj_camlight(hf.world.model, hf.world.data)  # camera poses follow the new angles
    d = hf.world.data
    hand1 = d.site_xpos[hf.world.agents[1].palm_sites[0]]
    cam = hf.world.agents[0].eye_cameras[1]
    look = -d.cam_xmat[cam].reshape(3, 3)[:, 2]
    to_hand = hand1 - d.cam_xpos[cam]
    assert look @ to_hand / np.linalg.norm(to_hand) > np.cos(np.deg2rad(2.0))


@pytest.mark.parametrize("posture, n", [("standing", 8), ("sitting", 4), ("lying", 3)])
def test_infants_start_apart(posture, n):
    env = free_play_v0.parallel_env(n_agents=n, posture=posture, expressions=False)
    env.reset(seed=0)
    d, ga = env.world.data, env.world.geom_agent
    g1, g2 = d.contact.geom1[: d.ncon], d.contact.geom2[: d.ncon]
    between = (ga[g1] != ga[g2]) & (ga[g1] >= 0) & (ga[g2] >= 0)
    assert not between.any()
