"""`mimo-social replay FILE.rrd`: the summary (read with Rerun's own reader, no viewer) and
opening the viewer only when one can be shown."""

import subprocess
import sys
import warnings

import numpy as np
import pytest
from rerun.chunk import RrdReader

from mimo_social import cli
from mimo_social.cli import replay as replay_cli
from mimo_social.envs import free_play_v0, high_five_v0
from mimo_social.recording import Recorder, summarize

N_STEPS = 90


def own_counts(path):
    """Rows with skin points per agent and contact event texts, read here independently."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chunks = RrdReader(path).stream().to_chunks()
    skin, events = {}, []
    for c in chunks:
        if c.entity_path.endswith("/skin") and not c.is_static:
            agent = c.entity_path.split("/")[2]
            lists = c.to_record_batch().column("Points3D:positions").to_pylist()
            skin[agent] = skin.get(agent, 0) + sum(1 for x in lists if x)
        if c.entity_path == "/events/contacts":
            events += [t for texts in c.to_record_batch().column("TextLog:text").to_pylist()
                       for t in texts]
    return skin, events


@pytest.fixture(scope="module")
def high_five_file(tmp_path_factory):
    """High five with touch on, right hands swung together (they meet after ~70 steps)."""
    env = high_five_v0.parallel_env(task_options={"end_on_touch": False, "distance": 0.3},
                                    touch=True)
    path = tmp_path_factory.mktemp("cli") / "high five.rrd"
    u = np.zeros(8, np.float32)
    u[:2] = -1.0
    obs, _ = env.reset(seed=0)
    with Recorder(env, path) as rec:
        rec.log_reset(obs)
        for _ in range(N_STEPS):
            actions = {a: {"motors": u, "expression": 3} for a in env.agents}
            obs, rewards, *_ = env.step(actions)
            rec.log_step(actions, rewards, obs)
    env.close()
    return {"path": path, "rec": rec}


def test_summary_says_what_the_file_holds(high_five_file, capsys):
    path, rec = high_five_file["path"], high_five_file["rec"]
    assert cli.main(["replay", str(path), "--summary"]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert lines[0].startswith(str(path))
    assert "complete: no" not in out
    assert "agents: 2 (infant_0, infant_1)" in lines
    assert f"simulated duration: {N_STEPS * 0.01:.3f} s (sim_time 0.000 .. 0.900 s)" in lines
    assert f"steps: {N_STEPS + 1} (step 0 .. {N_STEPS})" in lines
    assert f"pose rows: {N_STEPS + 1} (every body; {len(rec.body_paths)} bodies)" in lines
    assert "eye images: none" in lines
    skin, events = own_counts(path)
    assert all(n > 0 for n in skin.values()) and len(skin) == 2
    skin_line = next(x for x in lines if x.startswith("skin points: "))
    for agent, n in skin.items():
        assert f"{agent} {n} rows" in skin_line
    assert rec.contact_events == len(events) >= 1
    assert f"contact events between agents: {len(events)}" in lines
    listed = [x.split(": ", 1)[1] for x in lines if x.startswith("  step ")]
    assert listed == events
    assert any(t.startswith("infant_0 right_") and "touches infant_1 right_" in t for t in events)
    assert "expression log rows: infant_0 2, infant_1 2" in lines    # neutral at reset, then sad
    for group in ("/world/infant_0/", "/world/infant_1/", "/agents/infant_0/",
                  "/agents/infant_1/", "/world/scene/"):
        assert any(x.startswith(f"  {group} (") for x in lines), group
    assert "  /events/contacts" in lines
    agents_line = next(x for x in lines if x.startswith("  /agents/infant_0/ ("))
    for what in ("action_norm", "expression", "face", "reward", "touch_total"):
        assert what in agents_line
    assert "skin" in next(x for x in lines if x.startswith("  /world/infant_0/ ("))


def test_summary_dict(high_five_file):
    s = summarize(high_five_file["path"])
    assert s["agents"] == ["infant_0", "infant_1"] and s["complete"]
    assert (s["steps"], s["pose_rows"], s["pose_rows_per_body"]) == (
        N_STEPS + 1, N_STEPS + 1, [N_STEPS + 1])
    assert s["duration_s"] == pytest.approx(0.9, abs=1e-6)
    assert s["eye_images"] == {}
    assert "/world/infant_1/skin" in s["entities"]
    assert s["recordings"][0]["application_id"] == "mimo_social"


def test_summary_counts_eye_images_when_vision_is_on(tmp_path, capsys):
    try:
        import mimo_social.senses.vision  # noqa: F401
        env = free_play_v0.parallel_env(n_agents=2, vision={"width": 64, "height": 64})
        obs, _ = env.reset(seed=0)
    except Exception as exc:
        pytest.skip(f"vision does not build here: {type(exc).__name__}: {exc}")
    path = tmp_path / "eyes.rrd"
    zero = {a: {"motors": np.zeros(44, np.float32), "expression": 0} for a in env.agents}
    with Recorder(env, path, eye_every_k_steps=2) as rec:
        rec.log_reset(obs)
        for _ in range(6):
            obs, *_ = env.step(zero)
            rec.log_step(zero, None, obs)
    env.close()
    assert cli.main(["replay", str(path), "--summary"]) == 0
    out = capsys.readouterr().out
    assert "eye images: infant_0 4 left + 4 right, infant_1 4 left + 4 right" in out
    assert "skin points: none" in out and "contact events between agents: 0" in out


def test_summary_of_a_recording_that_was_not_closed(tmp_path, capsys):
    env = free_play_v0.parallel_env(n_agents=2)
    obs, _ = env.reset(seed=0)
    zero = {a: {"motors": np.zeros(44, np.float32), "expression": 0} for a in env.agents}
    rec = Recorder(env, tmp_path / "open.rrd", flush_every_s=0.1)
    rec.log_reset(obs)
    for _ in range(25):
        env.step(zero)
        rec.log_step(zero)
    rec.flush()                                   # 26 rows written, the file still open
    try:
        assert cli.main(["replay", str(rec.path), "--summary"]) == 0
        out = capsys.readouterr().out
    finally:
        rec.close()
    assert "complete: no" in out
    assert "steps: 26 (step 0 .. 25)" in out and "pose rows: 26" in out


def test_without_a_display_it_says_how_to_open_the_file(high_five_file, monkeypatch, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)

    def no_popen(*args, **kwargs):
        raise AssertionError("no viewer may be started without a display")
    monkeypatch.setattr(replay_cli.subprocess, "Popen", no_popen)
    path = high_five_file["path"]
    assert cli.main(["replay", str(path)]) == 0
    out = capsys.readouterr().out
    assert "no display" in out
    assert f"rerun {path}" in out and f"mimo-social replay {path} --summary" in out


def test_with_a_display_it_starts_the_viewer(high_five_file, monkeypatch, capsys):
    started = []

    class FakePopen:
        pid = 4242

        def __init__(self, args, **kwargs):
            started.append((args, kwargs))
    monkeypatch.setenv("DISPLAY", ":99")
    monkeypatch.setattr(replay_cli.shutil, "which", lambda name: f"/opt/bin/{name}")
    monkeypatch.setattr(replay_cli.subprocess, "Popen", FakePopen)
    path = high_five_file["path"]
    assert cli.main(["replay", str(path)]) == 0
    assert started == [(["/opt/bin/rerun", str(path)],
                        {"stdin": subprocess.DEVNULL, "start_new_session": True})]
    assert "4242" in capsys.readouterr().out
    # a display but no rerun executable: the instructions instead
    monkeypatch.setattr(replay_cli.shutil, "which", lambda name: None)
    started.clear()
    assert cli.main(["replay", str(path)]) == 0
    assert not started and "not on the PATH" in capsys.readouterr().out


def test_missing_or_unreadable_files_are_reported(tmp_path, capsys):
    assert cli.main(["replay", str(tmp_path / "nothing.rrd")]) == 2
    assert "no such file" in capsys.readouterr().err
    junk = tmp_path / "junk.rrd"
    junk.write_bytes(b"not a recording at all")
    assert cli.main(["replay", str(junk), "--summary"]) == 2
    assert "cannot read" in capsys.readouterr().err


def test_subcommand_is_registered():
    assert replay_cli in cli.SUBCOMMANDS
    args = cli.build_parser().parse_args(["replay", "x.rrd", "--summary"])
    assert (args.file, args.summary, args.func) == ("x.rrd", True, replay_cli.run)


def test_command_line_end_to_end(high_five_file):
    done = subprocess.run([sys.executable, "-m", "mimo_social.cli", "replay",
                           str(high_five_file["path"]), "--summary"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert f"steps: {N_STEPS + 1}" in done.stdout


def test_bench_recording_subcommand_measures_chosen_configurations(tmp_path, capsys):
    from mimo_social.cli import bench_recording

    assert bench_recording in cli.bench.MEASUREMENTS.values()
    assert cli.main(["bench", "recording", "--sim-seconds", "0.2", "--only", "0",
                     "--folder", str(tmp_path)]) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert len(lines) == 5 and lines[0].startswith("| configuration |")
    assert lines[2].startswith("| 2 infants, no images |")
    assert (tmp_path / "bench_0.rrd").stat().st_size > 0
    # 0.2 simulated s: the file's fixed part would be the size per minute; no cost, no size
    assert lines[2].endswith("| too short | too short | too short | too short |")
    assert lines[4].startswith("too short: under 30 simulated s a run gives no cost or size")
    assert err == ("mimo-social bench recording: warning: --sim-seconds 0.2: too short for a "
                   "cost or a size per minute (they are left out); give --sim-seconds >= 30\n")
    with pytest.raises(SystemExit, match="--only"):
        cli.main(["bench", "recording", "--only", "first"])
    # long enough: the figures, no note
    from mimo_social.bench.recording_cost import format_table
    row = {"config": "c", "ms_per_step": 1.0, "ms_per_step_recorded": 1.1, "cpu_pct": 12.0,
           "main_cpu_pct": 8.0, "wall_pct": 10.0, "mb_per_sim_minute": 14.7, "too_short": False}
    assert format_table([row]).splitlines()[2:] == [
        "| c | 1.000 | 1.100 | 12.0 % | 8.0 % | 10.0 % | 14.7 |"]
