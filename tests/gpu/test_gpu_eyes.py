"""The eyes on the device (:mod:`mimo_social.gpu.eyes`), on Warp's CPU device: every agent's
``eye_left`` / ``eye_right`` in the CPU sense's layout, rendered by MuJoCo Warp's batch
renderer: the CPU's view of the scene (the same bodies in the same places; the shading and the
faces' features differ: docs/gpu.md), following each world's state, held back by the vision
delay, re-rendered at resets (the blur, fovea, depth and ``every``: test_gpu_eye_optics.py)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social.envs import high_five_v0  # noqa: E402
from mimo_social.gpu import BatchedEnv, BatchedTaskEnv, device_spaces  # noqa: E402
from mimo_social.senses.vision import eye_images, render_now  # noqa: E402

EYES64 = {"width": 64, "height": 48}
KEYS = ("eye_left", "eye_right")


def _make(**kw):
    return high_five_v0.parallel_env(vision=dict(EYES64, **kw.pop("vision", {})), **kw)


def _agree(dev, cpu):
    """Mean absolute difference (of 255) and correlation of two images."""
    d, c = np.asarray(dev, float), np.asarray(cpu, float)
    return np.abs(d - c).mean(), np.corrcoef(d.ravel(), c.ravel())[0, 1]


def _reset_cpu():
    env = _make()
    env.reset(seed=0)
    return env


def _cpu_step(env, acts, w=0):
    space = env.action_space("infant_0")
    return env.step({a: {"motors": u[w], "expression": 0} if hasattr(space, "spaces") else u[w]
                     for a, u in acts.items()})[0]


@pytest.fixture(scope="module")
def pair():
    b = BatchedEnv(_make(), 2, device="cpu", seed=0)
    cpu = _make()
    return b, cpu


def test_the_eyes_are_observed_in_the_cpu_layout(pair):
    b, cpu = pair
    obs = b.reset()
    space = cpu.observation_space("infant_0")
    for a in b.agents:
        for k in KEYS:
            assert obs[a][k].shape == (2,) + space[k].shape == (2, 48, 64, 3)
            assert obs[a][k].dtype == b.torch.uint8
    tenv = BatchedTaskEnv(high_five_v0.scripted_env(vision=EYES64), 1, device="cpu")
    spaces_, _ = device_spaces(tenv, "infant_0")
    assert all(spaces_[k] == space[k] for k in KEYS)
    off = BatchedEnv(_make(), 1, device="cpu", eyes=False)
    assert off.eyes is None and all(k not in off.reset()["infant_0"] for k in KEYS)


def test_each_eye_sees_what_the_cpu_eye_sees_at_reset_and_after_steps(pair):
    """Both infants' eyes at reset and after 10 steps of the same actions: within 25 of 255 on
    average (measured 17-19: the renderer's shading) and correlated above 0.9 (0.95); an eye's
    image is more like its own CPU eye's than the other infant's (a like view of a like scene:
    0.86)."""
    b, cpu = pair
    obs = b.reset()
    o, _ = cpu.reset(seed=0)
    acts = {a: np.full((2, b.n_controls(a)), 0.3, np.float32) for a in b.agents}
    for when in ("reset", "10 steps"):
        if when != "reset":
            for _ in range(10):
                obs, _ = b.step(acts)
                o = _cpu_step(cpu, acts)
        for a in b.agents:
            for k in KEYS:
                diff, corr = _agree(obs[a][k][0].numpy(), o[a][k])
                assert diff < 25 and corr > 0.9, (when, a, k, diff, corr)
        own = _agree(obs["infant_0"]["eye_left"][0].numpy(), o["infant_0"]["eye_left"])[1]
        _, cross = _agree(obs["infant_0"]["eye_left"][0].numpy(), o["infant_1"]["eye_left"])
        assert cross < own - 0.03, (own, cross)


def test_each_world_is_seen_from_its_own_state(pair):
    """World 1 loaded with a CPU state in which the partner (infant_1) raised its right arm
    above its head: infant_0's image of world 1 follows that state (the CPU's view of it,
    which differs from the reset view: correlation 0.83), world 0's stays the reset view."""
    b, _ = pair
    start = b.reset()["infant_0"]["eye_left"][0].numpy().copy()
    moved = _make()
    moved.reset(seed=0)
    w = moved.unwrapped.world
    a = w.agents[1]
    names = list(a.actuated_names)
    for joint, angle in (("right_shoulder_abduction", 3.1), ("right_elbow", -1.5),
                         ("right_shoulder_horizontal", 0.8)):
        w.data.qpos[a.qpos_adr[a.actuated_joint_idx[names.index(joint)]]] = angle
    mujoco.mj_forward(w.model, w.data)
    render_now(moved)
    want = eye_images(moved, "infant_0")["eye_left"]
    obs = b.load([1], [b.snapshot(moved.unwrapped)])
    got = obs["infant_0"]["eye_left"][1].numpy()
    diff, corr = _agree(got, want)
    print("moved arm: device vs CPU", diff, corr, "; vs the reset view", _agree(got, start))
    assert _agree(want, eye_images(_reset_cpu(), "infant_0")["eye_left"])[1] < 0.9
    assert diff < 25 and corr > 0.9, (diff, corr)
    assert _agree(got, start)[1] < corr - 0.05          # the device's view changed too
    np.testing.assert_array_equal(b.eyes.images[0, "eye_left"][0].numpy(), start)


