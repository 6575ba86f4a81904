"""The on-device PPO with eyes (``GpuPPOConfig(eyes=N)``, ``mimo-social train-gpu --eyes N``): the
learner's two eyes rendered on the device and encoded by a CNN in both networks; the policy's
actions follow what its eyes see; runs are deterministic under a seed and evaluate."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")
pytest.importorskip("torchrl", reason="torchrl is not installed (the gpu extra)")

import torch  # noqa: E402

from mimo_social import cli  # noqa: E402
from mimo_social.train import gpu_ppo  # noqa: E402
from mimo_social.train.gpu_networks import EyeEncoder  # noqa: E402
from mimo_social.train.gpu_ppo import GpuPPOConfig, read_progress, train_gpu_ppo  # noqa: E402

TINY = dict(task="reach", worlds=2, steps=16, rollout=4, minibatch=4, epochs=2, device="cpu",
            max_steps=3, eyes=16, seed=5)
CLOCK = ("wall_time_s", "steps_per_s")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("eyes")
    train_gpu_ppo(GpuPPOConfig(**TINY), out)
    return out


def test_the_learner_sees_through_both_eyes(run):
    meta = json.loads((run / "config.json").read_text())
    assert meta["pixels"] == [16, 16, 6] and meta["observation_size"] == 84  # + proprioception
    state = torch.load(run / "policy.pt")
    assert state["module.0.module.eyes.conv.0.weight"].shape == (16, 6, 5, 5)
    rows = read_progress(run / "progress.csv")
    assert len(rows) == 2 and all(np.isfinite(r["loss_policy"]) for r in rows)


def test_the_policys_action_follows_what_its_eyes_see():
    """The same senses with other images give another action; the encoder takes any leading
    dims (worlds x steps, as the advantage estimate hands it)."""
    lo, hi = -torch.ones(3), torch.ones(3)
    actor, critic, _ = gpu_ppo.build_networks(5, lo, hi, GpuPPOConfig(), eyes=(16, 16, 6))
    obs = torch.zeros(2, 5)
    pixels = torch.zeros(2, 16, 16, 6, dtype=torch.uint8)
    pixels[1, 4:12, 4:12, :3] = 255          # a bright square in the left eye of the second
    mode = gpu_ppo.act(actor, {"observation": obs, "pixels": pixels}, explore=False)["action"]
    assert not torch.allclose(mode[0], mode[1])
    enc = EyeEncoder(16, 16)
    assert enc(torch.zeros(4, 3, 16, 16, 6, dtype=torch.uint8)).shape == (4, 3, 128)


def test_a_run_with_eyes_is_deterministic_under_its_seed_and_evaluates(run, tmp_path):
    train_gpu_ppo(GpuPPOConfig(**TINY), tmp_path / "again")
    same = [{k: v for k, v in r.items() if k not in CLOCK}
            for r in read_progress(tmp_path / "again" / "progress.csv")]
    assert same == [{k: v for k, v in r.items() if k not in CLOCK}
                    for r in read_progress(run / "progress.csv")]
    ev = gpu_ppo.evaluate_gpu_ppo(run, worlds=2, device="cpu")
    assert ev["episodes"] == 2 and ev["length_mean"] == 3.0 and np.isfinite(ev["return_mean"])


def test_the_command_passes_the_eyes_and_refuses_a_bad_side(tmp_path, capsys):
    out = tmp_path / "cli"
    assert cli.main(["train-gpu", "--task", "reach", "--worlds", "2", "--steps", "4",
                     "--rollout", "2", "--minibatch", "4", "--epochs", "1", "--max-steps", "2",
                     "--eyes", "16", "--device", "cpu", "--out", str(out)]) == 0
    assert json.loads((out / "config.json").read_text())["config"]["eyes"] == 16
    capsys.readouterr()
    assert cli.main(["train-gpu", "--task", "reach", "--eyes", "8", "--out",
                     str(tmp_path / "bad")]) == 2
    assert "eyes=8 not allowed; allowed: None (no eyes) or an image side from 16 to 256" in \
        capsys.readouterr().err
