"""``compare --engine rllib``: seeds as Ray Tune trials, each writing an SB3-shaped run directory,
then the compare plot (skipped where ray's RLlib is not installed)."""

import csv
import json

import pytest

ray = pytest.importorskip("ray")
pytest.importorskip("ray.rllib")

TINY = {"train_batch_size_per_learner": 100, "minibatch_size": 50, "num_epochs": 1,
        "fcnet_hiddens": [16]}


def test_two_seeds_as_tune_trials_write_runs_and_the_compare_plot(tmp_path):
    from mimo_social.train.rllib.tune import compare_rllib

    out = tmp_path / "cmp"
    png = compare_rllib("high_five", ["ppo"], seeds=2, steps=200, out=out, num_cpus=2,
                        num_env_runners=0, eval_every=100, eval_episodes=1,
                        env_kwargs={"max_steps": 40}, algo_kwargs=TINY)
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
    assert png == out / "compare.png" and png.stat().st_size > 5000
    with open(out / "compare.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert {(r["algo"], r["seed"]) for r in rows} == {("ppo", "0"), ("ppo", "1")}
    # the trials ran at the same time (2 CPUs, one CPU a trial): their spans overlap
    results = [json.loads(p.read_text().splitlines()[-1])
               for p in (out / "_tune").rglob("result.json")]
    assert sorted(r["run"] for r in results) == [str(out / "ppo_seed0"), str(out / "ppo_seed1")]
    assert max(r["started"] for r in results) < min(r["ended"] for r in results)


def test_a_bad_algorithm_is_refused_before_ray_starts(tmp_path):
    from mimo_social.train import TrainInputError
    from mimo_social.train.rllib.tune import compare_rllib

    with pytest.raises(TrainInputError, match="td3"):
        compare_rllib("high_five", ["td3"], seeds=1, steps=10, out=tmp_path / "x")
    assert not ray.is_initialized()
