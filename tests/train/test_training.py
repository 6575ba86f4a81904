"""Training plumbing: FlattenParallel, the SB3 single-agent adapter and the SuperSuit/SB3 vec env."""

import functools
import pickle

import numpy as np
import pytest
import torch
from pettingzoo.test import parallel_api_test
from stable_baselines3 import PPO

from mimo_social.envs import high_five_v0, reach_v0
from mimo_social.train.vector import sb3_vec_env
from mimo_social.core.wrappers import FlattenParallel
from mimo_social.train.envs import make_sb3_single

torch.set_num_threads(1)

PPO_KWARGS = dict(n_steps=64, batch_size=64, n_epochs=1, device="cpu", seed=0, verbose=0)
N_EXPR = 7
# high five: proprioception 84, touch 232 (the right hand's skin), vestibular 6
HF_OBS = 48 + 232 + 6   # proprioception without the head and eyes (held unless assisted_gaze)


def _params(model):
    return {k: v.detach().clone() for k, v in model.policy.state_dict().items()}


def _changed(before, after):
    return [k for k in before if not torch.equal(before[k], after[k])]


def _high_five_short():
    return high_five_v0.parallel_env(max_steps=3)


# a builtin that raises, so the spawned worker need not import this (torch-importing) module
_failing_env = functools.partial(int, "boom from env_fn")


# -- FlattenParallel ----------------------------------------------------------------------------
def test_flatten_parallel_passes_parallel_api_test():
    env = FlattenParallel(high_five_v0.parallel_env())
    for a in env.possible_agents:
        obs_space, act_space = env.observation_space(a), env.action_space(a)
        assert obs_space is env.observation_space(a) and act_space is env.action_space(a)
        assert obs_space.shape == (HF_OBS,) and obs_space.dtype == np.float32
        assert act_space.shape == (8 + N_EXPR,) and act_space.dtype == np.float32
    parallel_api_test(env, num_cycles=1000)
    env.close()


def test_flatten_parallel_observations_actions_and_passthrough():
    raw = high_five_v0.parallel_env()
    env = FlattenParallel(high_five_v0.parallel_env(info_text=True))   # expressions by name
    raw_obs, _ = raw.reset(seed=5)
    obs, infos = env.reset(seed=5)
    assert env.agents == env.possible_agents == raw.possible_agents
    for a in env.agents:  # keys concatenated in the Dict space's order
        expected = np.concatenate([raw_obs[a]["proprioception"], raw_obs[a]["touch"],
                                   raw_obs[a]["vestibular"]])
        np.testing.assert_array_equal(obs[a], expected)
        assert obs[a].dtype == np.float32 and env.observation_space(a).contains(obs[a])
    # motors then 7 logits; the argmax picks the expression
    act = {a: np.zeros(8 + N_EXPR, np.float32) for a in env.agents}
    act["infant_0"][8 + 3] = 0.9
    act["infant_1"][8 + 5] = 0.2
    obs, rew, term, trunc, infos = env.step(act)
    assert infos["infant_0"]["expression"] == "surprised"
    assert infos["infant_1"]["expression"] == "angry"
    assert list(env.unwrapped._expression) == [3, 5]
    with pytest.raises(ValueError, match="infant_0"):
        env.step({"infant_0": np.zeros(8, np.float32), "infant_1": act["infant_1"]})
    # pass-through: state, state_space, render_mode, attributes of the wrapped env
    assert env.state().shape == env.state_space.shape
    assert env.render_mode is None and env.render() is None
    assert env.max_steps == raw.max_steps
    # no expressions: the motor Box itself
    plain = FlattenParallel(high_five_v0.parallel_env(expressions=False))
    assert plain.action_space("infant_1").shape == (8,)
    plain.reset(seed=0)
    plain.step({a: np.full(8, 0.5, np.float32) for a in plain.agents})


def test_flatten_parallel_pickle_round_trip():
    env = FlattenParallel(high_five_v0.parallel_env())
    env.reset(seed=0)
    copy = pickle.loads(pickle.dumps(env))
    assert copy.possible_agents == env.possible_agents
    assert copy.observation_space("infant_0") == env.observation_space("infant_0")
    rng = np.random.default_rng(0)
    actions = [{a: rng.uniform(-1, 1, 8 + N_EXPR).astype(np.float32) for a in env.possible_agents}
               for _ in range(5)]
    results = []
    for e in (env, copy):
        obs, _ = e.reset(seed=1)
        for act in actions:
            obs, rew, term, trunc, info = e.step(act)
        results.append((obs, rew))
        assert all(np.isfinite(o).all() and o.shape == (HF_OBS,) for o in obs.values())
    for a in env.possible_agents:  # the copy is the same simulation
        np.testing.assert_array_equal(results[0][0][a], results[1][0][a])
        assert results[0][1][a] == results[1][1][a]