def test_the_vision_delay_holds_the_images_back():
    """With the developmental delays, the eyes' images of step t are those rendered at step
    t - k (k: the env's vision delay in steps); the first k are the reset's."""
    env = _make(delays="developmental")
    k = env.unwrapped.delay_steps("infant_0")["vision"]
    assert k >= 2
    b = BatchedEnv(env, 1, device="cpu", seed=0)
    first = b.reset()["infant_0"]["eye_left"].clone()
    acts = {a: np.full((1, b.n_controls(a)), 0.8, np.float32) for a in b.agents}
    seen, rendered = [], []
    for _ in range(k + 3):
        obs, _ = b.step(acts)
        seen.append(obs["infant_0"]["eye_left"].clone())
        rendered.append(b.eyes.images[0, "eye_left"].clone())
    for t in range(k):
        assert (seen[t] == first).all()
    for t in range(k, k + 3):
        assert (seen[t] == rendered[t - k]).all()
    assert not (rendered[k + 2] == first).all()        # the arms moved into view


def test_a_bad_eyes_value_is_refused():
    with pytest.raises(ValueError, match="eyes='yes' not allowed"):
        BatchedEnv(_make(), 1, device="cpu", eyes="yes")


def test_the_bench_renders_the_eyes_when_asked(tmp_path, capsys):
    import json

    from mimo_social import cli
    path = tmp_path / "gpu.json"
    assert cli.main(["bench", "gpu", "--worlds", "2", "--steps", "1", "--warmup", "0",
                     "--device", "cpu", "--eyes", "16", "--json", str(path)]) == 0
    assert "eyes 16x16" in capsys.readouterr().out
    assert json.loads(path.read_text())["results"][0]["eyes"] == 16


def test_the_vector_envs_hand_out_the_eyes():
    """GymVectorEnv: the eyes in its observation space and observations (uint8, the CPU
    shape); TorchRLEnv: the eyes as bounded uint8 specs, TorchRL's spec check passes."""
    from torchrl.envs.utils import check_env_specs

    from mimo_social.gpu import GymVectorEnv, TorchRLEnv
    small = {"width": 16, "height": 12}
    v = GymVectorEnv(high_five_v0.scripted_env(vision=small, max_steps=3), 2, device="cpu")
    obs, _ = v.reset(seed=0)
    assert v.single_observation_space["eye_left"].shape == (12, 16, 3)
    assert obs["eye_left"].shape == (2, 12, 16, 3) and obs["eye_left"].dtype == v.tenv.torch.uint8
    obs, *_ = v.step(v.action_space.sample())
    assert obs["eye_right"].shape == (2, 12, 16, 3)
    env = TorchRLEnv(high_five_v0.parallel_env(vision=small, max_steps=3), 2, device="cpu")
    spec = env.observation_spec["agents", "observation", "eye_left"]
    assert spec.dtype == env.tenv.torch.uint8 and spec.shape == (2, 2, 12, 16, 3)
    check_env_specs(env)


def test_the_cube_face_textures_become_longitude_latitude_images():
    """The renderer's copy of the model: each face texture (six sides stacked) as a 3n x 2n
    longitude-latitude image of the same bytes: straight ahead (+x) the front side's centre,
    behind the head plain skin; the floor's 2D texture and the model given are unchanged."""
    import mujoco

    from mimo_social.expressions.faces import SKIN_RGB
    from mimo_social.gpu.eyes import ray_traced_textures
    m = _make().unwrapped.world.model
    before = m.tex_data.copy()
    r = ray_traced_textures(m)
    np.testing.assert_array_equal(m.tex_data, before)
    cube = np.flatnonzero(m.tex_type == mujoco.mjtTexture.mjTEXTURE_CUBE)
    assert len(cube) == 7 and (r.tex_type[cube] == mujoco.mjtTexture.mjTEXTURE_2D).all()
    for t in range(m.ntex):
        n, adr = int(m.tex_width[t]), int(m.tex_adr[t])
        if t not in cube:
            assert r.tex_width[t] == n and r.tex_type[t] == m.tex_type[t]
            continue
        w, h = int(r.tex_width[t]), int(r.tex_height[t])
        assert (w, h) == (3 * n, 2 * n)
        img = r.tex_data[adr:adr + w * h * 3].reshape(h, w, 3)
        front = m.tex_data[adr:adr + n * n * 3].reshape(n, n, 3)
        ahead = img[h // 2, 0].astype(int)             # azimuth 0 (+x), elevation 0
        assert np.abs(ahead - front[n // 2, n // 2]).max() <= 40
        np.testing.assert_array_equal(img[h // 2, w // 2], SKIN_RGB)    # behind the head


def test_the_faces_features_are_rendered():
    """Zoomed in on the partner's face (20 degree eyes): with the textures resampled the face
    region shows its features (brows, eyes' outlines, mouth); rendered from the cube textures
    as they are, the renderer shows a plain head. The two images differ in the face."""
    import mimo_social.gpu.eyes as eyes_module
    zoom = {"width": 48, "height": 48, "field_of_view": 20}
    got = BatchedEnv(_make(vision=zoom), 1, device="cpu").reset()["infant_0"]["eye_left"][0]
    real = eyes_module.ray_traced_textures
    try:
        eyes_module.ray_traced_textures = lambda m: m
        plain = BatchedEnv(_make(vision=zoom), 1, device="cpu").reset()["infant_0"]["eye_left"][0]
    finally:
        eyes_module.ray_traced_textures = real
    diff = np.abs(got.numpy().astype(int) - plain.numpy()).max(axis=-1)
    assert (diff > 40).sum() > 30, (diff > 40).sum()
