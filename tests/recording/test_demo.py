"""The demo (`mimo-social demo`, :mod:`mimo_social.experiments.demo`): an 18-month-old and a
kneeling caregiver, a high five then a handover, recorded with eyes and skin to one .rrd file.
Checked by reading the file back (``recording.summary`` and Rerun's ``RrdReader``)."""

import argparse

import numpy as np
import pyarrow as pa
import pytest

from mimo_social.cli import demo as demo_cli
from mimo_social.cli import main
from mimo_social.experiments import demo
from mimo_social.experiments.demo_task import PHASES
from mimo_social.recording.summary import read_batches, summarize
from mimo_social.util.checks import ConfigError

INFANT, CAREGIVER = "infant_0", "caregiver_0"


def series(data, path: str, component: str) -> list[tuple[float, object]]:
    """(sim_time s, value) of every non-null timed ``component`` row at ``path``, by time."""
    out = []
    for batch in data.get(path, []):
        names = batch.schema.names
        if component not in names or "sim_time" not in names:
            continue
        times = batch.column("sim_time").cast(pa.int64()).to_pylist()
        out += [(t / 1e9, v) for t, v in zip(times, batch.column(component).to_pylist())
                if v is not None]
    return sorted(out, key=lambda r: r[0])


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    """The whole demo at its defaults (seed 0), recorded once for the tests of this module."""
    path = tmp_path_factory.mktemp("demo") / "demo.rrd"
    run = demo.record_demo(path, progress=False)
    return run, summarize(path), read_batches(path)


def test_the_interaction_succeeds(full):
    """The high five, then the handover (the ball held by the infant alone), in one run."""
    run, _, data = full
    assert run.stopped is None and run.phases == PHASES
    assert run.high_five_s is not None and run.handover_s is not None
    assert 0.2 < run.high_five_s < demo.HIGH_FIVE_WAIT_S
    assert run.high_five_s + demo.CELEBRATE_S < run.handover_s < run.seconds
    # the task's plots in the recording say the same
    success = series(data, "/plots/success", "Scalars:scalars")
    holder = series(data, "/plots/holder", "Scalars:scalars")
    first = [t for t, v in success if v[0] == 1.0]
    assert first and abs(first[0] - run.high_five_s) < 1e-6
    assert any(v[0] == 1.0 for t, v in holder if t >= run.handover_s)     # the infant holds it
    assert holder[-1][1][0] == 1.0                                       # ... to the end


def test_the_recording_holds_eyes_skin_and_contacts_between_the_agents(full):
    run, s, _ = full
    assert len(s["recordings"]) == 1 and s["complete"]         # one recording, one timeline
    assert s["agents"] == [INFANT, CAREGIVER]
    assert s["duration_s"] == pytest.approx(run.seconds, abs=1e-6)
    for agent in (INFANT, CAREGIVER):
        assert s["eye_images"][agent]["left"] > 50 and s["eye_images"][agent]["right"] > 50
        assert s["skin_rows"][agent] > 50 and s["skin_points"][agent] > 1000
    contacts = [text for _, text in s["contact_events"]]
    assert len(contacts) >= run.contact_events >= 1
    # the high five: the infant's right hand touches the caregiver's
    assert any(t.startswith(f"{INFANT} right_") and f" touches {CAREGIVER} right_" in t
               for t in contacts)
    assert "/world/props/ball" in s["entities"]
    # in the play room (the default scene): its toys are in the recording
    assert run.scene == "playroom"
    assert any(e.startswith("/world/props/playroom") for e in s["entities"])


