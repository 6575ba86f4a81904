"""``mimo-social eval RUN --ages ...``: a trained run's policy across infant ages (issue 32)."""

from __future__ import annotations

import csv
import json

import pytest

from mimo_social.train import TrainInputError, train
from mimo_social.train.cross_age import FIELDS, evaluate_ages

#: reach with short episodes; its ball placed at least 0.2 m from the shoulder, which a
#: 1-month-old's reach allows (the task's 0.25 m does not below 6 months)
ENV = {"max_steps": 15, "task_options": {"min_distance": 0.2}}


@pytest.fixture(scope="module")
def reach_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("cross_age") / "run"
    train("reach", "ppo", 128, 0, out, progress=False, n_envs=1, eval_episodes=1,
          algo_kwargs={"n_steps": 64, "n_epochs": 1, "batch_size": 64}, env_kwargs=ENV)
    return out


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_a_run_is_evaluated_at_each_age_into_a_table_and_a_figure(reach_run, tmp_path):
    res = evaluate_ages(reach_run, [1, 6, 12], episodes=2, seed=3, out=tmp_path / "grid")
    rows = _rows(tmp_path / "grid" / "cross_age.csv")
    assert [float(r["age_months"]) for r in rows] == [1, 6, 12]
    assert list(rows[0]) == list(FIELDS) and {r["episodes"] for r in rows} == {"2"}
    for r in res["rows"]:            # both policies, the task's success reported
        assert 0 <= r["success_rate"] <= 1 and 0 <= r["success_rate_stochastic"] <= 1
    md = (tmp_path / "grid" / "cross_age.md").read_text()
    assert md == res["markdown"] and md.count("\n| ") == 4   # the header and 3 rows
    assert "| 6 |" in md and "success, sampled" in md
    png = tmp_path / "grid" / "cross_age.png"
    assert png.stat().st_size > 10_000 and png.read_bytes()[:4] == b"\x89PNG"
    saved = json.loads((tmp_path / "grid" / "cross_age.json").read_text())
    assert [len(v["deterministic"]["returns"]) for v in saved["episodes_by_age"].values()] == \
        [2, 2, 2]
    assert saved["training_ages"] == {"age": None}
    # the same seeded episodes: the same numbers again
    again = evaluate_ages(reach_run, [6], episodes=2, seed=3, out=tmp_path / "again")
    assert again["rows"][0] == res["rows"][1]
    assert not (reach_run / "cross_age.csv").exists()      # --out was given


def test_the_command_line_prints_the_table_and_refuses_bad_ages(reach_run, capsys):
    from mimo_social.cli import main
    assert main(["eval", str(reach_run), "--ages", "6,12", "--episodes", "1",
                 "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "| age (months) |" in out and "| 12 |" in out and "cross_age.png" in out
    assert len(_rows(reach_run / "cross_age.csv")) == 2
    for bad, words in (("6,40", "--ages: '40' not allowed; allowed: ages in months from 0 to 33"),
                       ("6,six", "--ages: 'six' not allowed")):
        assert main(["eval", str(reach_run), "--ages", bad]) == 2
        err = capsys.readouterr().err
        assert words in err and err.count("\n") == 1          # one line
    assert main(["eval", str(reach_run), "--ages", "6", "--video", "v.mp4"]) == 2
    assert "--video with --ages" in capsys.readouterr().err
    assert main(["eval", str(reach_run), "--out", "x"]) == 2
    assert "give it with --ages" in capsys.readouterr().err


def test_an_age_the_env_cannot_reset_at_is_named(reach_run, tmp_path):
    with pytest.raises(TrainInputError, match=r"age 0 months: reach cannot reset at this age"):
        evaluate_ages(reach_run, [6, 0], episodes=1, out=tmp_path)
    assert not (tmp_path / "cross_age.csv").exists()


def test_a_touch_skin_that_differs_by_age_is_named_not_a_crash(tmp_path):
    """Self-body's skin has a few points more at 1 month than the published 18-month body the
    run was built with: refused naming the age and the observation key, before any episode."""
    from stable_baselines3 import PPO

    from mimo_social.train.envs import make_env
    run = tmp_path / "sb"
    run.mkdir()
    env = make_env("selfbody", flat=True)
    PPO("MlpPolicy", env, n_steps=64, device="cpu").save(run / "model.zip")
    env.close()
    (run / "config.json").write_text(json.dumps({"task": "selfbody", "algo": "ppo",
                                                 "observation": {"flat": True}}))
    with pytest.raises(TrainInputError) as e:
        evaluate_ages(run, [18, 1], episodes=1)
    msg = str(e.value)
    assert msg.startswith("age 1 months: the observation does not fit the model")
    assert "observation key 'touch'" in msg and "allowed:" in msg
    assert "proprioception" not in msg
    assert not (run / "cross_age.csv").exists()
