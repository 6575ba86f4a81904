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
    out = tmp_path_factory.mktemp("soak")
    import io
    from contextlib import redirect_stdout
    buf = io.StringIO()
    with redirect_stdout(buf):
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


def test_an_output_folder_that_cannot_be_made_is_refused_before_the_run(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert cli.main(["bench", "soak", "--steps", "10", "--vision-steps", "0", "--no-progress",
                     "--out", str(blocker / "sub")]) == 1
    err = capsys.readouterr().err
    assert "--out" in err and "sub" in err
