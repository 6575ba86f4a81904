"""The batched task envs as learners see them (issue 34), on Warp's CPU device: the Gymnasium
vector env (spaces, dtypes, seeding, same-step autoreset, the one-learner high five) and the
TorchRL env (TorchRL's own spec check, its multi-agent group, partial resets), with the
checks of Gymnasium's env checker that apply to a vector env: observations in the
observation space, the same seed giving the same episode and another seed another, bad
actions refused with a message naming the agent."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

import torch  # noqa: E402
from gymnasium.utils.env_checker import data_equivalence  # noqa: E402
from gymnasium.vector import AutoresetMode, VectorEnv  # noqa: E402
from gymnasium.vector.utils import batch_space  # noqa: E402

from mimo_social.envs import high_five_v0, reach_v0  # noqa: E402
from mimo_social.gpu import GymVectorEnv  # noqa: E402

N = 2
MAX_STEPS = 3


@pytest.fixture(scope="module")
def reach():
    return GymVectorEnv(reach_v0.parallel_env(max_steps=MAX_STEPS), N, device="cpu",
                        numpy=True)


def test_gpu_vector_env_declares_its_spaces_and_autoreset_mode(reach):
    v = reach
    assert isinstance(v, VectorEnv) and v.num_envs == N
    assert v.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP
    cpu = reach_v0.parallel_env()
    assert list(v.single_observation_space.spaces) == ["proprioception"]
    assert v.single_observation_space["proprioception"] == \
        cpu.observation_space("infant_0")["proprioception"]
    assert v.single_action_space == cpu.action_space("infant_0")
    assert v.observation_space == batch_space(v.single_observation_space, N)
    assert v.action_space == batch_space(v.single_action_space, N)


def test_gpu_vector_env_seeds_and_observations_are_the_cpu_envs(reach):
    v = reach
    obs, infos = v.reset(seed=5)
    assert obs in v.observation_space and obs["proprioception"].dtype == np.float32
    for w in range(N):
        want = reach_v0.parallel_env().reset(seed=5 + w)[0]["infant_0"]["proprioception"]
        assert np.abs(obs["proprioception"][w] - want).max() < 1e-5
    assert set(infos) >= {"is_success", "_is_success", "distance", "_distance"}
    again, _ = v.reset(seed=5)
    assert data_equivalence(obs, again)
    other, _ = v.reset(seed=6)
    assert not data_equivalence(obs, other)


def test_gpu_vector_env_resets_finished_worlds_in_the_same_step(reach):
    v = reach
    v.reset(seed=5)
    rng = np.random.default_rng(0)
    for t in range(1, MAX_STEPS + 2):
        obs, rew, term, trunc, infos = v.step(rng.uniform(-1, 1, (N, 8)).astype(np.float32))
        assert rew.shape == term.shape == trunc.shape == (N,)
        assert rew.dtype == np.float32 and term.dtype == trunc.dtype == np.bool_
        assert obs in v.observation_space
        assert not term.any()
        assert trunc.all() == (t == MAX_STEPS) and infos["_final_obs"].all() == (t == MAX_STEPS)
        if t == MAX_STEPS:
            final = infos["final_obs"]["proprioception"]
            for w in range(N):
                # the next episode of world w: seed 5 + w + N (its second)
                want = reach_v0.parallel_env().reset(seed=5 + w + N)[0]["infant_0"]
                assert np.abs(obs["proprioception"][w] - want["proprioception"]).max() < 1e-5
                assert np.abs(final[w] - want["proprioception"]).max() > 1e-3
            assert infos["final_info"]["distance"].shape == (N,)


def test_gpu_vector_env_hands_out_device_tensors():
    v = GymVectorEnv(reach_v0.parallel_env(), 1, device="cpu", seed=3)
    obs, _ = v.reset()
    obs, rew, term, trunc, _ = v.step(torch.zeros((1, 8)))
    assert all(isinstance(x, torch.Tensor) for x in (obs["proprioception"], rew, term, trunc))


def test_gpu_vector_env_high_five_with_its_scripted_partner():
    v = GymVectorEnv(high_five_v0.scripted_env(), N, device="cpu", numpy=True)
    cpu = high_five_v0.scripted_env().observation_space("infant_0")
    assert list(v.single_observation_space.spaces) == ["proprioception", "touch", "vestibular"]
    assert v.single_observation_space["touch"] == cpu["touch"]       # the hand's skin
    assert v.single_action_space.shape == (8,)
    obs, _ = v.reset(seed=0)
    obs, rew, term, trunc, infos = v.step(v.action_space.sample())
    assert obs in v.observation_space and rew.shape == (N,)
    assert infos["hand_feels_partner"].shape == (N,)
    with pytest.raises(ValueError, match=r"infant_0: motors of shape \(2, 7\); expected "
                                         r"\(2, 8\)"):
        v.step(np.zeros((N, 7), np.float32))
    with pytest.raises(ValueError, match=r"GymVectorEnv takes one learner; this env has "
                                         r"\['infant_0', 'infant_1'\]"):
        GymVectorEnv(high_five_v0.parallel_env(), 1, device="cpu")


def test_gpu_torchrl_env_passes_torchrls_checks_and_resets_some_worlds():
    pytest.importorskip("torchrl", reason="torchrl is not installed (the gpu extra)")
    from torchrl.envs.utils import check_env_specs

    from mimo_social.gpu import TorchRLEnv
    env = TorchRLEnv(high_five_v0.parallel_env(max_steps=MAX_STEPS), N, device="cpu")
    assert env.group_map == {"agents": ["infant_0", "infant_1"]}
    assert env.batch_size == torch.Size([N])
    check_env_specs(env)
    roll = env.rollout(MAX_STEPS + 1, break_when_any_done=False)
    assert roll["next", "agents", "reward"].shape == (N, MAX_STEPS + 1, 2, 1)
    done = roll["next", "done"][..., 0]
    assert done[:, MAX_STEPS - 1].all() and not done[:, :MAX_STEPS - 1].any()
    # a reset of world 0 only (as step_and_maybe_reset sends it): world 1 keeps its observation
    td = env.reset()
    td = env.step(td.set(("agents", "action"), env.action_spec.rand()[("agents", "action")]))
    before = td["next", "agents", "observation", "proprioception"].clone()
    nxt = td["next"].clone()
    nxt.set("_reset", torch.tensor([[True], [False]]))
    after = env.reset(nxt)
    got = after["agents", "observation", "proprioception"]
    cpu = high_five_v0.parallel_env().reset(seed=env.tenv.seed_of(0))[0]
    for j, a in enumerate(env.learners):   # world 0: its next episode's start
        assert np.abs(got[0, j].numpy() - cpu[a]["proprioception"]).max() < 1e-5
    assert torch.equal(got[1], before[1]) and not torch.equal(got[0], before[0])
    assert env.tenv.steps.tolist() == [0, 1]     # world 1 goes on where it was
