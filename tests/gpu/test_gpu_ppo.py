"""PPO on the device (:mod:`mimo_social.train.gpu_ppo`, ``mimo-social train-gpu``) on Warp's
CPU device: a few iterations with finite losses, the files it writes, the same progress from
the same seed (and another from another seed), the running normalisation of the observations,
its refusals of bad settings, and the command line."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")
pytest.importorskip("torchrl", reason="torchrl is not installed (the gpu extra)")

import torch  # noqa: E402
from tensordict import TensorDict  # noqa: E402

from mimo_social import cli  # noqa: E402
from mimo_social.envs import high_five_v0, selfbody_v0  # noqa: E402
from mimo_social.train import gpu_ppo  # noqa: E402
from mimo_social.train.gpu_ppo import (PROGRESS_COLUMNS, GpuPPOConfig,  # noqa: E402
                                       RunningObsNorm, read_progress, train_gpu_ppo)

#: 2 worlds, episodes of 3 steps, 2 iterations of 4 steps: every iteration ends episodes
TINY = dict(worlds=2, steps=16, rollout=4, minibatch=4, epochs=2, device="cpu", max_steps=3)
#: columns that depend on the wall clock
CLOCK = ("wall_time_s", "steps_per_s")


def _same(rows):
    return [{k: v for k, v in r.items() if k not in CLOCK} for r in rows]


@pytest.fixture(scope="module")
def reach_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("reach")
    summary = train_gpu_ppo(GpuPPOConfig(task="reach", seed=3, **TINY), out)
    return out, summary


def test_gpu_ppo_runs_iterations_with_finite_losses_and_writes_its_files(reach_run):
    out, summary = reach_run
    rows = read_progress(out / "progress.csv")
    assert summary["iterations"] == len(rows) == 2 and summary["device"] == "cpu"
    header = (out / "progress.csv").read_text().splitlines()[0].split(",")
    assert tuple(header) == PROGRESS_COLUMNS
    assert [r["timesteps"] for r in rows] == [8, 16]
    for r in rows:
        for k in ("loss_policy", "loss_critic", "episode_return_mean", "success_rate"):
            assert np.isfinite(r[k]), (k, r)
        assert r["loss_critic"] > 0 and r["wall_time_s"] > 0
        assert r["episodes"] >= 2 and 0 <= r["success_rate"] <= 1   # episodes of 3 steps
        assert r["episode_length_mean"] <= 3
    meta = json.loads((out / "config.json").read_text())
    assert meta["config"]["task"] == "reach" and meta["observation_size"] == 84
    # policy.pt: the actor's state, the normaliser's statistics in it, loadable into a new one
    state = torch.load(out / "policy.pt")
    lo, hi = -torch.ones(meta["action_size"]), torch.ones(meta["action_size"])
    actor, _, norm = gpu_ppo.build_networks(84, lo, hi, GpuPPOConfig(**TINY))
    actor.load_state_dict(state)
    assert norm.count.item() == 2 + 2 * 8    # the reset's rows, then each rollout's
    td = actor(TensorDict({"observation": torch.zeros(3, 84)}, batch_size=[3]))
    assert td["action"].shape == (3, meta["action_size"])
    assert (td["action"].abs() <= 1).all()


def test_gpu_ppo_is_deterministic_under_a_seed(reach_run, tmp_path):
    out, _ = reach_run
    first = read_progress(out / "progress.csv")
    train_gpu_ppo(GpuPPOConfig(task="reach", seed=3, **TINY), tmp_path / "again")
    again = read_progress(tmp_path / "again" / "progress.csv")
    assert _same(again) == _same(first)
    assert torch.equal(torch.load(out / "policy.pt")["module.0.module.mlp.0.weight"],
                       torch.load(tmp_path / "again" / "policy.pt")
                       ["module.0.module.mlp.0.weight"])
    train_gpu_ppo(GpuPPOConfig(task="reach", seed=4, **TINY), tmp_path / "other")
    other = read_progress(tmp_path / "other" / "progress.csv")
    assert _same(other) != _same(first)


def _tiny_run(task, out, **kw) -> dict:
    """Two worlds, one iteration of 4 steps, episodes of 2 steps: 4 episodes end; returns the
    run's config.json."""
    cfg = GpuPPOConfig(task=task, worlds=2, steps=8, rollout=4, minibatch=8,
                       epochs=1, device="cpu", max_steps=2, **kw)
    train_gpu_ppo(cfg, out)
    rows = read_progress(out / "progress.csv")
    assert len(rows) == 1 and rows[0]["episodes"] == 4 and np.isfinite(rows[0]["loss_policy"])
    return json.loads((out / "config.json").read_text())


