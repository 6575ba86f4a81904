"""``mimo-social bench development`` with tiny numbers: every body builds and is timed, every
compared env steps, and the table names each figure against its base."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mimo_social import cli
from mimo_social.bench import development


def test_bench_development_times_every_body_and_variant(tmp_path, capsys):
    out = tmp_path / "dev.json"
    code = cli.main(["bench", "development", "--sim-seconds", "0.06", "--repeats", "1",
                     "--json", str(out)])
    assert code == 0
    results = json.loads(out.read_text())
    bodies = {(r["hands"], r["body"]) for r in results["build"]}
    assert bodies == {(h, label) for h in ("mitten", "five_fingers")
                      for label, _ in development.BUILD_BODIES}
    assert all(r["tables_ms"] > 0 and r["env_ms"] > 0 for r in results["build"])
    assert set(results["delays"]) == {"touch", "touch + delays", "touch + vision",
                                      "touch + vision + delays"}
    assert len(results["acuity"]) == 4 and all(v > 0 for v in results["acuity"].values())
    printed, err = capsys.readouterr()
    assert "| five_fingers | adult |" in printed
    # 6 steps a configuration: one turn, no comparison (and a warning before the run)
    assert err == ("mimo-social bench development: warning: --sim-seconds 0.06: too short to "
                   "compare timings (1 turn(s) of 100 steps for the acuity ones; a comparison "
                   "needs 10, the noise of one turn being tens of percent); the comparisons are "
                   "left out; give --sim-seconds >= 15\n")
    assert "% vs" not in printed
    assert ("| touch + delays | " in printed and "(no comparison with touch: 1 turn(s) of up to "
            "100 steps, fewer than 10; give --sim-seconds >= 15) |" in printed)
    assert results["comparisons"]["touch + delays"]["turns"] == 1
    assert results["min_turns"] == 10


def test_a_comparison_has_its_turns_and_their_noise(monkeypatch):
    """Turn by turn ratios: their mean's two standard errors; enough turns give the figure."""
    c = development.compare_turns([1.1, 0.9, 1.0, 1.0], [1.0, 1.0, 1.0, 1.0])
    assert c["turns"] == 4 and c["noise_pct"] == pytest.approx(200 * np.std(
        [1.1, 0.9, 1.0, 1.0], ddof=1) / 2)
    assert development.min_sim_seconds() == 15.0
    assert development.turns_of(15) == 15 and development.turns_of(10) == 10
    results = {"build": [], "delays": {"touch": 1.0, "touch + delays": 1.1}, "acuity": {},
               "comparisons": {"touch + delays": {"base": "touch", "turns": 10,
                                                  "noise_pct": 2.345}}}
    assert "| touch + delays | 1.10 (+10.0 % +- 2.3 % vs touch) |" in (
        development.format_results(results))


def test_every_configuration_warms_up_before_it_is_timed(monkeypatch):
    """The first steps (first render, caches) are not timed: a configuration that has them in
    its one turn read as slower than the same configuration after them."""
    from mimo_social.bench import vision_cost
    made = []
    real = vision_cost.free_play_v0.parallel_env

    def counting(**kw):
        env = real(**kw)
        step = env.step
        env.step = lambda actions: (made.append(1), step(actions))[1]
        return env
    monkeypatch.setattr(vision_cost.free_play_v0, "parallel_env", counting)
    (row,) = vision_cost.bench_env({"touch": dict(n_agents=1, touch=True)}, sim_seconds=0.15)
    assert len(made) == vision_cost.WARMUP_STEPS + 15
    assert len(row["turn_s"]) == 1 and row["sim_s"] == pytest.approx(0.15)


def test_hearing_paths_time_both_ways_and_name_the_one_taken():
    """The audition update's two ways are both timed inside the step, at each agent count."""
    rows = development.hearing_paths(agents=(2, 8), steps=100)
    assert [r["pairs"] for r in rows] == [4, 64]
    assert [r["default"] for r in rows] == ["floats", "arrays"]
    assert all(r["floats_us"] > 0 and r["arrays_us"] > 0 for r in rows)
    table = development.format_hearing_paths(rows)
    assert "| 8 | 64 |" in table and table.count("\n") == 5
