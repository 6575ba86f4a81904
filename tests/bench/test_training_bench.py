"""The training-throughput benchmark (issue 29): PPO's env steps/s against the env alone."""

from __future__ import annotations

import json
import re

import pytest

from mimo_social import cli
from mimo_social.bench import training as bench
from mimo_social.cli import bench_training

#: tiny PPO rollouts, so that a run of a few hundred steps has updates to time
TINY = {"n_steps": 64, "batch_size": 64, "n_epochs": 1}


def test_measure_gives_positive_rates_for_each_configuration(tmp_path):
    res = bench_training.measure(("reach",), (1, 2), 640, root=tmp_path, algo_kwargs=TINY,
                                 envs_per_worker=(1, 2))
    assert [(r["task"], r["workers"], r["envs_per_worker"]) for r in res["rows"]] == [
        ("reach", 1, 1), ("reach", 1, 2), ("reach", 2, 1), ("reach", 2, 2)]
    assert [r["order"] for r in res["rows"]] == [["env", "ppo"], ["ppo", "env"]] * 2
    for r in res["rows"]:
        assert r["env"]["steps_per_s"] > 0 and r["ppo"]["steps_per_s"] > 0 and r["ratio"] > 0
        assert r["env"]["env_steps"] == 640
        ppo = r["ppo"]
        n_envs = r["workers"] * r["envs_per_worker"]
        # the timed phase: from the checkpoint one vector step after the first update to the end
        assert ppo["rollout"] == 64 * n_envs
        assert ppo["first_mark"] == ppo["rollout"] + n_envs
        config = json.loads((tmp_path / f"reach_{r['workers']}x{r['envs_per_worker']}"
                             / "config.json").read_text())
        assert (config["n_envs"], config["n_cpus"]) == (n_envs, r["workers"])
        assert ppo["env_steps"] == ppo["timesteps_done"] - ppo["first_mark"] > 0
        assert ppo["eval_steps"] > 0 and ppo["startup_s"] > 0 and ppo["final_s"] > 0
    json.dumps(res)                                     # plain JSON
    text = bench.markdown(res)
    assert "| `reach` | 1 x 1 |" in text and "| `reach` | 2 x 2 |" in text
    assert "PPO / env" in text
    assert re.search(r"`reach`, 2 workers x 1 env: target >= 60% of the env alone; \d+%: "
                     r"(met|NOT met)", text)
    assert "torch" in text and "MuJoCo" in text


def test_the_env_alone_of_a_learner_with_eyes_steps_its_image_observations():
    config = bench.TrainingConfig("mirror", "scripted", 1)
    r = bench_training.env_rate(config, 20)
    assert r["env_steps"] == 20 and r["steps_per_s"] > 0


def _fake(kind):
    def rate(config, steps, seed):
        return {"steps_per_s": (1000.0 if kind == "env" else 500.0) * config.workers,
                "steps": steps}
    return rate


def test_the_table_the_order_and_the_targets():
    configs = bench.configs(bench.DEFAULT_TASKS, bench.DEFAULT_WORKERS, bench_training.MODES,
                            (bench.TARGET_ENVS_PER_WORKER,))
    assert [c.name for c in configs] == [
        "reach, 1 worker x 1 env", "reach, 2 workers x 1 env",
        "high_five --mode scripted, 1 worker x 1 env",
        "high_five --mode scripted, 2 workers x 1 env",
        "mirror --mode scripted, 1 worker x 1 env", "mirror --mode scripted, 2 workers x 1 env"]
    res = bench.measure(configs, {"reach": 10, "high_five": 20, "mirror": 30},
                        env_rate=_fake("env"), ppo_rate=_fake("ppo"))
    assert [r["order"][0] for r in res["rows"]] == ["env", "ppo"] * 3
    assert [r["env"]["steps"] for r in res["rows"]] == [10, 10, 20, 20, 30, 30]
    table = bench.format_table(res)
    assert table.count("\n") == 7
    assert "| `mirror` (scripted) | 2 x 1 | 2000 | 1000 | **50%** |" in table
    met = {t["task"]: t["met"] for t in bench.targets(res)}
    assert met == {"reach": False, "high_five": False, "mirror": True}
    assert ("`mirror`, 2 workers x 1 env: target >= 40% of the env alone; 50%: met"
            in bench.markdown(res))


@pytest.mark.parametrize("tasks, workers, match", [
    (["fly"], [1], "unknown task 'fly'; allowed: reach"),
    (["reach"], [0], "workers=0; allowed: integers >= 1"),
    (["reach"], [-2], "workers=-2"),
    ([], [1], "no task given"),
    (["reach"], [], "no worker count given"),
    (["reach", "reach"], [1], "repeated"),
])
def test_bad_arguments_are_clear_errors(tasks, workers, match):
    with pytest.raises(ValueError, match=match):
        bench.configs(tasks, workers, bench_training.MODES)


def test_too_few_steps_to_time_the_learning_is_a_clear_error(tmp_path):
    with pytest.raises(ValueError, match="more than one PPO rollout"):
        bench_training.ppo_rate(bench.TrainingConfig("reach", None, 1), 64, root=tmp_path,
                                algo_kwargs=TINY)
    with pytest.raises(ValueError, match="steps=0"):
        bench.measure([bench.TrainingConfig("reach", None, 1)], 0, env_rate=_fake("env"),
                      ppo_rate=_fake("ppo"))


@pytest.mark.parametrize("bad, option", [(["--tasks", "fly"], "--tasks"),
                                         (["--workers", "0"], "--workers"),
                                         (["--steps", "0"], "--steps")])
def test_bad_command_line_arguments_are_usage_errors(bad, option, capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["bench", "training", *bad])
    assert e.value.code == 2
    assert option in capsys.readouterr().err.strip().splitlines()[-1]


def test_the_default_steps_are_fewer_for_a_learner_with_eyes():
    assert bench_training.default_steps(["reach", "mirror"]) == {
        "reach": bench_training.DEFAULT_STEPS, "mirror": bench_training.DEFAULT_STEPS_EYES}
