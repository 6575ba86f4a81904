"""Pixels through a CNN (issue 29): Dict observations with images for SB3, the eyes' encoder,
policy_spec and frame stacking."""

import gymnasium as gym
import numpy as np
import pytest
import torch
from gymnasium import spaces
from stable_baselines3 import PPO, SAC
from torch import nn

from mimo_social.core.wrappers import VECTOR_KEY, DictObservationWrapper
from mimo_social.train.encoders import EyesExtractor, ImageEncoder, policy_spec
from mimo_social.train.envs import make_env

PX = 32
SMALL = {"vision": {"width": PX, "height": PX}}
EYES = ("eye_left", "eye_right")


@pytest.fixture(scope="module", autouse=True)
def one_torch_thread():
    """One torch thread, as the runner trains: here (2 shared cores) a PPO run of 128 steps on
    the eyes took 13 s with torch's default threads, 1 s with one."""
    before = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(before)


@pytest.fixture(scope="module")
def ja_env():
    env = make_env("joint_attention", **SMALL)
    yield env
    env.close()


def test_a_vision_task_keeps_its_images(ja_env):
    space = ja_env.observation_space
    assert isinstance(space, spaces.Dict) and set(space.spaces) == {*EYES, VECTOR_KEY}
    for eye in EYES:
        assert space[eye].shape == (3, PX, PX) and space[eye].dtype == np.uint8
    assert space[VECTOR_KEY].dtype == np.float32 and space[VECTOR_KEY].shape == (54,)
    obs, _ = ja_env.reset(seed=3)
    assert space.contains(obs)
    assert obs["eye_left"].any(), "the eye sees something"
    # the same numbers as the flat path: eyes (scaled, HWC) then the rest
    flat = make_env("joint_attention", flat=True, **SMALL)
    f, _ = flat.reset(seed=3)
    flat.close()
    assert isinstance(flat.observation_space, spaces.Box) and f.shape == (2 * 3 * PX * PX + 54,)
    n = 3 * PX * PX
    for i, eye in enumerate(EYES):
        hwc = obs[eye].transpose(1, 2, 0).ravel().astype(np.float32) / 255
        np.testing.assert_allclose(f[i * n:(i + 1) * n], hwc, atol=1e-6)
    np.testing.assert_array_equal(f[2 * n:], obs[VECTOR_KEY])
    obs, *_ = ja_env.step(ja_env.action_space.sample())
    assert space.contains(obs)


def test_policy_spec_picks_the_cnn(ja_env):
    name, kw = policy_spec(ja_env.observation_space)
    assert name == "MultiInputPolicy" and kw["features_extractor_class"] is EyesExtractor
    assert kw["normalize_images"] is False
    flat = make_env("joint_attention", flat=True, **SMALL)
    assert policy_spec(flat.observation_space) == ("MlpPolicy", {})
    flat.close()


def test_a_task_without_vision_stays_flat():
    env = make_env("reach")
    assert isinstance(env.observation_space, spaces.Box)
    assert policy_spec(env.observation_space) == ("MlpPolicy", {})
    env.close()
    with pytest.raises(ValueError, match="frame_stack"):
        make_env("reach", frame_stack=2)
    with pytest.raises(ValueError, match="frame_stack"):
        make_env("joint_attention", flat=True, frame_stack=2, **SMALL)


def _convs(model) -> list:
    return [m for m in model.policy.features_extractor.modules() if isinstance(m, nn.Conv2d)]


@pytest.mark.parametrize("task", ["joint_attention", "mirror"])
def test_ppo_learns_and_predicts_through_the_cnn(task, tmp_path):
    """joint_attention: eyes + vector, Box action; mirror: eyes only, Discrete action; saved
    and loaded (the shared eye encoder too), the same actions."""
    env = make_env(task, **SMALL)
    policy, kw = policy_spec(env.observation_space)
    model = PPO(policy, env, n_steps=64, batch_size=32, n_epochs=1, seed=0, device="cpu",
                policy_kwargs=kw)
    assert len(_convs(model)) == 3
    model.learn(128)
    obs, _ = env.reset(seed=1)
    action, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(action if task != "mirror" else int(action))
    model.save(tmp_path / "model.zip")
    loaded = PPO.load(tmp_path / "model.zip", device="cpu")
    assert isinstance(loaded.policy.features_extractor, EyesExtractor)
    np.testing.assert_array_equal(loaded.predict(obs, deterministic=True)[0], action)
    env.close()