# -- SB3 ----------------------------------------------------------------------------------------
def test_ppo_learns_on_reach_single_agent():
    env = make_sb3_single("mimo_social/Reach-v0")
    assert env.observation_space.shape == (84,) and env.action_space.shape == (8,)
    model = PPO("MlpPolicy", env, **PPO_KWARGS)
    before = _params(model)
    model.learn(total_timesteps=256)
    assert model.num_timesteps >= 256
    assert _changed(before, _params(model)), "PPO did not change any policy parameter"
    obs, _ = env.reset(seed=0)
    action, _ = model.predict(obs, deterministic=True)
    assert action.shape == (8,) and env.action_space.contains(action.astype(np.float32))
    env.close()


def test_ppo_learns_on_high_five_with_parameter_sharing():
    vec = sb3_vec_env(high_five_v0.parallel_env)
    assert vec.num_envs == 2
    assert vec.observation_space.shape == (HF_OBS,) and vec.action_space.shape == (8 + N_EXPR,)
    model = PPO("MlpPolicy", vec, **PPO_KWARGS)  # seed=0 -> vec.seed(0): crashed before the fix
    before = _params(model)
    model.learn(total_timesteps=256)
    assert model.num_timesteps >= 256
    assert _changed(before, _params(model)), "PPO did not change any policy parameter"
    obs = vec.reset()
    actions, _ = model.predict(obs, deterministic=True)
    assert actions.shape == (2, 8 + N_EXPR)
    vec.close()


# -- seeds and the SB3 VecEnv API ---------------------------------------------------------------
def test_vec_seed_is_used_by_the_next_reset():
    vec = sb3_vec_env(reach_v0.parallel_env, n_envs=2)  # Reach's reset is random
    assert list(vec.seed(3)) == [3, 4]
    first = vec.reset()
    assert isinstance(first, np.ndarray) and first.shape == (2, 84)  # obs only, SB3 style
    assert len(vec.reset_infos) == 2
    vec.seed(3)
    again = vec.reset()
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first[0], first[1])  # world w is seeded with seed + w
    assert not np.array_equal(vec.reset(), first)  # the seed is used once
    vec.seed(4)
    assert not np.array_equal(vec.reset(), first)
    vec.close()


def _high_five_short_fixed_start():
    return high_five_v0.parallel_env(max_steps=3, task_options={"start_spread": 0.0})


def test_vec_step_api_and_terminal_observation():
    vec = sb3_vec_env(_high_five_short_fixed_start, n_envs=2)
    first = vec.reset()
    assert first.shape == (4, HF_OBS)
    assert vec.get_attr("max_steps") == [3, 3, 3, 3]
    assert vec.env_is_wrapped(object) == [False] * 4
    for t in range(3):
        out = vec.step(np.zeros((4, 8 + N_EXPR), np.float32))
        assert len(out) == 4
        obs, rewards, dones, infos = out
        assert obs.shape == (4, HF_OBS) and rewards.shape == (4,) and dones.dtype == bool
    assert dones.all()
    for info in infos:
        assert info["terminal_observation"].shape == (HF_OBS,)
        assert info["TimeLimit.truncated"] is True
    np.testing.assert_array_equal(obs, first)  # auto reset (a fixed start without start_spread)
    vec.close()


def test_spawn_workers_match_in_process():
    local = sb3_vec_env(reach_v0.parallel_env, n_envs=3)
    remote = sb3_vec_env(reach_v0.parallel_env, n_envs=3, n_cpus=2, start_method="spawn")
    try:
        procs = list(remote.gym_venv._procs)
        assert len(procs) == 2 and all(p._start_method == "spawn" for p in procs)
        local.seed(7)
        remote.seed(7)
        np.testing.assert_array_equal(local.reset(), remote.reset())
        rng = np.random.default_rng(0)
        for _ in range(10):
            act = rng.uniform(-1, 1, (3, 8)).astype(np.float32)
            a, b = local.step(act), remote.step(act)
            np.testing.assert_array_equal(a[0], b[0])
            np.testing.assert_array_equal(a[1], b[1])
            np.testing.assert_array_equal(a[2], b[2])
        assert remote.get_attr("max_steps") == [1000] * 3
    finally:
        local.close()
        remote.close()
    assert not any(p.is_alive() for p in procs)


