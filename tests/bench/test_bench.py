"""Smoke tests of the benchmark (`mimo-social bench sim`): structure, names, totals, components."""

import json

import numpy as np
import pytest

from mimo_social import bench
from mimo_social.cli import build_parser
from mimo_social.core import random_actions

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
    assert entry["per_agent_real_s_per_sim_s"] == pytest.approx(total / n_agents)
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
    md = bench.markdown_report(report, "mimo-social bench sim --sim-seconds 0.5", "docs/b.png")
    assert "| `agents_1` | 1 |" in md and "| `physics_only` | 1 |" in md
    assert report["machine"]["cpu"] in md and "![" in md
    checks = bench.target_checks(report)
    assert any("one infant" in c["target"] for c in checks)


def test_actions_are_smooth_seeded_and_bounded():
    a, ea = random_actions.smooth_random_actions(500, 44, 3)
    b, eb = random_actions.smooth_random_actions(500, 44, 3)
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
    parser = build_parser()
    out, md, png = tmp_path / "b.json", tmp_path / "B.md", tmp_path / "docs" / "b.png"
    args = parser.parse_args(["bench", "sim", "--json", str(out), "--sim-seconds", "0.3",
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
    args = parser.parse_args(["bench", "sim", "--from-json", str(out), "--markdown", str(md2)])
    assert args.func(args) == 0
    assert "mimo-social bench sim --json" in md2.read_text()
    assert "--only physics_only,reach" in md2.read_text()


# -- the paper's grid, scaling, recording, build times, skipped configurations ---------------
@pytest.fixture(scope="module")
def small():
    """Two small configurations of the default set: one-infant grid and two infants."""
    return bench.run_benchmarks(["v64", "agents_2"], sim_seconds=0.3, progress=False,
                                measure_cold_start=False)


def test_smoke_two_small_configurations(small):
    data = json.loads(json.dumps(small))
    assert TOP_KEYS | {"skipped"} <= set(data)
    assert data["skipped"] == []
    v64, agents_2 = data["results"]
    _check_entry(v64, "v64", 1)
    _check_entry(agents_2, "agents_2", 2)
    for entry in (v64, agents_2):
        assert entry["steps"] == 30
        comps = entry["components"]
        # every sense is on and the run is recorded: each has its share of the total
        for key in ("touch", "vision", "proprioception", "vestibular", "recording"):
            assert comps[key] > 0, key
        assert entry["recording"]["on"] and entry["recording"]["error"] is None
        assert entry["senses"]["vision"] == [64, 64] and entry["senses"]["touch"] == 1.0
        assert entry["touch_points"] > 0 and entry["skin_cache"]
        assert entry["mimo_reference"]["value"] == bench.MIMO_REFERENCE["default"]
    assert v64["group"] == "grid" and agents_2["group"] == "scaling"


def test_default_set_and_names():
    want = {"default", "v64", "v128", "v512", "t0.25", "t0.5", "t2", "physics_only",
            "five_fingers", "muscle", "agents_1", "agents_2", "agents_4", "agents_8",
            "free_play", "high_five", "reach"}
    assert want <= set(bench.DEFAULT_CONFIGS)
    assert not any(n.startswith("jacobian_") for n in bench.DEFAULT_CONFIGS)
    assert "jacobian_dense_4" in bench.CONFIGS
    assert bench.check_names(None) == bench.DEFAULT_CONFIGS
    assert bench.check_names("all") == list(bench.CONFIGS)
    # the grid: vision sizes at touch x1, touch densities at vision 256
    for name, size, density in (("v64", 64, 1.0), ("v128", 128, 1.0), ("default", 256, 1.0),
                                ("v512", 512, 1.0), ("t0.25", 256, 0.25), ("t0.5", 256, 0.5),
                                ("t2", 256, 2.0)):
        kw = bench.CONFIGS[name].kwargs
        assert kw["vision"] == {"width": size, "height": size}
        assert kw["touch"] == {"density": density}
        assert kw["task_options"] == {"props": True} and kw["n_agents"] == 1
    # agents_1 is v64 (the run's noise check)
    assert bench.CONFIGS["agents_1"].key() == bench.CONFIGS["v64"].key()


def test_every_catalogue_env_is_a_configuration():
    from mimo_social.envs.catalog import CATALOG

    for e in CATALOG:  # a new catalogue line is benchmarked with its defaults, recorded
        cfg = bench.CONFIGS[e.name]
        assert (cfg.task, dict(cfg.kwargs), cfg.record, cfg.group) == (e.name, {}, True, "tasks")
        assert e.summary in cfg.description and cfg.name in bench.DEFAULT_CONFIGS


def test_muscle_actions_fill_their_bounds():
    from mimo_social.envs import free_play_v0

    try:
        env = free_play_v0.parallel_env(n_agents=1, actuation="muscle")
    except ValueError as e:  # the muscle model not in yet
        pytest.skip(str(e))
    block = random_actions.random_action_block(env, 200, 0)
    motors = np.stack([a["infant_0"]["motors"] for a in block])
    box = env.action_space("infant_0")["motors"]
    assert (motors >= box.low).all() and (motors <= box.high).all()
    assert motors.min() < 0.2 and motors.max() > 0.8
    env.close()
    # spring-damper bounds [-1, 1] leave the actions unchanged
    x = np.linspace(-1, 1, 9, dtype=np.float32)[:, None]
    np.testing.assert_array_equal(random_actions.to_bounds(x, -np.ones(1), np.ones(1)), x)
    np.testing.assert_allclose(random_actions.to_bounds(x, np.zeros(1), np.ones(1)), (x + 1) / 2)


def test_configuration_that_cannot_be_built_is_skipped(monkeypatch):
    bad = bench.BenchConfig("claws", "free_play", {"n_agents": 1, "hands": "claws"})
    monkeypatch.setitem(bench.CONFIGS, "claws", bad)
    report = bench.run_benchmarks(["claws", "physics_only"], sim_seconds=0.1, progress=False,
                                  measure_cold_start=False)
    assert [r["name"] for r in report["results"]] == ["physics_only"]
    (skip,) = report["skipped"]
    assert skip["name"] == "claws" and "claws" in skip["reason"] and "allowed" in skip["reason"]
    assert "`claws`" in bench.markdown_report(report)


def test_skin_cache_cold_then_warm():
    out = bench.skin_cache_builds(["physics_only", "no_vision"])
    assert list(out) == ["no_vision"]  # only configurations with touch
    cold, warm = out["no_vision"]["cold"], out["no_vision"]["warm"]
    assert "error" not in cold and "error" not in warm, out
    assert cold["skin"] == ["built"] and warm["skin"] == ["disk"]
    assert cold["build_s"] > 0 and warm["build_s"] > 0


def test_report_tables_plots_and_noise_check(small, tmp_path):
    report = json.loads(json.dumps(small))
    # a copy of v64 named agents_1 stands in for the real one (the same configuration)
    one = dict(report["results"][0], name="agents_1", group="scaling")
    report["results"].insert(1, one)
    md = bench.markdown_report(report, "mimo-social bench sim", ["docs/a.png", "docs/b.png"])
    assert "## Infants in one world" in md and "| 2 |" in md
    assert "`agents_1` and `v64`" in md or "`v64` and `agents_1`" in md
    assert "](docs/a.png)" in md and "](docs/b.png)" in md
    assert "original MIMo" in md and "ahead" in md
    checks = bench.target_checks(report)
    assert any("ahead of the original MIMo" in c["target"] for c in checks)
    assert any("linear" in c["target"] for c in checks)
    paths = bench.plot_report(report, tmp_path / "p.png")
    assert [p.name for p in paths] == ["p.png", "p_tasks_scaling.png"]
    for p in paths:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
