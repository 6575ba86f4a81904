"""``mimo-social bench soak`` with tiny numbers: it writes the samples (CSV), the figures (JSON), the
plot (PNG) and prints the growth per 100k steps; what it samples and fits is right."""

from __future__ import annotations

import csv
import json
import math
import os
import threading

import numpy as np
import pytest

from mimo_social import cli
from mimo_social.bench import soak

ARGS = ["--steps", "600", "--vision-steps", "2e2", "--episode-steps", "50",
        "--sample-every", "100", "--vision-size", "16", "--seed", "3", "--no-progress"]


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    """A soak of 600 + 200 steps, long enough for a growth figure with a fit of 100 steps after
    the warm-up (the real minimum, 20k steps, is too long for a test)."""
    out = tmp_path_factory.mktemp("soak")
    import io
    from contextlib import redirect_stdout
    buf = io.StringIO()
    with pytest.MonkeyPatch.context() as mp, redirect_stdout(buf):
        mp.setattr(soak, "MIN_FIT_STEPS", 100)
        code = cli.main(["bench", "soak", *ARGS, "--out", str(out)])
    return out, code, buf.getvalue()


def test_soak_writes_csv_json_png_and_prints_the_growth(ran):
    out, code, printed = ran
    assert code == 0
    with open(out / "soak.csv") as f:
        rows = list(csv.DictReader(f))
    assert set(rows[0]) == set(soak.CSV_FIELDS)
    touch = [r for r in rows if r["phase"] == "touch"]
    vision = [r for r in rows if r["phase"] == "vision+recording"]
    # a sample at the start and every min(100, steps // 20) steps (at least 20 a phase)
    assert [int(r["step"]) for r in touch] == list(range(0, 601, 30))
    assert [int(r["step"]) for r in vision] == list(range(0, 201, 10))
    assert int(vision[-1]["total_step"]) == 800
    for r in rows:
        assert float(r["rss_mb"]) > 10 and int(float(r["threads"])) >= 1
        assert int(float(r["fds"])) >= 3
    # every episode of 50 steps is its own recording, the next opened at once
    assert [int(r["recordings"]) for r in vision][::5] == [1, 2, 3, 4, 5]
    figures = json.loads((out / "soak.json").read_text())
    assert figures["command"].startswith("mimo-social bench soak --steps 600 --vision-steps 200")
    assert figures["settings"]["seed"] == 3
    for phase, n in (("touch", 600), ("vision+recording", 200)):
        f = figures["phases"][phase]
        assert f["steps"] == n and f["steps_per_s"] > 0
        assert set(f["growth_per_100k"]) == {"rss_mb", "threads", "fds"}
        assert all(math.isfinite(v) for v in f["growth_per_100k"].values())
    assert figures["phases"]["touch"]["episodes"] == 12
    # the warm-up: 10 % of the steps, at least two episodes of 50
    assert figures["phases"]["touch"]["warmup_steps"] == 100
    assert figures["phases"]["vision+recording"]["warmup_steps"] == 100
    assert figures["phases"]["touch"]["resolution_mb_per_100k"] == pytest.approx(1e5 / 500)
    assert (out / "soak.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "touch" in printed and "vision+recording" in printed and "MB/100k" in printed
    g = figures["phases"]["vision+recording"]["growth_per_100k"]["threads"]
    assert f"{g:.2f}" in printed


def test_the_recordings_are_deleted_as_it_goes_unless_kept(tmp_path):
    keep = tmp_path / "recs"
    res = soak.soak(0, 120, episode_steps=30, sample_every=60, vision_size=16, progress=False,
                    folder=keep, keep_recordings=True)
    assert sorted(p.name for p in keep.glob("*.rrd")) == [f"ep{k:06d}.rrd" for k in range(5)]
    assert res["phases"]["vision+recording"]["recordings"] == 5
    assert res["phases"]["vision+recording"]["episodes"] == 4
    gone = tmp_path / "gone"
    soak.soak(0, 120, episode_steps=30, sample_every=60, vision_size=16, progress=False,
              folder=gone)
    assert len(list(gone.glob("*.rrd"))) == 1            # only the last one


def test_growth_is_the_least_squares_slope_after_the_warm_up():
    steps = np.arange(0, 200_001, 10_000)
    values = 100.0 + 3.0 * steps / 1e5
    values[0] = 50.0                                       # warm-up: left out of the fit
    assert soak.growth_per_100k(steps, values, warmup_step=10_000) == pytest.approx(3.0)
    assert soak.growth_per_100k(steps, values) != pytest.approx(3.0)
    assert math.isnan(soak.growth_per_100k([0], [1.0]))


def test_process_sample_sees_a_new_thread_and_an_open_file(tmp_path):
    before = soak.process_sample()
    stop = threading.Event()
    t = threading.Thread(target=stop.wait)
    t.start()
    fd = os.open(tmp_path / "x", os.O_CREAT | os.O_RDWR)
    big = np.ones(64 * 2 ** 20 // 8)                      # 64 MB touched
    try:
        after = soak.process_sample()
    finally:
        os.close(fd)
        stop.set()
        t.join()
    assert after["threads"] == before["threads"] + 1
    assert after["fds"] == before["fds"] + 1
    assert after["rss_mb"] - before["rss_mb"] > 50
    del big


@pytest.mark.parametrize("bad", [["--steps", "-1"], ["--steps", "abc"], ["--steps", "1.5"],
                                 ["--vision-steps", "nan"], ["--seed", "-2"],
                                 ["--sample-every", "0"], ["--warmup", "2"],
                                 ["--vision-size", "4"], ["--episode-steps", "1e20"]])
def test_bad_arguments_are_usage_errors(bad, capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["bench", "soak", *bad])
    assert e.value.code == 2
    assert bad[0] in capsys.readouterr().err


def test_nothing_to_run_says_so(capsys):
    assert cli.main(["bench", "soak", "--steps", "0", "--vision-steps", "0",
                     "--no-progress"]) == 2
    assert "nothing to run" in capsys.readouterr().err


@pytest.mark.parametrize("where", ["file", "file/sub"])
def test_an_output_folder_that_cannot_be_made_is_one_line_before_the_run(where, tmp_path,
                                                                        capsys, monkeypatch):
    ran = []
    monkeypatch.setattr(soak, "soak", lambda *a, **k: ran.append(a))
    (tmp_path / "file").write_text("x")
    out = tmp_path / where
    with pytest.raises(SystemExit) as e:
        cli.main(["soak", "--steps", "10", "--no-progress", "--out", str(out)])
    assert e.value.code == 2 and not ran
    last = capsys.readouterr().err.splitlines()[-1]
    assert last.startswith(f"mimo-social soak: error: argument --out: {out}: ")
    assert last.endswith("is a file; allowed: a folder to write into"
                         if where == "file" else "file is a file, not a folder")
    assert "Errno" not in last


def test_min_phase_steps_is_the_warm_up_and_the_fit_a_growth_needs():
    assert soak.MIN_FIT_STEPS == 20_000 and soak.RSS_JITTER_MB * 1e5 / soak.MIN_FIT_STEPS == 5
    assert soak.min_phase_steps() == 22_223                   # 10 % warm-up: 2,223 steps
    assert soak.min_phase_steps(episode_steps=5000) == 30_000  # two episodes of warm-up
    assert soak.min_phase_steps(warmup=0.5) == 40_000
    assert soak.short_phases(400, 0) == {"touch": 400}
    assert soak.short_phases(10**6, 10**5) == {}


def test_a_phase_too_short_for_a_growth_figure_is_warned_of_and_gives_none(tmp_path, capsys):
    """400 steps: the first episode's allocations would read as hundreds of MB per 100k."""
    assert cli.main(["bench", "soak", "--steps", "400", "--vision-steps", "0", "--no-progress",
                     "--episode-steps", "100", "--out", str(tmp_path)]) == 0
    out, err = capsys.readouterr()
    assert err.splitlines()[0] == (
        "mimo-social bench soak: warning: --steps 400: too short for a growth figure of touch "
        "(its growth is left out); give at least 22223 steps (a warm-up of 0.1 of the steps, "
        "at least 2 episodes, then 20000 steps to fit)")
    assert "too short for a growth figure: give it at least 22223 steps" in out
    assert "MB/100k)" not in out
    touch = json.loads((tmp_path / "soak.json").read_text())["phases"]["touch"]
    assert touch["growth_per_100k"] == {"rss_mb": None, "threads": None, "fds": None}
    assert touch["min_steps"] == 22_223 and touch["steps_per_s"] > 0
    assert (tmp_path / "soak.png").exists()


def test_vision_steps_default_to_a_tenth_of_steps(tmp_path, monkeypatch, capsys):
    """``--steps 10`` alone ran 1e5 vision steps (7 min): --vision-steps did not follow it."""
    asked = []

    def fake(steps, vision_steps, **kw):
        asked.append((steps, vision_steps))
        raise OSError(28, "No space left on device", str(tmp_path / "soak.csv"))
    monkeypatch.setattr(soak, "soak", fake)
    for argv, want in ((["--steps", "10"], (10, 1)), (["--steps", "50000"], (50_000, 5000)),
                       (["--steps", "0"], (0, 100_000)), ([], (1_000_000, 100_000)),
                       (["--steps", "10", "--vision-steps", "7"], (10, 7))):
        assert cli.main(["bench", "soak", *argv, "--no-progress", "--out", str(tmp_path)]) == 1
        assert asked.pop() == want
    assert capsys.readouterr().err.splitlines()[-1] == (
        f"mimo-social bench soak: error: cannot write the outputs {tmp_path / 'soak.csv'}: "
        "No space left on device")
