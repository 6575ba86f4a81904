"""The floor benchmark: the env step against a bare mj_step loop on the same model and trajectory."""

from __future__ import annotations

import json

import pytest

from mimo_social import cli
from mimo_social.bench import floor


@pytest.mark.parametrize("config", [floor.FloorConfig(1, False), floor.FloorConfig(2, True)],
                         ids=lambda c: c.name)
def test_the_floor_replays_the_envs_own_trajectory(config):
    r = floor.measure_one(config, chunks=2, chunk=15)
    assert r["same_trajectory"], "the bare mj_step replay left the env's trajectory"
    assert r["steps"] == 30 and r["env_ms"] > 0 and r["floor_ms"] > 0 and r["ratio"] > 0
    assert r["touch"] == config.touch and r["n_agents"] == config.n_agents
    assert abs(sum(r["split_pct"].values()) - 100) < 1e-6


def test_the_configurations_are_one_two_and_eight_infants_without_and_with_touch():
    assert [(c.n_agents, c.touch) for c in floor.FLOOR_CONFIGS] == [
        (1, False), (1, True), (2, False), (2, True), (8, False), (8, True)]
    text = floor.format_results([floor.measure_one(floor.FloorConfig(1, True), 1, 5)])
    assert "| 1 infant, touch |" in text and "| yes |" in text


def test_bench_floor_command(tmp_path, capsys):
    out = tmp_path / "floor.json"
    assert cli.main(["bench", "floor", "--agents", "1", "--chunks", "1", "--chunk", "5",
                     "--json", str(out)]) == 0
    results = json.loads(out.read_text())
    assert [r["config"] for r in results] == ["1 infant", "1 infant, touch"]
    assert all(r["same_trajectory"] for r in results)
    assert "env / floor" in capsys.readouterr().out
    assert cli.main(["bench", "floor", "--agents", "1", "--jacobian", "dense,sparse", "--chunks",
                     "1", "--chunk", "5", "--json", str(out)]) == 0
    assert [r["config"] for r in json.loads(out.read_text())] == [
        "1 infant, dense Jacobian", "1 infant, sparse Jacobian", "1 infant, touch, dense Jacobian",
        "1 infant, touch, sparse Jacobian"]
    for bad in (["--chunks", "0"], ["--agents", "3"], ["--jacobian", "fast"]):
        with pytest.raises(SystemExit) as e:
            cli.main(["bench", "floor", *bad])
        assert e.value.code == 2
