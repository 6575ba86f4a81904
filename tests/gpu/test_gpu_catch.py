"""Catch's task logic on the device (:class:`~mimo_social.gpu.motor_tasks.BatchedCatch`), on Warp's
CPU device, against the CPU env on the catalogue's scripted catches: the gaze following the
ball (:class:`~mimo_social.gpu.gaze.BatchedGaze`), each world's ball (radius and mass per
world), the touch and hold counts, success, the rewards with the muscles' effort."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from test_gpu_tasks import SEEDS, check, run_pair  # noqa: E402 (on the path)

from mimo_social.core.kinematics import LookAt  # noqa: E402
from mimo_social.envs import catch_v0  # noqa: E402
from mimo_social.envs.catalog import entry  # noqa: E402
from mimo_social.gpu import BatchedTaskEnv, GymVectorEnv  # noqa: E402
from mimo_social.gpu.gaze import BatchedGaze  # noqa: E402


@pytest.fixture(scope="module")
def catch():
    return BatchedTaskEnv(catch_v0.parallel_env(), len(SEEDS), device="cpu", seed=SEEDS[0])


def test_gpu_catch_task_logic_over_one_step_is_the_cpus(catch):
    """Each world's state copied from its CPU env before every step: rewards (touch, effort,
    the success's payment for the steps left) to 1e-6, success and the end on the same step;
    each world's ball is its seed's."""
    records, cpus = run_pair(catch, catch_v0.parallel_env,
                             {"infant_0": entry("catch").controller}, force=True)
    check(records, 1e-6)
    radius = [c.unwrapped.task.ball_radius for c in cpus]
    assert catch.task.radius.tolist() == pytest.approx(radius, rel=1e-6)
    assert radius[0] != radius[1]
    sizes = catch.batched.model_tensors["geom_size"][:, catch.task.ball_geom, 0]
    assert sizes.tolist() == pytest.approx(radius, rel=1e-6)


def test_gpu_catch_free_running_catches_as_the_cpu_does(catch):
    """Free running, the fingers closing on the ball under float32 physics: both sides catch;
    the first success within 5 steps of the CPU's (measured: 3 and 1 steps earlier); before
    it, the rewards agree to 1e-3 except on steps where one side touches the ball and the
    other not (the touch reward, 1: measured on 11 of 124 and 1 of 109 steps, the fingers
    brushing the ball as it lands)."""
    records, _ = run_pair(catch, catch_v0.parallel_env, {"infant_0": entry("catch").controller})
    for r in records:
        assert r[:, 2].any() and r[-1, 3] == 1.0
        first_dev, first_cpu = int(np.argmax(r[:, 2] > 0)), int(np.argmax(r[:, 3] > 0))
        k = min(first_dev, first_cpu)
        diff = np.abs(r[:k, 0] - r[:k, 1])
        print("first success device / CPU:", first_dev, first_cpu, "; steps apart by more "
              "than 1e-3 before:", int((diff > 1e-3).sum()), "of", k)
        assert abs(first_dev - first_cpu) <= 5
        assert ((diff < 1e-3) | (np.abs(diff - 1.0) < 1e-3)).all()
        assert (diff > 1e-3).mean() < 0.15


def test_the_gaze_on_the_device_is_the_cpus_look_at(catch):
    """The head and eye angles that fixate the ball, every world, against the CPU's LookAt on
    the same state."""
    import mujoco

    catch.reset(seed=4)
    env = catch_v0.parallel_env()
    env.reset(seed=4)
    w = env.unwrapped.world
    look = LookAt(w, 0, w.agents[0].gaze_idx)
    want = look(w.model, w.data, "body", int(w.prop_bodies["ball"]))
    gaze = BatchedGaze(look, catch.batched)
    catch.batched.load([0], [catch.batched.snapshot(env.unwrapped)])
    mujoco.mj_forward(w.model, w.data)
    gaze.fixate(catch.task.ball_body)
    got = catch.batched.qpos[0, gaze.qpos].numpy()
    np.testing.assert_allclose(got, want, atol=1e-5)
    assert np.abs(want).max() > 0.05                  # it does turn


def test_gpu_catch_runs_as_a_vector_env_and_observes_the_ball_size():
    v = GymVectorEnv(catch_v0.parallel_env(max_steps=3), 2, device="cpu")
    obs, _ = v.reset(seed=0)
    assert obs["ball_size"].shape == (2, 1)
    assert obs["ball_size"][:, 0].tolist() == pytest.approx(v.tenv.task.radius.tolist())
    _, rew, *_ = v.step(v.action_space.sample())
    assert rew.shape == (2,)


def test_catch_with_positional_actuation_is_refused_on_the_device():
    with pytest.raises(ValueError, match="catch: actuation='positional' does not run on the "
                                         "GPU backend"):
        BatchedTaskEnv(catch_v0.parallel_env(actuation="positional"), 1, device="cpu")


def test_gpu_ppo_trains_catch_on_the_device(tmp_path):
    """A tiny run: the learner's input is proprioception, the hand's skin and the ball size."""
    import json

    from mimo_social.train.gpu_ppo import GpuPPOConfig, read_progress, train_gpu_ppo

    train_gpu_ppo(GpuPPOConfig(task="catch", worlds=2, steps=8, rollout=4, minibatch=8,
                               epochs=1, device="cpu", max_steps=2), tmp_path)
    assert np.isfinite(read_progress(tmp_path / "progress.csv")[0]["loss_policy"])
    space = catch_v0.parallel_env().observation_space("infant_0")
    meta = json.loads((tmp_path / "config.json").read_text())
    assert meta["observation_size"] == space["proprioception"].shape[0] + \
        space["touch"].shape[0] + 1
