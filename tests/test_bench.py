"""Smoke tests of the benchmark (`mimo-social bench`): structure, names, totals, components."""

import argparse
import json

import numpy as np
import pytest

from mimo_social import bench

TOP_KEYS = {"machine", "settings", "cold_start", "results"}
ENTRY_KEYS = {"name", "n_agents", "real_s_per_sim_s", "build_s", "components"}


def _check_entry(entry, name, n_agents):
    assert ENTRY_KEYS <= set(entry)
    assert entry["name"] == name
    assert entry["n_agents"] == n_agents
    total = entry["real_s_per_sim_s"]
    assert np.isfinite(total) and total > 0
    assert entry["build_s"] > 0
    comps = entry["components"]
    assert set(comps) == set(bench.COMPONENTS)
    assert all(v >= 0 for v in comps.values())
    assert sum(comps.values()) == pytest.approx(total, rel=0.10)
    assert comps["physics"] > 0
    assert entry["unstable_episodes"] == 0


@pytest.fixture(scope="module")
def report():
    return bench.run_benchmarks(["agents_1", "physics_only"], sim_seconds=0.5, progress=False,
                                measure_cold_start=False)


def test_run_benchmarks_structure(report):
    assert TOP_KEYS <= set(report)
    machine = report["machine"]
    for key in ("cpu", "cores", "mujoco", "python", "platform", "mujoco_gl"):
        assert machine[key]
    json.loads(json.dumps(report))  # plain JSON all the way down
    names = [r["name"] for r in report["results"]]
    assert names == ["agents_1", "physics_only"]
    agents_1, physics_only = report["results"]
    _check_entry(agents_1, "agents_1", 1)
    _check_entry(physics_only, "physics_only", 1)
    assert agents_1["steps"] == 50 and agents_1["sim_seconds"] == pytest.approx(0.5)
    # the env does more than the bare physics loop (senses, actuation, overhead)
    for key in ("actuation", "proprioception", "vestibular", "other"):
        assert agents_1["components"][key] > 0
    assert physics_only["components"]["proprioception"] == 0


def test_markdown_and_targets(report):
    md = bench.markdown_report(report, "mimo-social bench --sim-seconds 0.5", "docs/b.png")
    assert "| `agents_1` | 1 |" in md and "| `physics_only` | 1 |" in md
    assert report["machine"]["cpu"] in md and "![" in md
    checks = bench.target_checks(report)
    assert any("one infant" in c["target"] for c in checks)


def test_actions_are_smooth_seeded_and_bounded():
    a, ea = bench.smooth_random_actions(500, 44, 3)
    b, eb = bench.smooth_random_actions(500, 44, 3)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(ea, eb)
    assert a.dtype == np.float32 and a.shape == (500, 44)
    assert a.min() >= -1 and a.max() <= 1 and a.std() > 0.3
    # low-pass: consecutive steps change much less than independent draws would
    assert np.abs(np.diff(a, axis=0)).mean() < 0.25 * np.abs(a).mean()
    assert ((0 <= ea) & (ea < 7)).all()


def test_unknown_name_is_rejected():
    with pytest.raises(ValueError, match="allowed: agents_1"):
        bench.run_benchmarks(["agents_3"], sim_seconds=0.1, progress=False)


def test_cli_writes_json_markdown_and_plot(tmp_path, capsys):
    parser = argparse.ArgumentParser(prog="mimo-social")
    bench.add_parser(parser.add_subparsers(dest="command", required=True))
    out, md, png = tmp_path / "b.json", tmp_path / "B.md", tmp_path / "docs" / "b.png"
    args = parser.parse_args(["bench", "--json", str(out), "--sim-seconds", "0.3",
                              "--only", "physics_only,reach", "--markdown", str(md),
                              "--plot", str(png), "--no-progress", "--no-cold-start"])
    assert args.func(args) == 0
    data = json.loads(out.read_text())
    assert [r["name"] for r in data["results"]] == ["physics_only", "reach"]
    _check_entry(data["results"][1], "reach", 1)
    assert "](docs/b.png)" in md.read_text()
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "physics_only" in capsys.readouterr().out
    # re-rendering from the JSON measures nothing and keeps the recorded command
    md2 = tmp_path / "again.md"
    args = parser.parse_args(["bench", "--from-json", str(out), "--markdown", str(md2)])
    assert args.func(args) == 0
    assert "--only physics_only,reach" in md2.read_text()
