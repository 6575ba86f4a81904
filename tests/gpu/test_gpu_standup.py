"""Stand-up's task logic on the device (:class:`~mimo_social.gpu.motor_tasks.BatchedStandup`), on
Warp's CPU device, against the CPU env on the catalogue's scripted episodes: the reward (the
head's height above the reference minus the control cost), the start height of each world's
seed, success after the hold, no termination."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from test_gpu_tasks import SEEDS, check, run_pair  # noqa: E402 (on the path)

from mimo_social.envs import standup_v0  # noqa: E402
from mimo_social.envs.catalog import entry  # noqa: E402
from mimo_social.gpu import BatchedTaskEnv, GymVectorEnv  # noqa: E402


@pytest.fixture(scope="module")
def standup():
    return BatchedTaskEnv(standup_v0.parallel_env(), len(SEEDS), device="cpu", seed=SEEDS[0])


def test_gpu_standup_rewards_and_success_are_the_cpu_envs(standup):
    """Free running: the scripted controller's actions on both sides. The rewards agree within
    1e-5 over the first 100 steps and 2e-4 over the first 200 (the child pulls itself up); once
    it stands it sways, and float32 physics parts from the CPU's (measured: 6 mm and 2.4 cm of
    head height apart at step 500); success agrees on every step."""
    records, cpus = run_pair(standup, standup_v0.parallel_env,
                             {"infant_0": entry("standup").controller})
    for r in records:
        diff = np.abs(r[:, 0] - r[:, 1])
        print("largest reward difference, first 100 / 200 / 500 steps:", diff[:100].max(),
              diff[:200].max(), diff.max(), "; first success", np.argmax(r[:, 3] > 0))
        assert len(r) == 500 and diff[:100].max() < 1e-5 and diff[:200].max() < 2e-4
        assert r[-1, 3] == 1.0 and (r[:, 2] == r[:, 3]).all()
        assert not r[:, 4].any() and not r[:, 5].any()        # success does not end it
    starts = standup.task.start.tolist()
    assert starts == pytest.approx([c.unwrapped.task.start_height for c in cpus], abs=1e-6)
    assert starts[0] != starts[1]                              # each seed's own settling


def test_gpu_standup_task_logic_over_one_step_is_the_cpus(standup):
    """Each world's state copied from its CPU env before every step."""
    records, _ = run_pair(standup, standup_v0.parallel_env,
                          {"infant_0": entry("standup").controller}, force=True)
    check(records, 1e-4)


def test_gpu_standup_without_actions_does_not_succeed_and_pays_no_cost():
    tenv = BatchedTaskEnv(standup_v0.parallel_env(max_steps=60), 2, device="cpu", seed=0)
    tenv.reset(seed=0)
    zero = {"infant_0": np.zeros((2, tenv.n_controls("infant_0")), np.float32)}
    for _ in range(59):
        _, rew, term, trunc, infos = tenv.step(zero, autoreset=False)
        assert not infos["is_success"].any() and not term.any() and not trunc.any()
        assert (infos["control_cost"] == 0).all()
    _, rew, term, trunc, infos = tenv.step(zero, autoreset=False)
    assert trunc.all() and not term.any()
    np.testing.assert_allclose(rew["infant_0"].numpy(), (infos["head_height"]
                                                         - tenv.task.ref).numpy(), atol=1e-6)


def test_gpu_standup_runs_as_a_vector_env():
    v = GymVectorEnv(standup_v0.parallel_env(max_steps=3), 2, device="cpu")
    obs, _ = v.reset(seed=0)
    assert set(obs) == {"proprioception", "vestibular"}
    _, rew, term, trunc, infos = v.step(v.action_space.sample())
    assert rew.shape == (2,) and "head_gain" in infos


def test_gpu_ppo_trains_standup_on_the_device(tmp_path):
    """A tiny run: the learner's input is proprioception and the vestibular sense."""
    import json

    from mimo_social.envs import standup_v0 as su
    from mimo_social.train.gpu_ppo import GpuPPOConfig, read_progress, train_gpu_ppo

    train_gpu_ppo(GpuPPOConfig(task="standup", worlds=2, steps=8, rollout=4, minibatch=8,
                               epochs=1, device="cpu", max_steps=2), tmp_path)
    rows = read_progress(tmp_path / "progress.csv")
    assert rows[0]["episodes"] == 4 and np.isfinite(rows[0]["loss_policy"])
    space = su.parallel_env().observation_space("infant_0")
    meta = json.loads((tmp_path / "config.json").read_text())
    assert meta["observation_size"] == space["proprioception"].shape[0] + \
        space["vestibular"].shape[0]
