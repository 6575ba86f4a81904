"""SuperSuit (normalize_obs_v0, and its vector-env path into Stable-Baselines3) and Gymnasium's
env checker (render check included) on the Gymnasium ids.

``normalize_obs_v0`` needs a Box observation with finite bounds: flatten the Dict
(FlattenParallel; eye pixels become [0, 1]) and keep the bounded parts of the senses (joint
angles, limit sensors, the spring-damper state, eyes, task one-hots); velocities, torques,
forces and accelerations have no bound, and an env with them is refused by SuperSuit. Touch
tasks cannot do without their skin's forces: their observations are normalised by the package's
running normaliser instead."""

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import mimo_social  # noqa: F401  (registers the Gymnasium ids)
from client_envs import CHEAP, SHORT, entries
from mimo_social.core.wrappers import FlattenParallel
from mimo_social.envs import high_five_v0, mirror_v0, reach_v0

ss = pytest.importorskip("supersuit")

BOUNDED = {"proprioception": {"components": ["qpos", "limits", "actuation"]}}


@pytest.mark.parametrize("make", [
    pytest.param(lambda: reach_v0.parallel_env(max_steps=SHORT, **BOUNDED), id="reach"),
    pytest.param(lambda: mirror_v0.parallel_env(max_steps=SHORT, **CHEAP["mirror"]),
                 id="mirror-16px-eyes"),
])
def test_normalize_obs_on_bounded_flat_observations(make):
    env = ss.normalize_obs_v0(FlattenParallel(make()), env_min=-1.0, env_max=1.0)
    obs, _ = env.reset(seed=0)
    for a in env.possible_agents:
        env.action_space(a).seed(0)
    for _ in range(SHORT):
        for a, o in obs.items():
            assert np.all(np.isfinite(o)) and o.min() >= -1.0 - 1e-5 and o.max() <= 1.0 + 1e-5, a
        if not env.agents:
            break
        obs = env.step({a: env.action_space(a).sample() for a in env.agents})[0]


def test_normalize_obs_refuses_unbounded_observations():
    """Velocities are unbounded: SuperSuit says so (the docs tell to keep bounded parts)."""
    with pytest.raises(AssertionError, match="infinite bounds"):
        ss.normalize_obs_v0(FlattenParallel(reach_v0.parallel_env(max_steps=SHORT)))


def test_supersuit_vector_env_into_stable_baselines3():
    sb3 = pytest.importorskip("stable_baselines3")
    par = FlattenParallel(high_five_v0.parallel_env(max_steps=SHORT, expressions=False))
    vec = ss.pettingzoo_env_to_vec_env_v1(ss.black_death_v3(par))
    venv = ss.concat_vec_envs_v1(vec, 2, num_cpus=0, base_class="stable_baselines3")
    model = sb3.PPO("MlpPolicy", venv, n_steps=8, batch_size=16, n_epochs=1,
                    device="cpu")
    model.learn(total_timesteps=32)
    obs = venv.reset()
    assert obs.shape == (4, par.observation_space("infant_0").shape[0])
    venv.close()


@pytest.mark.parametrize("entry", entries())
def test_gymnasium_env_checker_with_render(entry):
    env = gym.make(entry.gym_id, render_mode="rgb_array", render_size=(24, 32),
                   max_steps=SHORT, **CHEAP[entry.name]).unwrapped
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # advice on unbounded Box parts
        check_env(env)
    assert env.render().shape == (24, 32, 3)
    env.close()


def test_touch_forces_have_no_bound_so_normalise_with_running_norm():
    """A touch task's skin forces are >= 0 with no upper bound (the force of a contact grows with
    how hard it is pressed; MuJoCo's soft contacts set no maximum, and a made-up one would clip
    real readings): SuperSuit's ``normalize_obs_v0`` needs finite bounds and refuses them. The
    package's ``RunningNorm`` (running mean and variance, inside the policy) takes any Box."""
    torch = pytest.importorskip("torch")
    from mimo_social.train.obs_norm import RunningNorm
    raw = high_five_v0.parallel_env(max_steps=SHORT, expressions=False)
    touch = raw.observation_space("infant_0")["touch"]
    assert np.all(touch.low == 0.0) and np.all(np.isinf(touch.high))
    env = FlattenParallel(raw)
    with pytest.raises(AssertionError, match="infinite bounds"):
        ss.normalize_obs_v0(env)
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=0)
    rows = [obs["infant_0"]]
    while env.agents:
        actions = {a: rng.uniform(-1, 1, env.action_space(a).shape).astype(np.float32)
                   for a in env.agents}
        obs = env.step(actions)[0]
        rows += [obs[a] for a in ("infant_0",) if a in obs]
    batch = torch.as_tensor(np.stack(rows))
    norm = RunningNorm(env.observation_space("infant_0"))
    norm.train()
    out = norm(batch)            # learns the batch's statistics, then normalises it
    assert out.shape == batch.shape and torch.isfinite(out).all()
    assert float(out.abs().max()) <= 10.0
    varying = batch.std(0) > 1e-3
    assert varying.any() and float(out[:, varying].mean(0).abs().max()) < 1e-3
