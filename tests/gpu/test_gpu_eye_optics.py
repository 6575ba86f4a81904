"""The CPU vision sense's settings on the device (:mod:`mimo_social.gpu.eyes`,
:mod:`mimo_social.gpu.optics`), on Warp's CPU device: the acuity blur and the fovea are the CPU's
own filters applied to the device's render (the same pixels, up to a count), depth images agree
with the CPU's in metres, ``every`` holds the images between renders as the CPU env does, world
by world, and the depth images are observed and delayed in the CPU's spaces."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social.envs import high_five_v0  # noqa: E402
from mimo_social.gpu import BatchedEnv, GymVectorEnv  # noqa: E402
from mimo_social.senses.vision import eye_images, vision_system  # noqa: E402

SIZE = {"width": 64, "height": 48}


def _make(**vision):
    return high_five_v0.parallel_env(vision=dict(SIZE, **vision))


def _first(env, n=2):
    b = BatchedEnv(env, n, device="cpu", seed=0)
    return b, b.reset()


def _counts_apart(a, b):
    d = np.abs(np.asarray(a, int) - np.asarray(b, int))
    return int(d.max()), float((d > 0).mean())


@pytest.fixture(scope="module")
def plain():
    """The device's render at 64x48 and three times that, without blur or fovea, with depth."""
    return (_first(_make(depth=True))[1],
            _first(high_five_v0.parallel_env(vision={"width": 192, "height": 144,
                                                     "depth": True}))[1])


def test_the_acuity_blur_is_the_cpus_filter_on_the_devices_render(plain):
    env = _make(acuity=0.2)        # 0.2 cycles per degree: blurs 48-pixel-tall eyes
    _, obs = _first(env)
    blur = vision_system(env).blurs[0]
    assert blur is not None and blur.sigma_px > 1.0
    for agent in ("infant_0", "infant_1"):
        for eye in ("eye_left", "eye_right"):
            sharp = plain[0][agent][eye][1].numpy()
            got = obs[agent][eye][1].numpy()
            assert _counts_apart(got, blur(sharp))[0] <= 1
            assert np.abs(got.astype(float) - sharp).mean() > 3.0      # it did blur


def test_the_fovea_is_the_cpus_warp_of_the_larger_render_and_sees_what_the_cpu_sees(plain):
    env = _make(fovea=3, acuity=0.2, depth=True)
    _, obs = _first(env)
    system = vision_system(env)
    warp, blur = system.foveas[0], system.blurs[0]
    assert (blur.height, blur.width) == (144, 192)        # blurred at the render size
    big = plain[1]["infant_0"]
    for eye in ("left", "right"):
        got = obs["infant_0"][f"eye_{eye}"][0].numpy()
        assert got.shape == (48, 64, 3)
        assert _counts_apart(got, warp.rgb(blur(big[f"eye_{eye}"][0].numpy())))[0] <= 1
        np.testing.assert_array_equal(obs["infant_0"][f"depth_{eye}"][0].numpy(),
                                      warp.depth(big[f"depth_{eye}"][0].numpy()))
    cpu = _make(fovea=3, acuity=0.2)
    cpu.reset(seed=0)
    want = eye_images(cpu, "infant_0")["eye_left"].astype(float)
    got = obs["infant_0"]["eye_left"][0].numpy().astype(float)
    corr = np.corrcoef(want.ravel(), got.ravel())[0, 1]
    print("fovea: device vs CPU correlation", corr, "mean abs", np.abs(want - got).mean())
    assert corr > 0.95


def test_depth_agrees_with_the_cpus_in_metres(plain):
    cpu = _make(depth=True)
    cpu.reset(seed=0)
    far = float(cpu.unwrapped.world.model.vis.map.zfar * cpu.unwrapped.world.model.stat.extent)
    for agent in ("infant_0", "infant_1"):
        for eye in ("depth_left", "depth_right"):
            want = eye_images(cpu, agent)[eye]
            got = plain[0][agent][eye][0].numpy()
            assert got.dtype == np.float32 and got.shape == (48, 64)
            err = np.abs(got - want)
            print(agent, eye, "median error", np.median(err), "over 5 cm", (err > 0.05).mean())
            assert np.median(err) < 1e-3 and (err > 0.05).mean() < 0.06   # edges differ
            assert ((got == far) == (want == far)).mean() > 0.97          # nothing hit: far
            assert 0.05 < got.min() and got.max() <= far


def test_every_k_holds_the_images_as_the_cpu_does_world_by_world():
    """``every=3``: rendered at reset and every 3rd step after (the CPU env's pattern); a
    world reset later (world 1, before step 5) counts its own steps: next rendered at step 7."""
    b, _ = _first(_make(every=3), 2)
    cpu = _make(every=3)
    cpu.reset(seed=0)
    acts = {a: np.full((2, b.n_controls(a)), 0.7, np.float32) for a in b.agents}
    before = b.eyes.images[0, "eye_left"].numpy().copy()
    before_cpu = eye_images(cpu, "infant_0")["eye_left"].copy()
    changed = {0: [], 1: [], "cpu": []}
    for t in range(1, 8):
        if t == 5:
            b.reset(worlds=np.array([False, True]))
            before[1] = b.eyes.images[0, "eye_left"][1].numpy()
        obs, _ = b.step(acts)
        cpu.step({a: {"motors": acts[a][0], "expression": 0} for a in cpu.agents})
        now, now_cpu = obs["infant_0"]["eye_left"].numpy(), eye_images(cpu, "infant_0")[
            "eye_left"]
        for w in (0, 1):
            if not np.array_equal(now[w], before[w]):
                changed[w].append(t)
        if not np.array_equal(now_cpu, before_cpu):
            changed["cpu"].append(t)
        before, before_cpu = now.copy(), now_cpu.copy()
    assert changed == {0: [3, 6], 1: [3, 7], "cpu": [3, 6]}
    assert b.eyes.count.tolist() == [8, 4]


def test_depth_is_observed_delayed_and_in_the_vector_envs_spaces():
    env = high_five_v0.parallel_env(vision={"width": 16, "height": 12, "depth": True},
                                    delays="developmental")
    k = env.unwrapped.delay_steps("infant_0")["vision"]
    b, obs = _first(env, 1)
    assert list(obs["infant_0"])[-4:] == ["eye_left", "eye_right", "depth_left", "depth_right"]
    first = obs["infant_0"]["depth_left"].clone()
    acts = {a: np.full((1, b.n_controls(a)), 0.8, np.float32) for a in b.agents}
    seen, rendered = [], []
    for _ in range(k + 2):
        obs, _ = b.step(acts)
        seen.append(obs["infant_0"]["depth_left"].clone())
        rendered.append(b.eyes.images[0, "depth_left"].clone())
    assert all((seen[t] == first).all() for t in range(k))
    assert all((seen[t] == rendered[t - k]).all() for t in range(k, k + 2))
    v = GymVectorEnv(high_five_v0.scripted_env(vision={"width": 16, "height": 12,
                                                       "depth": True}, max_steps=3), 2,
                     device="cpu")
    obs, _ = v.reset(seed=0)
    space = v.single_observation_space["depth_right"]
    assert space.shape == (12, 16) and space.dtype == np.float32
    assert obs["depth_right"].shape == (2, 12, 16)