def test_faces_change_with_the_events(full):
    """Both smile at the high five; new episode, faces neutral; the infant is surprised when
    the ball first touches its hand; both smile once it holds the ball."""
    run, _, data = full
    logged = {a: [(t, v[0]) for t, v in series(data, f"/agents/{a}/expression", "TextLog:text")]
              for a in (INFANT, CAREGIVER)}
    assert [e for _, e in logged[INFANT]] == ["neutral", "happy", "neutral", "surprised",
                                              "happy"]
    assert [e for _, e in logged[CAREGIVER]] == ["neutral", "happy", "neutral", "happy"]
    dt = 0.01
    assert logged[INFANT][1][0] == pytest.approx(run.high_five_s + dt, abs=1e-6)
    assert logged[CAREGIVER][1][0] == pytest.approx(run.high_five_s + dt, abs=1e-6)
    assert run.high_five_s < logged[INFANT][3][0] < run.handover_s       # surprised before
    assert logged[INFANT][4][0] == pytest.approx(run.handover_s + dt, abs=1e-6)
    assert [(a, e) for _, a, e in run.faces] == \
        [(a, e) for a in (INFANT, CAREGIVER) for e in ["neutral"]] + [
            (INFANT, "happy"), (CAREGIVER, "happy"), (INFANT, "neutral"),
            (CAREGIVER, "neutral"), (INFANT, "surprised"), (INFANT, "happy"),
            (CAREGIVER, "happy")]
    # the face images follow (a head texture per change that is shown long enough)
    assert len(series(data, f"/agents/{INFANT}/face", "Image:buffer")) == 5


def test_the_report_says_what_happened(full):
    run, s, _ = full
    text = demo_cli.report(run, 3.0, s)
    assert f"{run.high_five_s:5.2f} s  high five" in text
    assert f"{run.handover_s:5.2f} s  handover" in text
    assert "neutral -> happy -> neutral -> surprised -> happy" in text
    assert f"contact events between the two: {len(s['contact_events'])} (first: step" in text
    assert f"rerun {run.path}" in text and f"mimo-social replay {run.path}" in text


def test_demo_parser_defaults():
    parser = argparse.ArgumentParser()
    demo_cli.add_parser(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["demo"])
    assert (args.record, args.seconds, args.seed, args.scene) == (
        "recordings/demo.rrd", demo.DEFAULT_SECONDS, 0, demo.DEFAULT_SCENE)
    assert args.func is demo_cli.run


def test_the_subcommand_cut_short_writes_a_readable_recording(tmp_path, capsys):
    """--seconds cuts the script: 0.3 s is the high five's approach only."""
    path = tmp_path / "sub" / "demo.rrd"
    assert main(["demo", "--seconds", "0.3", "--record", str(path), "--seed", "4",
                 "--scene", "floor"]) == 0
    out = capsys.readouterr().out
    assert "Recorded 0.30 s of simulated time (30 steps, scene floor, seed 4)" in out
    assert "high five: not reached in the recorded time" in out
    assert f"rerun {path}" in out
    s = summarize(path)
    assert s["steps"] == 31 and s["agents"] == [INFANT, CAREGIVER]
    assert s["eye_images"][INFANT]["left"] >= 1


@pytest.mark.parametrize("kwargs, name", [
    ({"seconds": 0.0}, "seconds"), ({"seconds": float("nan")}, "seconds"),
    ({"seed": -1}, "seed"), ({"scene": "moon"}, "scene")])
def test_bad_settings_name_the_setting(tmp_path, kwargs, name):
    with pytest.raises((ConfigError, ValueError), match=name):
        demo.record_demo(tmp_path / "x.rrd", progress=False, **kwargs)
    assert not (tmp_path / "x.rrd").exists()


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(6))
def test_the_interaction_succeeds_for_seeds_0_to_5(tmp_path, seed):
    """Measured: seeds 0-5 succeed in both phases (of 0-9: 6, 7 and 9 keep the ball in the
    caregiver's hand for 6 s, 8 misses the high five for 3 s)."""
    run = demo.record_demo(tmp_path / "d.rrd", seconds=8.0, seed=seed, progress=False)
    assert run.high_five_s is not None and run.handover_s is not None, run
    assert np.isfinite(run.seconds)