def test_sac_learns_through_the_cnn():
    env = make_env("joint_attention", **SMALL)
    policy, kw = policy_spec(env.observation_space)
    model = SAC(policy, env, buffer_size=200, learning_starts=32, batch_size=16, seed=0,
                device="cpu", policy_kwargs=kw)
    assert len([m for m in model.actor.features_extractor.modules()
                if isinstance(m, nn.Conv2d)]) == 3
    model.learn(48)
    obs, _ = env.reset(seed=1)
    action, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(action)
    env.close()


def _space(px: int, channels: int = 3, vector: int = 5) -> spaces.Dict:
    parts = {eye: spaces.Box(0, 255, (channels, px, px), np.uint8) for eye in EYES}
    if vector:
        parts[VECTOR_KEY] = spaces.Box(-np.inf, np.inf, (vector,), np.float32)
    return spaces.Dict(parts)


@pytest.mark.parametrize("px", [32, 64, 96, 128])
@pytest.mark.parametrize("channels", [3, 12])
def test_the_extractor_fits_32_to_128_px(px, channels):
    space = _space(px, channels)
    ex = EyesExtractor(space)
    assert ex.features_dim == 2 * 128 + 5
    batch = {eye: torch.randint(0, 256, (4, channels, px, px), dtype=torch.uint8).float()
             for eye in EYES}
    batch[VECTOR_KEY] = torch.randn(4, 5)
    out = ex(batch)
    assert out.shape == (4, ex.features_dim) and torch.isfinite(out).all()
    assert torch.equal(out[:, -5:], batch[VECTOR_KEY])         # the vector passes through
    n_convs = sum(isinstance(m, nn.Conv2d) for m in ex.encoders["eye_left"].modules())
    assert n_convs == (3 if px <= 64 else 4)


def test_the_extractor_options():
    space = _space(32)
    shared = EyesExtractor(space)
    assert shared.encoders["eye_left"] is shared.encoders["eye_right"]
    apart = EyesExtractor(space, share_weights=False, vector_dim=16, image_dim=32)
    assert apart.encoders["eye_left"] is not apart.encoders["eye_right"]
    assert apart.features_dim == 2 * 32 + 16
    n_shared = sum(p.numel() for p in shared.parameters())
    n_one = sum(p.numel() for p in ImageEncoder((3, 32, 32)).parameters())
    assert n_shared == n_one        # the eyes' encoder counted once
    eyes_only = EyesExtractor(_space(32, vector=0))
    assert eyes_only.features_dim == 256
    # pixels are scaled inside: raw 0..255 in, the layers see [0, 1]
    enc = ImageEncoder((3, 32, 32))
    x = torch.rand(2, 3, 32, 32)
    torch.testing.assert_close(enc(x * 255), enc.head(enc.cnn(x)))
    with pytest.raises(TypeError):
        EyesExtractor(spaces.Dict({"v": spaces.Box(-1, 1, (3,), np.float32)}))


def test_the_vector_can_be_normalised():
    """``normalize_vector``: RunningNorm on the non-image keys, learnt in training mode only."""
    ex = EyesExtractor(_space(32, vector=4), normalize_vector=True)
    batch = {eye: torch.zeros(8, 3, 32, 32) for eye in EYES}
    batch[VECTOR_KEY] = torch.arange(32.0).reshape(8, 4) * 10 + 5
    ex.train()
    ex(batch)
    assert float(ex.norm.count) >= 8 and float(ex.norm.mean.abs().max()) > 1
    ex.eval()
    with torch.no_grad():
        out = ex(batch)[:, -4:]
    assert float(out.abs().max()) < 3         # shifted and scaled
    assert "norm.mean" in ex.state_dict()      # saved with the policy
    name, kw = policy_spec(_space(32, vector=4), normalize_vector=True)
    assert kw["features_extractor_kwargs"] == {"normalize_vector": True}
    with pytest.raises(TypeError, match="without images"):
        policy_spec(spaces.Box(-1, 1, (3,), np.float32), normalize_vector=True)