def test_gpu_ppo_high_five_learns_beside_its_partner_on_the_device(tmp_path):
    meta = _tiny_run("high_five", tmp_path)
    hand = high_five_v0.scripted_env().observation_space("infant_0")["touch"].shape[0]
    assert meta["observation_size"] == 48 + 6 + hand   # proprioception, vestibular, the hand's
    assert meta["config"]["touch"] is True            # skin


def test_gpu_ppo_selfbody_observes_its_target(tmp_path):
    """Self-body on the device: the policy's input is the arm's proprioception, the skin and
    the one-hot target (``touch=False``: without the skin); the episodes end at the time limit
    (the untrained arm touches nothing)."""
    space = selfbody_v0.parallel_env().observation_space("infant_0")
    meta = _tiny_run("selfbody", tmp_path / "touch")
    assert meta["observation_size"] == (space["proprioception"].shape[0]
                                        + space["touch"].shape[0] + 28)
    meta = _tiny_run("selfbody", tmp_path / "none", touch=False)
    assert meta["observation_size"] == space["proprioception"].shape[0] + 28
    with pytest.raises(ValueError, match="touch=1 not allowed"):
        GpuPPOConfig(task="selfbody", touch=1)


def test_gpu_ppo_samples_its_actions_while_collecting():
    """The rollout explores: the same observation gives other actions each time (TorchRL's
    actor gives its mode unless told to sample), within the Box; without exploring, the mode."""
    lo, hi = -torch.ones(3), torch.ones(3)
    actor, _, _ = gpu_ppo.build_networks(5, lo, hi, GpuPPOConfig())
    obs = torch.zeros(64, 5)
    sampled = gpu_ppo.act(actor, obs)["action"]
    assert sampled.shape == (64, 3) and (sampled.abs() <= 1).all()
    assert sampled.std(0).min() > 0.2        # tanh of a unit normal: about 0.6
    mode = gpu_ppo.act(actor, obs, explore=False)["action"]
    assert torch.equal(mode, mode[:1].expand_as(mode))
    assert torch.isfinite(gpu_ppo.act(actor, obs)["action_log_prob"]).all()


def test_gpu_ppo_running_normalisation_is_the_mean_and_variance_of_all_rows():
    rng = np.random.default_rng(0)
    parts = [rng.normal(3.0, 2.0, (n, 4)).astype(np.float32) for n in (5, 1, 17)]
    norm = RunningObsNorm(4)
    for p in parts:
        norm.update(torch.as_tensor(p))
    every = np.concatenate(parts)
    assert np.allclose(norm.mean.numpy(), every.mean(0), atol=1e-5)
    assert np.allclose(norm.var.numpy(), every.var(0), atol=1e-4)
    z = norm(torch.as_tensor(every)).numpy()
    assert np.allclose(z.mean(0), 0, atol=1e-4) and np.allclose(z.std(0), 1, atol=1e-3)
    assert norm(torch.full((1, 4), 1e6)).max().item() == 10.0    # clipped


@pytest.mark.parametrize("setting, value, allowed", [
    ("task", "mirror", "one of reach, high_five, selfbody, standup, catch, rollover"),
    ("worlds", 0, "a positive integer"),
    ("steps", -5, "a positive integer"),
    ("epochs", 1.5, "a positive integer"),
    ("rollout", True, "a positive integer"),
    ("seed", -1, "an integer >= 0"),
    ("learning_rate", 0.0, "a number > 0"),
    ("learning_rate", float("nan"), "a number > 0"),
    ("gamma", 1.5, "a number > 0 and <= 1"),
    ("device", "tpu", "'cpu' or 'cuda'"),
    ("max_steps", 0, "None or a positive integer"),
    ("entropy_coeff", -0.1, "a number >= 0"),
    ("minibatch", 129, "at most worlds * rollout = 4 * 32 = 128"),
    ("eyes", 8, "None (no eyes) or an image side from 16 to 256 pixels"),
    ("eyes", True, "None (no eyes) or an image side from 16 to 256 pixels"),
])
def test_gpu_ppo_refuses_bad_settings_naming_them(setting, value, allowed):
    kw = {"worlds": 4, setting: value}
    with pytest.raises(ValueError) as e:
        GpuPPOConfig(**kw)
    text = str(e.value)
    assert text.startswith(f"{setting}={value!r} not allowed; allowed: ") and allowed in text


