"""The training tooling: ``mimo-social train | eval | compare`` (short runs on reach)."""

import csv
import importlib.util
import json
import shutil

import numpy as np
import pytest
import torch

from mimo_social import cli
from mimo_social.train import compare, evaluate, read_progress, train
from mimo_social.train.tasks import TrainInputError

torch.set_num_threads(1)

FAST_PPO = {"n_steps": 128, "batch_size": 64, "n_epochs": 2}
SHORT = {"max_steps": 60}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("runs") / "reach_ppo"
    res = train("reach", "ppo", 256, 0, out, eval_every=128, eval_episodes=2,
                checkpoint_every=128, progress=False, env_kwargs=SHORT, algo_kwargs=FAST_PPO)
    return out, res


def test_train_writes_model_csv_png_and_checkpoints(run):
    out, res = run
    for name in ("model.zip", "best_model.zip", "config.json", "progress.csv", "episodes.csv",
                 "learning_curve.png"):
        assert (out / name).stat().st_size > 0, name
    assert sorted(p.name for p in (out / "checkpoints").iterdir()) == [
        "model_128_steps.zip", "model_256_steps.zip"]
    p = read_progress(out / "progress.csv")
    assert list(p["timesteps"]) == [128, 256]
    assert np.isfinite(p["eval_return_mean"]).all() and np.isfinite(p["eval_success_rate"]).all()
    with open(out / "episodes.csv", newline="") as f:
        episodes = list(csv.DictReader(f))
    assert episodes and all(int(e["length"]) <= 60 for e in episodes)
    config = json.loads((out / "config.json").read_text())
    assert config["task"] == "reach" and config["algo"] == "ppo" and config["timesteps_done"] >= 256
    assert config["env_kwargs"] == SHORT
    assert {k: config["algo_kwargs"][k] for k in FAST_PPO} == FAST_PPO     # over the shipped
    assert config["algo_kwargs"]["gamma"] == 0.99 and config["policy"] == "MlpPolicy"
    assert (out / "learning_curve.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert res["last_eval"]["timesteps"] == 256


def test_eval_reloads_the_model_and_runs_episodes(run, tmp_path):
    out, _ = run
    a = evaluate(out, episodes=3, seed=5)
    b = evaluate(out, episodes=3, seed=5, model="best")
    assert len(a["returns"]) == 3 and all(n <= 60 for n in a["lengths"])
    c = evaluate(out, episodes=3, seed=5)
    assert a["returns"] == c["returns"]                       # deterministic policy, seeded
    assert np.isfinite(b["return_mean"])
    assert json.loads((out / "eval_results.json").read_text())["episodes"] == 3
    # recording and frames through the command line
    rrd, frames = tmp_path / "ep.rrd", tmp_path / "frames"
    assert cli.main(["eval", str(out), "--episodes", "1", "--record", str(rrd),
                     "--frames", str(frames), "--frame-every", "20"]) == 0
    assert rrd.stat().st_size > 0
    pngs = sorted(frames.glob("*.png"))
    assert pngs and pngs[0].read_bytes()[:4] == b"\x89PNG"


@pytest.mark.skipif(importlib.util.find_spec("imageio") is not None or shutil.which("ffmpeg"),
                    reason="an mp4 encoder is installed")
def test_eval_video_without_an_encoder_says_so(run, tmp_path, capsys):
    out, _ = run
    assert cli.main(["eval", str(out), "--episodes", "1", "--video", str(tmp_path / "v.mp4")]) == 2
    err = capsys.readouterr().err
    assert "no MP4 encoder" in err and "--frames" in err
    assert not (tmp_path / "v.mp4").exists()


def test_cli_train_sac_and_unknown_task(tmp_path, capsys):
    out = tmp_path / "sac"
    assert cli.main(["train", "--task", "reach", "--algo", "sac", "--steps", "64", "--seed", "1",
                     "--out", str(out), "--eval-every", "64", "--eval-episodes", "1",
                     "--checkpoint-every", "0", "--no-progress",
                     "--env-kwargs", '{"max_steps": 30}',
                     "--algo-kwargs", '{"learning_starts": 32, "batch_size": 32}']) == 0
    assert (out / "model.zip").exists() and not (out / "checkpoints").exists()
    assert json.loads((out / "config.json").read_text())["algo_kwargs"]["buffer_size"] == 64
    assert "trained SAC on reach" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        cli.main(["train", "--task", "juggle", "--algo", "ppo", "--steps", "1", "--out", "x"])


def test_compare_trains_seeds_and_plots_them_together(tmp_path):
    png = compare("reach", ["ppo"], seeds=2, steps=128, out=tmp_path, eval_every=64,
                  eval_episodes=1, checkpoint_every=0, progress=False, env_kwargs={"max_steps": 30},
                  algo_kwargs={"n_steps": 64, "batch_size": 32, "n_epochs": 1})
    assert png == tmp_path / "compare.png" and png.stat().st_size > 0
    with open(tmp_path / "compare.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert {(r["algo"], r["seed"]) for r in rows} == {("ppo", "0"), ("ppo", "1")}
    png.unlink()
    assert cli.main(["compare", "--task", "reach", "--algos", "ppo", "--seeds", "2", "--steps",
                     "128", "--out", str(tmp_path), "--plot-only"]) == 0
    assert png.exists()


def test_a_run_saved_before_the_layout_still_loads_and_runs(tmp_path, capsys):
    """tests/data/pre_layout_reach_run: PPO on reach with --normalize-obs, trained by the code of
    commit f078d91 (before the package was laid out in layers); its model.zip names
    ``mimo_social.obs_norm.RunningNorm``."""
    from pathlib import Path

    from stable_baselines3 import PPO

    from mimo_social.train.obs_norm import RunningNorm

    run = tmp_path / "old"
    shutil.copytree(Path(__file__).parents[1] / "data" / "pre_layout_reach_run", run)
    config = json.loads((run / "config.json").read_text())
    assert config["algo_kwargs"]["policy_kwargs"]["features_extractor_class"] == \
        "mimo_social.obs_norm.RunningNorm"
    norm = PPO.load(str(run / "model.zip"), device="cpu").policy.features_extractor
    assert isinstance(norm, RunningNorm)
    res = evaluate(run, episodes=2, seed=3)
    assert res["task"] == "reach" and len(res["returns"]) == 2
    assert all(n <= 30 for n in res["lengths"]) and np.isfinite(res["return_mean"])
    assert cli.main(["eval", str(run), "--episodes", "1"]) == 0
    assert "reach PPO model.zip: 1 episodes" in capsys.readouterr().out


def test_the_observation_normalisers_floor_is_recorded_and_saved_with_the_model(tmp_path):
    from stable_baselines3 import PPO

    out = tmp_path / "floor"
    train("reach", "ppo", 64, 0, out, eval_every=64, eval_episodes=1, checkpoint_every=0,
          progress=False, normalize_obs=True, obs_min_std=0.02, n_envs=1,
          env_kwargs={"max_steps": 16}, algo_kwargs={"n_steps": 64, "batch_size": 32,
                                                     "n_epochs": 1})
    assert json.loads((out / "config.json").read_text())["obs_min_std"] == 0.02
    norm = PPO.load(str(out / "model.zip"), device="cpu").policy.features_extractor
    assert norm.min_std == 0.02 and float(norm.count) >= 64
    for bad, what in ((-0.1, "from 0"), (True, "from 0"), ("0.1", "from 0"),
                      (0.02, "needs normalize_obs")):
        with pytest.raises(TrainInputError, match=what):
            train("reach", "ppo", 64, 0, tmp_path / "never", progress=False,
                  normalize_obs=what == "from 0", obs_min_std=bad)
    assert not (tmp_path / "never").exists()
    # the command line's flag reaches train() (and its check)
    assert cli.main(["train", "--task", "reach", "--algo", "ppo", "--steps", "64", "--out",
                     str(tmp_path / "never"), "--no-progress", "--no-normalize-obs",
                     "--obs-min-std", "0.02"]) == 2
    assert not (tmp_path / "never").exists()


def test_a_bad_algo_kwarg_is_refused_before_anything_is_written(tmp_path):
    out = tmp_path / "never"
    with pytest.raises(TrainInputError, match=r"n_step.*did you mean.*n_steps"):
        train("reach", "ppo", 64, 0, out, algo_kwargs={"n_step": 64}, progress=False)
    with pytest.raises(TrainInputError, match=r"gamma"):
        train("reach", "ppo", 64, 0, out, algo_kwargs={"gamma": 2.0}, progress=False)
    assert not out.exists()


def test_frame_stacking_needs_the_image_observations(tmp_path):
    with pytest.raises(TrainInputError, match="frame_stack=2"):
        train("mirror", "ppo", 64, 0, tmp_path / "a", mode="scripted", flat_obs=True,
              frame_stack=2, progress=False)
    with pytest.raises(TrainInputError, match="frame_stack=2"):
        train("mirror", "ppo", 64, 0, tmp_path / "b", mode="shared", frame_stack=2,
              progress=False)
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()
