"""``mimo-social fig8``: the paper's Fig. 8 in one command (issue 30): every run trained into
``OUT/<task>/<algo>_seed<k>`` (a recipe's: ``recipe_seed<k>``), finished runs reused, one
figure over the tasks, a compare plot and a baselines table per task."""

import json
import os
from pathlib import Path

import pytest

from mimo_social.cli import main
from mimo_social.train.fig8 import fig8
from mimo_social.train.plots import runs_by_group
from mimo_social.train.tasks import TrainInputError


def test_fig8_trains_plots_tabulates_and_reuses_finished_runs(tmp_path):
    out = tmp_path / "f8"
    # PPO's smallest rollout is 2048 steps; SAC before learning_starts makes no gradient step
    png = fig8(out, 1, ["reach"], steps={"reach": {"ppo": 2048, "sac": 64}}, episodes=1,
               eval_episodes=1, recipes=True, recipe_steps=2048, progress=False)
    assert png == out / "fig8.png" and png.stat().st_size > 10_000
    task = out / "reach"
    for run, algo in (("ppo_seed0", "ppo"), ("sac_seed0", "sac"), ("recipe_seed0", "ppo")):
        config = json.loads((task / run / "config.json").read_text())
        assert config["algo"] == algo and config["seed"] == 0
        assert config.get("recipe") == ("reach" if run.startswith("recipe") else None)
    assert json.loads((task / "ppo_seed0" / "config.json").read_text())["n_envs"] == 1
    assert set(runs_by_group(task)) == {"ppo", "sac", "ppo recipe"}
    assert (task / "compare.png").exists() and (task / "compare.csv").exists()
    table = (task / "baselines.md").read_text()
    for row in ("random", "zero", "scripted", "ppo_seed0", "sac_seed0", "recipe_seed0"):
        assert row in table
    text = (out / "fig8.md").read_text()
    assert "## reach" in text and "PPO 2,048, SAC 64" in text and "cores" in text
    stamp = os.stat(task / "sac_seed0" / "model.zip").st_mtime_ns
    fig8(out, 1, ["reach"], steps={"reach": {"ppo": 2048, "sac": 64}}, episodes=1,
         eval_episodes=1, recipes=True, recipe_steps=2048, progress=False)
    assert os.stat(task / "sac_seed0" / "model.zip").st_mtime_ns == stamp
    # --episodes 0: no evaluation run, each run's last evaluation during training tabulated
    (task / "baselines.md").unlink()
    fig8(out, 1, ["reach"], steps={"reach": {"ppo": 2048, "sac": 64}}, episodes=0,
         eval_episodes=1, recipes=True, recipe_steps=2048, plot_only=True, progress=False)
    assert not (task / "baselines.md").exists()
    text = (out / "fig8.md").read_text()
    for row in ("| ppo_seed0 | 2,048 |", "| sac_seed0 | 64 |", "| recipe_seed0 | 2,048 |"):
        assert row in text
    # an interrupted run is left out of the table and named as not finished
    cfg = task / "sac_seed0" / "config.json"
    cfg.write_text(json.dumps({**json.loads(cfg.read_text()), "interrupted": True}))
    fig8(out, 1, ["reach"], steps={"reach": {"ppo": 2048, "sac": 64}}, episodes=0,
         eval_episodes=1, recipes=True, recipe_steps=2048, plot_only=True, progress=False)
    text = (out / "fig8.md").read_text()
    assert "| sac_seed0 |" not in text and "| ppo_seed0 | 2,048 |" in text
    assert ("Not in the table (not trained yet, interrupted or another budget): sac_seed0."
            in text)


def test_fig8_refuses_other_tasks_and_bad_counts(tmp_path, capsys):
    with pytest.raises(TrainInputError, match="mirror"):
        fig8(tmp_path, 1, ["mirror"])
    with pytest.raises(TrainInputError, match="seeds=0"):
        fig8(tmp_path, 0, ["reach"])
    with pytest.raises(SystemExit) as e:
        main(["fig8", "--out", str(tmp_path), "--tasks", "reach,juggle"])
    assert e.value.code == 2 and "unknown task 'juggle'" in capsys.readouterr().err


def _capture_plot(monkeypatch):
    """Replace the figure with a record of the runs it was given (groups, seeds, last steps)."""
    import mimo_social.train.plots as plots
    seen = {}

    def record(out, tasks, png=None, log_steps=False):
        for t in tasks:
            seen[t] = {g: sorted((c["seed"], int(p["timesteps"][-1])) for c, p in rs)
                       for g, rs in runs_by_group(Path(out) / t).items()}
        seen["log"] = log_steps
        return png
    monkeypatch.setattr(plots, "plot_fig8", record)
    return seen


def test_fig8_redraw_from_compare_csv_and_recipe_runs(tmp_path, monkeypatch, capsys):
    from mimo_social.train.fig8 import redraw
    fields = "algo,seed,timesteps,wall_time_s,eval_return_mean,eval_return_mean_stochastic"
    rows = ["ppo,0,2048,1.0,-5,-4", "ppo,0,4096,2.0,-3,-2", "ppo,1,2048,1.1,-6,-5",
            "sac,0,64,3.0,-9,-9", "ppo recipe,0,5000,4.0,1,1"]
    (tmp_path / "fig" / "catch").mkdir(parents=True)
    (tmp_path / "fig" / "catch" / "compare.csv").write_text("\n".join([fields, *rows]) + "\n")
    seen = _capture_plot(monkeypatch)
    redraw(tmp_path / "fig")
    assert seen["catch"] == {"ppo": [(0, 4096), (1, 2048)], "sac": [(0, 64)],
                             "ppo recipe": [(0, 5000)]}
    assert seen["log"] is False
    # recipe runs replace the recipe rows; a budget over 5x the learners' draws steps on a log axis
    run = tmp_path / "recipes" / "catch" / "seed1"
    run.mkdir(parents=True)
    (run / "config.json").write_text(json.dumps({"algo": "ppo", "seed": 1, "steps": 2_000_000,
                                                 "recipe": "catch"}))
    (run / "progress.csv").write_text(fields.split(",", 2)[2] + "\n2000000,60,880,881\n")
    redraw(tmp_path / "fig", tmp_path / "recipes")
    assert seen["catch"]["ppo recipe"] == [(1, 2_000_000)] and seen["log"] is True
    with pytest.raises(TrainInputError, match="compare.csv"):
        redraw(tmp_path / "recipes")
    assert main(["fig8", "--seeds", "2"]) == 2
    assert "--out is needed" in capsys.readouterr().err