def test_gpu_ppo_command_trains_a_tiny_run(tmp_path, capsys):
    out = tmp_path / "run"
    assert cli.main(["train-gpu", "--task", "reach", "--worlds", "2", "--steps", "8",
                     "--rollout", "4", "--minibatch", "8", "--epochs", "1", "--max-steps", "3",
                     "--seed", "1", "--lr", "1e-3", "--device", "cpu", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "device: cpu (no GPU: Warp's CPU device); 1 iterations" in printed
    meta = json.loads((out / "config.json").read_text())["config"]
    assert (meta["worlds"], meta["steps"], meta["rollout"], meta["minibatch"], meta["epochs"],
            meta["max_steps"], meta["seed"], meta["learning_rate"]) == (2, 8, 4, 8, 1, 3, 1,
                                                                         1e-3)
    assert (out / "policy.pt").is_file() and len(read_progress(out / "progress.csv")) == 1
    png = (out / "learning_curve.png").read_bytes()
    assert png.startswith(b"\x89PNG") and len(png) > 10_000


@pytest.mark.parametrize("argv, option", [
    (["--task", "mirror"], "--task"), (["--worlds", "0"], "--worlds"),
    (["--steps", "x"], "--steps"), (["--seed", "-1"], "--seed"), (["--lr", "0"], "--lr"),
    (["--entropy-coeff", "-1"], "--entropy-coeff"), (["--device", "tpu"], "--device")])
def test_gpu_ppo_command_refuses_bad_flags_before_running(argv, option, tmp_path, capsys,
                                                         monkeypatch):
    ran = []
    monkeypatch.setattr(gpu_ppo, "train_gpu_ppo", lambda *a, **k: ran.append(a))
    base = {"--task": "reach", "--out": str(tmp_path / "x")}
    base.update(dict(zip(argv[::2], argv[1::2])))
    with pytest.raises(SystemExit) as e:
        cli.main(["train-gpu", *[x for kv in base.items() for x in kv]])
    assert e.value.code == 2 and not ran
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert last.startswith("mimo-social train-gpu: error: argument") and option in last


def test_gpu_ppo_command_names_a_setting_refused_while_running(tmp_path, capsys):
    """minibatch larger than a rollout's samples: a one-line error naming the setting."""
    assert cli.main(["train-gpu", "--task", "reach", "--worlds", "2", "--rollout", "4",
                     "--minibatch", "9", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("mimo-social train-gpu: error: minibatch=9 not allowed; allowed: at "
                          "most worlds * rollout = 2 * 4 = 8")


def test_gpu_ppo_evaluates_a_run_on_episodes_it_did_not_train_on(reach_run):
    out, _ = reach_run
    ev = gpu_ppo.evaluate_gpu_ppo(out, worlds=3, device="cpu")
    assert ev["episodes"] == 3 and ev["policy"] == "mode" and ev["seed"] == 1_000_000
    assert ev["length_mean"] == 3.0 and 0 <= ev["success_rate"] <= 1   # episodes of 3 steps
    assert np.isfinite(ev["return_mean"]) and ev["return_mean"] < 0    # not at the ball yet
    assert gpu_ppo.evaluate_gpu_ppo(out, worlds=3, device="cpu") == ev
    sampled = gpu_ppo.evaluate_gpu_ppo(out, worlds=3, device="cpu", explore=True)
    assert sampled["return_mean"] != ev["return_mean"]


def test_gpu_ppo_evaluates_a_run_written_before_the_device_had_touch(tmp_path):
    """A run's config.json without ``touch`` (written before the device observed touch) is
    evaluated without the skin, as it was trained."""
    meta = _tiny_run("high_five", tmp_path, touch=False)
    assert meta["observation_size"] == 48 + 6
    del meta["config"]["touch"]
    (tmp_path / "config.json").write_text(json.dumps(meta))
    ev = gpu_ppo.evaluate_gpu_ppo(tmp_path, worlds=2, device="cpu")
    assert ev["episodes"] == 2 and np.isfinite(ev["return_mean"])


def test_gpu_ppo_command_offers_every_task_the_learner_trains():
    from mimo_social.cli import train_gpu
    assert train_gpu.TASKS == tuple(gpu_ppo.TASKS)
