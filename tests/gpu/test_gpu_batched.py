"""The batched env's interface on Warp's CPU device: actuation models (positional agrees with
the CPU env, unknown models are refused), proprioception in the CPU sense's layout, per-world
resets, bad actions, overflowing contact buffers, the device chosen, and high five."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social.envs import free_play_v0, high_five_v0  # noqa: E402
from mimo_social.gpu import BatchedEnv, describe, has_gpu, pick_device  # noqa: E402

W = 3


def _cpu_step(env, actions):
    space = env.action_space(env.possible_agents[0])
    wrap = (lambda u: {"motors": u, "expression": 0}) if hasattr(space, "spaces") \
        else (lambda u: u)
    return env.step({a: wrap(u) for a, u in actions.items()})[0]


def _pair(make, worlds=W):
    batched = BatchedEnv(make(), worlds, device="cpu", seed=0)
    cpus = [make() for _ in range(worlds)]
    return batched, batched.reset(), cpus, [c.reset(seed=0)[0] for c in cpus]


def _random(batched, rng):
    return {a: rng.uniform(-1, 1, (batched.nworld, batched.n_controls(a))).astype(np.float32)
            for a in batched.agents}


@pytest.mark.parametrize("task", ["free_play_positional", "high_five"])
def test_gpu_worlds_with_their_own_actions_follow_their_cpu_envs(task):
    make = (lambda: free_play_v0.parallel_env(n_agents=1, actuation="positional")) \
        if task == "free_play_positional" else high_five_v0.parallel_env
    batched, _, cpus, _ = _pair(make)
    rng = np.random.default_rng(2)
    errors = []
    for _ in range(20):
        acts = _random(batched, rng)
        batched.step(acts)
        row = []
        for w, c in enumerate(cpus):
            _cpu_step(c, {a: v[w] for a, v in acts.items()})
            row.append(np.abs(batched.qpos[w].numpy() - c.world.data.qpos).max())
        errors.append(row)
    errors = np.array(errors)
    assert errors.shape == (20, W)
    assert errors[:3].max() < 1e-4 and errors[19].max() < 5e-3, errors[[0, 2, 19]]


def test_gpu_proprioception_has_the_cpu_layout_and_values():
    """Every component (qpos, qvel, torque, limits, actuation) where the CPU sense has it, with
    the proprioceptive and motor delays (2 steps each at 18 months), over 6 steps."""
    make = lambda: free_play_v0.parallel_env(n_agents=2, delays="developmental")  # noqa: E731
    batched, obs, cpus, cpu_obs = _pair(make, 2)
    rng = np.random.default_rng(3)
    for t in range(7):
        for w, c in enumerate(cpus):
            for i, a in enumerate(batched.agents):
                got, want = obs[a]["proprioception"][w].numpy(), cpu_obs[w][a]["proprioception"]
                assert got.shape == want.shape == c.observation_space(a)["proprioception"].shape
                sl = c.senses[i][0].slices
                for part, tol in (("qpos", 1e-4), ("limits", 1e-2), ("actuation", 1e-3)):
                    assert np.abs(got[sl[part]] - want[sl[part]]).max() < tol, (t, part)
                # velocities and joint torques: float32 against float64 (rad/s, Nm)
                for part in ("qvel", "torque"):
                    assert np.allclose(got[sl[part]], want[sl[part]], rtol=1e-2, atol=2e-2), \
                        (t, part, np.abs(got[sl[part]] - want[sl[part]]).max())
        if t == 6:
            break
        acts = _random(batched, rng)
        obs, _ = batched.step(acts)
        cpu_obs = [_cpu_step(c, {a: v[w] for a, v in acts.items()}) for w, c in enumerate(cpus)]


def test_gpu_a_world_reset_starts_over_and_leaves_the_others_going():
    make = lambda: free_play_v0.parallel_env(n_agents=1)  # noqa: E731
    batched, start, cpus, _ = _pair(make)
    q0 = batched.qpos.numpy().copy()
    rng = np.random.default_rng(4)
    for _ in range(5):
        acts = _random(batched, rng)
        batched.step(acts)
        for w, c in enumerate(cpus):
            _cpu_step(c, {a: v[w] for a, v in acts.items()})
    moved = batched.qpos.numpy().copy()
    obs = batched.reset(np.array([True, False, True]))
    q = batched.qpos.numpy()
    assert np.array_equal(q[[0, 2]], q0[[0, 2]]) and np.array_equal(q[1], moved[1])
    assert np.abs(moved[[0, 2]] - q0[[0, 2]]).max() > 1e-3      # they had moved
    a = batched.agents[0]
    assert np.allclose(obs[a]["proprioception"][0].numpy(), start[a]["proprioception"][0].numpy())
    cpus[0].reset(seed=0)
    for _ in range(3):      # world 0 follows a fresh CPU env again, world 1 its old one
        acts = _random(batched, rng)
        batched.step(acts)
        for w in (0, 1):
            _cpu_step(cpus[w], {a: v[w] for a, v in acts.items()})
            assert np.abs(batched.qpos[w].numpy() - cpus[w].world.data.qpos).max() < 1e-4


def test_gpu_an_actuation_model_the_device_does_not_know_is_refused_by_name():
    """The three models run on the device (muscles: tests/gpu/test_gpu_muscle.py); another
    object (e.g. a subclass with other dynamics) is refused, naming the agent and the model."""
    from mimo_social.body.actuation import SpringDamper
    from mimo_social.gpu import check_actuation

    class Stiffer(SpringDamper):
        name = "stiffer"
    act = Stiffer.__new__(Stiffer)
    with pytest.raises(ValueError, match=r"infant_0: actuation='stiffer' does not run on the "
                                         r"GPU backend; allowed: spring_damper, positional, "
                                         r"muscle"):
        check_actuation("infant_0", act)


def test_gpu_bad_actions_and_settings_are_errors_that_say_what_is_allowed():
    batched = BatchedEnv(free_play_v0.parallel_env(n_agents=1), 2, device="cpu")
    a, n = batched.agents[0], batched.n_controls(batched.agents[0])
    with pytest.raises(ValueError, match=r"shape \(2, 3\); expected \(2, %d\)" % n):
        batched.step({a: np.zeros((2, 3))})
    with pytest.raises(ValueError, match="NaN/inf"):
        batched.step({a: np.full((2, n), np.nan)})
    with pytest.raises(ValueError, match="one \\(nworld, n_controls\\) array per agent"):
        batched.step({})
    for bad in (0, -1, 2.5, True):
        with pytest.raises(ValueError, match="nworld"):
            BatchedEnv(free_play_v0.parallel_env(n_agents=1), bad, device="cpu")


def test_gpu_a_step_beyond_the_contact_buffer_is_an_error_naming_the_setting():
    batched = BatchedEnv(free_play_v0.parallel_env(n_agents=1), 2, device="cpu", nconmax=2)
    zeros = {a: np.zeros((2, batched.n_controls(a))) for a in batched.agents}
    with pytest.raises(RuntimeError, match="give a larger nconmax"):
        for _ in range(10):     # the feet settle onto the floor within a few steps
            batched.step(zeros)


@pytest.mark.skipif(has_gpu(), reason="checks the machine without a GPU")
def test_gpu_without_a_gpu_the_cpu_device_is_chosen_and_named():
    assert pick_device() == "cpu"
    assert describe("cpu") == "no GPU: Warp's CPU device"
    with pytest.raises(ValueError, match="Warp sees no GPU here"):
        pick_device("cuda")
    with pytest.raises(ValueError, match="allowed: None"):
        pick_device("tpu")
