"""The engines benchmark's harness (mimo_social.bench.engines) with stand-in measurements, and
one real SB3 measurement through the command (RLlib's side: tests/train/test_rllib_tune.py)."""

import json

import pytest

from mimo_social.bench import engines


def _fake(rates):
    def measure(task, workers, seconds):
        sps = rates[(task, workers)]
        return {"env_steps": int(sps * seconds), "seconds": seconds, "steps_per_s": sps,
                "iterations": 2, "warmup_s": 0.5, "sample_s": 0.2, "learn_s": 0.1}
    return measure


def test_efficiency_table_and_figure(tmp_path):
    measure = {"sb3": _fake({("high_five", 1): 100.0, ("high_five", 2): 150.0}),
               "rllib": _fake({("high_five", 1): 80.0, ("high_five", 2): 160.0})}
    res = engines.run(measure, ["high_five"], (1, 2), 3.0, log=None)
    eff = {e["engine"]: e for e in res["efficiency"]}
    assert eff["sb3"]["efficiency"] == pytest.approx(0.75)
    assert eff["sb3"]["speedup"] == pytest.approx(1.5)
    assert eff["rllib"]["efficiency"] == pytest.approx(1.0)
    assert [(r["engine"], r["workers"]) for r in res["rows"]] == [
        ("sb3", 1), ("sb3", 2), ("rllib", 1), ("rllib", 2)]
    json.dumps(res)                                    # plain JSON
    table = engines.markdown(res)
    assert "| `high_five` | sb3 | **100** | **150** | 75% (1.50x) |" in table
    assert "| `high_five` | rllib | **80** | **160** | 100% (2.00x) |" in table
    png = engines.plot(res, tmp_path / "e.png")
    assert png.stat().st_size > 5000


def test_command_measures_sb3(tmp_path):
    from mimo_social.cli import main
    out = tmp_path / "bench"
    code = main(["bench", "engines", "--engines", "sb3", "--tasks", "high_five", "--workers",
                 "1", "--seconds", "0.5", "--rollout", "64", "--minibatch", "64", "--epochs",
                 "1", "--out", str(out)])
    assert code == 0
    res = json.loads((out / "engines.json").read_text())
    (row,) = res["rows"]
    assert row["engine"] == "sb3" and row["workers"] == 1 and row["env_steps"] >= 64
    assert row["steps_per_s"] > 0
    assert (out / "engines.png").exists() and "bench engines" in (out / "engines.md").read_text()