def test_policy_for_passes_the_normalisers_floor():
    """``min_std`` (``--obs-min-std``) reaches the normaliser of either policy, only with
    ``normalize_obs``; a model built from the keywords has it."""
    from mimo_social.train.encoders import policy_for
    from mimo_social.train.obs_norm import RunningNorm
    _, kw = policy_for(_space(32, vector=4), {}, True, min_std=0.02)
    assert kw["policy_kwargs"]["features_extractor_kwargs"] == {"normalize_vector": True,
                                                                "norm_min_std": 0.02}
    ex = EyesExtractor(_space(32, vector=4), **kw["policy_kwargs"]["features_extractor_kwargs"])
    assert ex.norm.min_std == 0.02
    _, kw = policy_for(_space(32, vector=4), {}, True)
    assert kw["policy_kwargs"]["features_extractor_kwargs"] == {"normalize_vector": True}
    box = spaces.Box(-1, 1, (3,), np.float32)
    _, kw = policy_for(box, {}, True, min_std=0.05)
    assert kw["policy_kwargs"]["features_extractor_class"] is RunningNorm
    assert kw["policy_kwargs"]["features_extractor_kwargs"] == {"min_std": 0.05}
    assert policy_for(box, {}, False, min_std=0.05) == ("MlpPolicy", {})


class Frames(gym.Env):
    """A tiny env whose eye shows the step count (each frame different) and a vector."""

    def __init__(self):
        self.observation_space = spaces.Dict({
            "eye": spaces.Box(0, 255, (16, 16, 3), np.uint8),
            "state": spaces.Dict({"a": spaces.Box(-2, 2, (2,), np.float32)})})
        self.action_space = spaces.Discrete(2)
        self.t = 0

    def _obs(self):
        img = np.full((16, 16, 3), self.t, np.uint8)
        img[..., 1] += 100      # channels differ, so a wrong transpose shows
        return {"eye": img, "state": {"a": np.array([self.t, -1], np.float32) / 10}}

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 7
        return self._obs(), {}

    def step(self, action):
        self.t += 1
        return self._obs(), 0.0, False, False, {}


def test_frame_stacking_content():
    env = DictObservationWrapper(Frames(), frame_stack=3)
    assert env.observation_space["eye"].shape == (9, 16, 16)
    assert env.observation_space[VECTOR_KEY].shape == (2,)
    obs, _ = env.reset()
    first = Frames().reset()[0]["eye"].transpose(2, 0, 1)
    for k in range(3):                      # reset fills every slot with its frame
        np.testing.assert_array_equal(obs["eye"][3 * k:3 * k + 3], first)
    seen = [7, 7, 7]
    for _ in range(4):
        obs, *_ = env.step(0)
        seen.append(seen[-1] + 1)
        want = seen[-3:]                    # oldest first
        assert [int(obs["eye"][3 * k, 0, 0]) for k in range(3)] == want
        assert [int(obs["eye"][3 * k + 1, 0, 0]) for k in range(3)] == [t + 100 for t in want]
        np.testing.assert_allclose(obs[VECTOR_KEY], [seen[-1] / 10, -0.1])
    assert env.observation_space.contains(obs)
    with pytest.raises(ValueError, match="frame_stack"):
        DictObservationWrapper(Frames(), frame_stack=3.5)
    with pytest.raises(ValueError, match="smaller side"):
        DictObservationWrapper(Frames(), frame_stack=6)  # 18 channels > 16 px


def test_frame_stacking_a_vision_task():
    stacked = make_env("joint_attention", frame_stack=2, **SMALL)
    single = make_env("joint_attention", **SMALL)
    assert stacked.observation_space["eye_left"].shape == (6, PX, PX)
    assert policy_spec(stacked.observation_space)[0] == "MultiInputPolicy"
    a, _ = stacked.reset(seed=5)
    b, _ = single.reset(seed=5)
    for eye in EYES:
        np.testing.assert_array_equal(a[eye][:3], a[eye][3:])
        np.testing.assert_array_equal(a[eye][3:], b[eye])
    act = stacked.action_space.sample()
    a2, *_ = stacked.step(act)
    b2, *_ = single.step(act)
    for eye in EYES:
        np.testing.assert_array_equal(a2[eye][:3], b[eye])
        np.testing.assert_array_equal(a2[eye][3:], b2[eye])
    np.testing.assert_array_equal(a2[VECTOR_KEY], b2[VECTOR_KEY])
    stacked.close()
    single.close()
