"""``compare --engine rllib``: seeds as Ray Tune trials, each writing an SB3-shaped run directory,
then the compare plot (skipped where ray's RLlib is not installed)."""

import csv
import json

import pytest

ray = pytest.importorskip("ray")
pytest.importorskip("ray.rllib")

TINY = {"train_batch_size_per_learner": 100, "minibatch_size": 50, "num_epochs": 1,
        "fcnet_hiddens": [16]}


def test_two_seeds_as_tune_trials_write_runs_and_the_compare_plot(tmp_path, capsys):
    from mimo_social.cli import main

    out = tmp_path / "cmp"
    code = main(["compare", "--engine", "rllib", "--task", "high_five", "--algos", "ppo",
                 "--seeds", "2", "--steps", "200", "--eval-every", "100", "--eval-episodes", "1",
                 "--env-kwargs", json.dumps({"max_steps": 40}), "--algo-kwargs", json.dumps(TINY),
                 "--num-env-runners", "0", "--num-cpus", "2", "--out", str(out)])
    assert code == 0
    png = out / "compare.png"
    assert f"wrote {png}" in capsys.readouterr().out
    assert not ray.is_initialized()          # the local Ray it started is shut down
    assert sorted(p.name for p in out.glob("ppo_seed*")) == ["ppo_seed0", "ppo_seed1"]
    for seed in (0, 1):
        run = out / f"ppo_seed{seed}"
        config = json.loads((run / "config.json").read_text())
        assert (config["engine"], config["algo"], config["seed"]) == ("rllib", "ppo", seed)
        with open(run / "progress.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        assert len(rows) >= 2 and all(float(r["timesteps"]) >= 100 for r in rows)
        assert "eval_return_mean_infant_0" in rows[0]
        assert (run / "learning_curve.png").exists()
    assert png.stat().st_size > 5000
    with open(out / "compare.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert {(r["algo"], r["seed"]) for r in rows} == {("ppo", "0"), ("ppo", "1")}
    # the trials ran at the same time (2 CPUs, one CPU a trial): their spans overlap
    results = [json.loads(p.read_text().splitlines()[-1])
               for p in (out / "_tune").rglob("result.json")]
    assert sorted(r["run"] for r in results) == [str(out / "ppo_seed0"), str(out / "ppo_seed1")]
    assert max(r["started"] for r in results) < min(r["ended"] for r in results)


def test_sb3_options_and_bad_algorithms_are_refused_before_ray_starts(tmp_path, capsys):
    from mimo_social.cli import main

    assert main(["compare", "--engine", "rllib", "--task", "high_five", "--steps", "10",
                 "--jobs", "2", "--out", str(tmp_path / "y")]) == 2
    assert "--jobs is for --engine sb3" in capsys.readouterr().err
    from mimo_social.train import TrainInputError
    from mimo_social.train.rllib.tune import compare_rllib

    with pytest.raises(TrainInputError, match="td3"):
        compare_rllib("high_five", ["td3"], seeds=1, steps=10, out=tmp_path / "x")
    assert not ray.is_initialized()