def test_vec_errors():
    with pytest.raises(ValueError, match="n_envs"):
        sb3_vec_env(high_five_v0.parallel_env, n_envs=0)
    with pytest.raises(ValueError, match="n_cpus"):
        sb3_vec_env(high_five_v0.parallel_env, n_cpus=-1)
    with pytest.raises(RuntimeError, match="(?s)worker 0 failed.*boom from env_fn"):
        sb3_vec_env(_failing_env, n_envs=1, n_cpus=1)


@pytest.mark.slow
def test_ppo_with_spawn_workers():
    vec = sb3_vec_env(high_five_v0.parallel_env, n_envs=2, n_cpus=2)
    try:
        model = PPO("MlpPolicy", vec, **PPO_KWARGS)
        before = _params(model)
        model.learn(total_timesteps=1024)
        assert _changed(before, _params(model))
    finally:
        vec.close()


def test_flat_observations_scale_eye_images_to_unit_range():
    """Learners get eye pixels in [0, 1] (raw 0-255 values saturate an MLP's first layer)."""
    from mimo_social.envs import mirror_v0
    from mimo_social.core.gym_adapter import SingleAgentEnv
    env = mirror_v0.parallel_env()
    flat = FlattenParallel(env)
    raw, _ = env.reset(seed=0)
    obs, _ = flat.reset(seed=0)
    space = flat.observation_space("infant_0")
    parts = env.observation_space("infant_0").spaces
    start = 0
    for key, sub in parts.items():
        size = int(np.prod(sub.shape))
        chunk = obs["infant_0"][start:start + size]
        value = raw["infant_0"][key].astype(np.float32).ravel()
        if key.startswith("eye_"):
            assert np.allclose(chunk, value / 255)
            assert space.low[start:start + size].min() == 0
            assert space.high[start:start + size].max() == 1
            assert chunk.max() > 0.2  # a real image
        else:
            assert np.array_equal(chunk, value), key
        start += size
    assert start == space.shape[0]
    single = make_sb3_single(SingleAgentEnv(mirror_v0.scripted_env()), flat=True)
    o, _ = single.reset(seed=0)
    assert single.observation_space.contains(o) and o.shape == space.shape


def test_a_face_only_agent_learns_a_discrete_expression():
    """The mirror learner has no motors: its SB3 action is the expression id itself."""
    from gymnasium import spaces
    from mimo_social.envs import mirror_v0
    from mimo_social.core.gym_adapter import SingleAgentEnv
    single = SingleAgentEnv(mirror_v0.scripted_env())
    env = make_sb3_single(single)
    assert env.action_space == spaces.Discrete(7)
    env.reset(seed=0)
    world = single.parallel.unwrapped.world
    for face in (3, 5):
        env.step(face)
        assert world.expression_of(0) == face
    with pytest.raises(ValueError):
        env.step(7)


def test_running_norm_learns_input_statistics_only_while_training():
    from gymnasium import spaces
    from mimo_social.train.obs_norm import RunningNorm
    norm = RunningNorm(spaces.Box(-np.inf, np.inf, (3,), np.float32))
    data = np.random.default_rng(0).normal([1, 5, -2], [0.1, 2, 3], (4000, 3)).astype(np.float32)
    norm.train()
    for k in range(0, 4000, 100):
        norm(torch.tensor(data[k:k + 100]))
    assert np.allclose(norm.mean.numpy(), data.mean(0), atol=1e-4)
    assert np.allclose(np.sqrt(norm.var.numpy()), data.std(0), rtol=1e-3)
    out = norm(torch.tensor(data)).numpy()
    assert np.allclose(out.mean(0), 0, atol=1e-2) and np.allclose(out.std(0), 1, atol=1e-2)
    norm.eval()                                   # acting / evaluating: statistics stay
    before = norm.mean.clone()
    norm(torch.tensor(data[:10] + 100))
    assert torch.equal(before, norm.mean)
