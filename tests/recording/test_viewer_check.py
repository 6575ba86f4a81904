"""The real-browser check of a replay (issue 20), a developer's check that lives beside the
package in ``scripts/`` (``python3 scripts/check_viewer.py FILE.rrd``, issue 27): Rerun's web
viewer in headless Chromium shows the bodies of a play-room recording in its 3D view, and does
not pass a recording without bodies.

The browser tests are slow (``-m slow``: minutes of software WebGL) and skipped (with the
reason) where Chromium, Playwright or ``rerun`` is missing; the pixel, colour and argument tests
run by default and everywhere.
"""

from __future__ import annotations

import colorsys
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from mimo_social.core.world import CLOTHES_PALETTE
from mimo_social.envs import high_five_v0
from mimo_social.recording.recorder import Recorder

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"
sys.path.insert(0, str(SCRIPTS))       # the check is a script's module, not the package's

import check_viewer as script  # noqa: E402
from viewer_check import (SEPARATOR_RGB, TIMEOUT, ViewerCheckError,  # noqa: E402
                          browser_missing, check_viewer, colour_pixels, empty_panels,
                          find_3d_view, is_empty_panel, panel_boxes, recording_colours,
                          screenshot, time_bar, without_agents)
from viewer_check.web_viewer import Browser, rerun_command  # noqa: E402

main = script.main

MISSING = browser_missing()
needs_browser = pytest.mark.skipif(MISSING is not None, reason=f"viewer check: {MISSING}")
BLUE, RED = (tuple(round(255 * c) for c in CLOTHES_PALETTE[i][:3]) for i in (0, 1))


def _record(path, steps: int = 200):
    """A short run of the high five pair in the play room (random actions, eyes, faces)."""
    env = high_five_v0.scripted_env(vision={"width": 32, "height": 32}, expressions=True,
                                    scene="playroom")
    try:
        obs, _ = env.reset(seed=0)
        rng = np.random.default_rng(0)
        with Recorder(env, path) as rec:
            rec.log_reset(obs)
            for k in range(steps):
                acts = {}
                for a in env.agents:
                    space = env.action_space(a)
                    space.seed(int(rng.integers(2**31)))
                    acts[a] = space.sample()
                obs, rewards, _, _, _ = env.step(acts)
                rec.log_step(acts, rewards, obs)
                if not env.agents:
                    break
    finally:
        env.close()
    return path


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    return _record(tmp_path_factory.mktemp("viewer") / "play_room.rrd")


def _no_bodies(path):
    """A recording of the floor alone: no agent, nothing of the clothes colours."""
    rec = rr.RecordingStream("mimo_social", recording_id="no-bodies")
    rec.save(str(path))
    rec.log("world/scene/floor", rr.Boxes3D(half_sizes=[[2, 2, 0.01]], colors=[[198, 188, 168]],
                                            fill_mode="solid"), static=True)
    for k in range(5):
        rec.set_time("sim_time", duration=0.1 * k)
        rec.log("agents/nobody/reward", rr.Scalars(0.0))
    rec.flush()
    rec.disconnect()
    return path


# ---------------------------------------------------------------- pixels and colours (no browser)

def _page(panel_colour=None, small_colour=None):
    """A fake viewer page: white, a 1-px grey frame around a large panel (left) and two small
    ones (right); the large panel optionally holds a patch of ``panel_colour``, lit darker, the
    small ones ``small_colour``."""
    img = np.full((540, 960, 3), 255, np.uint8)
    img[20, :] = img[:, 600] = img[280, 600:] = SEPARATOR_RGB
    if panel_colour is not None:
        img[200:260, 200:260] = np.array(panel_colour) * 0.6        # in shadow
        img[260:280, 200:260] = panel_colour
    if small_colour is not None:
        img[60:200, 650:900] = small_colour
        img[320:500, 650:900] = small_colour
    return img


def test_the_3d_view_is_the_largest_panel_and_only_its_pixels_count():
    img = _page(panel_colour=BLUE, small_colour=RED)
    x0, y0, x1, y1 = find_3d_view(img)
    assert x0 < 10 and 20 < y0 < 30 and 590 < x1 <= 600 and y1 == 540
    box = (x0, y0, x1, y1)
    assert colour_pixels(img, BLUE, box) == 60 * 80            # lit and in shadow
    assert colour_pixels(img, RED, box) == 0                    # only in the small panels
    assert colour_pixels(img, RED) > 10_000


def test_background_floor_skin_and_grey_are_not_clothes_colours():
    img = np.zeros((4, 1, 3), np.uint8)
    img[:, 0] = [(255, 255, 255), (198, 188, 168), (240, 199, 171), (140, 140, 140)]
    for rgb in (BLUE, RED, (115, 191, 115)):
        assert colour_pixels(img, rgb) == 0
    hue = colorsys.rgb_to_hsv(*(c / 255 for c in RED))[0] * 360
    near = colorsys.hsv_to_rgb(((hue + 10) % 360) / 360, 0.55, 0.7)
    far = colorsys.hsv_to_rgb(((hue + 40) % 360) / 360, 0.55, 0.7)
    assert colour_pixels(np.array([[[round(255 * c) for c in near]]], np.uint8), RED) == 1
    assert colour_pixels(np.array([[[round(255 * c) for c in far]]], np.uint8), RED) == 0


def test_time_bar_is_the_long_dark_run_at_the_bottom():
    img = np.full((300, 800, 3), 255, np.uint8)
    img[285:289, 100:700] = 40
    x0, x1, y = time_bar(img)
    assert (x0, x1) == (100, 699) and 285 <= y < 289
    assert time_bar(np.full((300, 800, 3), 255, np.uint8)) is None


def _panels_page(empty: bool):
    """A fake viewer page of four panels, each with a title bar (its name in dark grey): a large
    one, an image, a plot, and one whose body holds only a short line of grey text in its middle
    (``empty``: the viewer's "No data available") or an image; and a blank grid cell (no title)."""
    img = np.full((540, 960, 3), 255, np.uint8)
    img[:, 500] = img[:, 730] = img[270, 500:] = SEPARATOR_RGB
    for x0, y0 in ((0, 0), (501, 0), (731, 0), (501, 271)):
        img[y0 + 8:y0 + 18, x0 + 10:x0 + 90] = (60, 60, 60)            # the panel's name
    img[40:500, 20:480] = (120, 160, 90)                                # the 3D view's scene
    img[40:260, 510:720] = (240, 200, 170)                              # a face image
    img[60:250, 740] = img[250, 740:950] = 80                           # a plot's axes
    img[100:200:7, 745:945] = 200
    img[200:240, 745:945:3] = (200, 60, 50)
    if empty:
        img[395:405, 570:660] = (90, 90, 90)                            # "No data available"
    else:
        img[300:520, 510:720] = (90, 140, 200)
    return img


def test_the_panels_are_found_and_one_without_data_is_told():
    full, empty = _panels_page(False), _panels_page(True)
    boxes = panel_boxes(full)
    assert len(boxes) == 5 and boxes[0][2] <= 500             # the largest first
    assert empty_panels(full) == []                            # the blank cell is no panel
    lacking = empty_panels(empty)
    assert len(lacking) == 1
    x0, y0, x1, y1 = lacking[0]
    assert 495 <= x0 <= 505 and 265 <= y0 <= 275 and x1 >= 725 and y1 == 540
    assert is_empty_panel(empty, lacking[0]) and not is_empty_panel(full, lacking[0])
    blank = full.copy()
    blank[300:520, 510:720] = 255                               # nothing at all: empty too
    assert empty_panels(blank) == lacking


def _error(text):
    from playwright.sync_api import Error
    return Error(text)


class _Page:
    """A fake Playwright page: its first screenshots fail (``failures``: the errors' texts), its
    first loads fail (``loads``: True for each that fails); it notes what each was allowed."""

    def __init__(self, failures=(), loads=()):
        self.failures, self.loads = list(failures), list(loads)
        self.timeouts, self.closed, self.visited = [], False, []

    def screenshot(self, timeout=30_000):
        self.timeouts.append(timeout)
        if self.failures:
            raise _error(self.failures.pop(0))
        return b"png"

    def is_closed(self):
        return self.closed

    def set_default_timeout(self, ms):
        self.default = ms

    def set_default_navigation_timeout(self, ms):
        self.navigation = ms

    def on(self, event, handler):
        self.handler = handler

    def goto(self, url, wait_until=None, timeout=None):
        self.visited.append(url)
        if self.loads and self.loads.pop(0):
            raise _error("page.goto: Timeout 900000ms exceeded.")

    def wait_for_selector(self, selector, state=None, timeout=None):
        return None

    def close(self):
        self.closed = True


@needs_browser
def test_a_screenshot_waits_as_long_as_the_check_allows_and_is_taken_again():
    """Not Playwright's fixed 30 s: the check's own limit; a failed one is taken again."""
    page = _Page(failures=["Timeout 30000ms exceeded.", "Protocol error "
                           "(Page.captureScreenshot): Internal error"])
    assert screenshot(page, 600.0) == b"png"
    assert page.timeouts == [600_000] * 3
    page = _Page(failures=["Internal error"] * 3)
    with pytest.raises(ViewerCheckError, match="no screenshot .* 3 attempts .* Internal error"):
        screenshot(page, TIMEOUT)


@needs_browser
def test_a_browser_failure_is_one_line_of_the_check_not_a_traceback():
    from viewer_check.web_viewer import browser_errors

    with pytest.raises(ViewerCheckError) as e:
        with browser_errors("showing the recording"):
            raise _error("Protocol error (Input.dispatchMouseEvent): Internal error\nCall log:")
    assert str(e.value) == ("the browser failed while showing the recording: Protocol error "
                            "(Input.dispatchMouseEvent): Internal error")


@needs_browser
def test_a_page_that_does_not_load_is_opened_again():
    pages = [_Page(loads=[True]), _Page(loads=[True, True]), _Page()]
    browser = Browser()
    browser.browser = type("Fake", (), {"new_page": lambda self, **kw: pages.pop(0)})()
    said = []
    opened = pages[2]
    assert browser.open("http://viewer", (1280, 720), 900.0, say=said.append) is opened
    assert opened.default == opened.navigation == 900_000 and opened.visited == ["http://viewer"]
    assert len(said) == 2 and "opening it again (3 of 3)" in said[-1]
    pages = [_Page(loads=[True]) for _ in range(3)]
    browser.browser = type("Fake", (), {"new_page": lambda self, **kw: pages.pop(0)})()
    with pytest.raises(ViewerCheckError, match="did not load in 3 attempts"):
        browser.open("http://viewer", (1280, 720), 900.0)


def test_the_colours_looked_for_are_the_agents_clothes(recording):
    colours = recording_colours(recording)
    assert list(colours) == ["infant_0", "infant_1"]
    assert np.abs(np.subtract(colours["infant_0"], BLUE)).max() <= 1
    assert np.abs(np.subtract(colours["infant_1"], RED)).max() <= 1


def test_a_recording_without_bodies_has_nothing_to_look_for(tmp_path):
    path = _no_bodies(tmp_path / "floor.rrd")
    assert recording_colours(path) == {}
    with pytest.raises(ViewerCheckError, match="nothing to look for"):
        check_viewer(path, progress=None)


def test_the_script_refuses_a_bad_size_and_a_missing_file(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        main([str(tmp_path / "none.rrd")])
    err = capsys.readouterr().err
    assert e.value.code == 2 and "no such file" in err
    assert err.strip().splitlines()[-1].startswith("scripts/check_viewer.py: error: argument")
    path = _no_bodies(tmp_path / "floor.rrd")
    for bad, why in (("1920", "WIDTHxHEIGHT"), ("axb", "WIDTHxHEIGHT"),
                     ("10x10", "width 640 to 7680")):
        with pytest.raises(SystemExit) as e:
            main([str(path), "--size", bad])
        assert e.value.code == 2 and why in capsys.readouterr().err


def test_the_script_runs_from_the_command_line_and_says_why_it_fails(tmp_path):
    """Run as the README says (its own folder on the path); a recording without bodies is one
    line, exit code 1, before any browser starts."""
    path = _no_bodies(tmp_path / "floor.rrd")
    done = subprocess.run([sys.executable, str(SCRIPTS / "check_viewer.py"), str(path)],
                          capture_output=True, text=True)
    assert done.returncode == 1, done.stderr
    assert "Traceback" not in done.stderr
    assert done.stderr.strip() == (f"scripts/check_viewer.py: FAILED: {path}: no agent body "
                                   "with a saturated clothes colour under /world/<agent>/: "
                                   "nothing to look for")


def test_the_check_left_the_package(capsys):
    import importlib

    from mimo_social import cli

    with pytest.raises(SystemExit) as e:
        cli.main(["check-viewer", "x.rrd"])
    assert e.value.code == 2 and "invalid choice: 'check-viewer'" in capsys.readouterr().err
    for gone in ("mimo_social.recording.viewer_check", "mimo_social.recording.web_viewer"):
        with pytest.raises(ModuleNotFoundError):
            importlib.import_module(gone)


# ------------------------------------------------------------------------------ in the browser

@pytest.mark.slow
@needs_browser
def test_the_web_viewer_shows_both_bodies_in_its_3d_view(recording, tmp_path, capsys):
    shot = tmp_path / "shot.png"
    code = main([str(recording), "--screenshot", str(shot),
                 "--size", "1280x720"])              # half the pixels of 1920x1080: faster
    out = capsys.readouterr().out
    assert code == 0, out
    # every poll looks at the other panels too: the faces, eyes and plots showed their data
    assert re.search(r"; 0 of \d+ other panels without data$", out, re.M), out
    # progress shown at every poll (a poll before the load says "loading the data"; on a quiet
    # machine the first poll may already find it loaded)
    assert "viewer check passed" in out
    assert re.search(r"^ +\d+\.\d s: (loading the data|data loaded after)", out, re.M), out
    assert "without the agents" in out                  # the scene's own pixels were counted
    assert shot.is_file() and shot.stat().st_size > 50_000
    from PIL import Image
    assert Image.open(shot).size == (1280, 720)


@pytest.mark.slow
@needs_browser
def test_a_recording_without_bodies_fails_the_check(tmp_path):
    path = _no_bodies(tmp_path / "floor.rrd")
    shot = tmp_path / "floor.png"
    with pytest.raises(ViewerCheckError) as e:      # fails: it may give up soon after the load
        check_viewer(path, screenshot=shot, colours={"infant_0": BLUE, "infant_1": RED},
                     settle=8, progress=None)
    text = str(e.value)
    assert "does not show the bodies" in text and "infant_0 (#" in text and ": 0 px" in text
    assert str(shot) in text and shot.is_file()


@pytest.mark.slow
@needs_browser
def test_the_play_room_without_its_agents_fails_the_check(recording, tmp_path):
    """The room has a blue sofa and red table legs: their pixels alone must not pass."""
    empty = without_agents(recording, ["infant_0", "infant_1"], tmp_path / "empty.rrd")
    with pytest.raises(ViewerCheckError, match="without the agents") as e:
        check_viewer(empty, screenshot=tmp_path / "empty.png", colours=recording_colours(recording),
                     settle=10, progress=None)
    assert "does not show the bodies" in str(e.value)


@pytest.mark.slow
@needs_browser
def test_panels_without_data_fail_the_check(recording, tmp_path):
    """The bodies show, but the faces and eyes are not in the file: their six panels show only
    "No data available" (what a screenshot taken before the images had loaded showed)."""
    agents = list(recording_colours(recording))
    drop = [f"/agents/{a}/{p}" for a in agents for p in ("face", "eyes/left", "eyes/right")]
    faceless = tmp_path / "faceless.rrd"
    subprocess.run(rerun_command() + ["rrd", "filter", str(recording), "-o", str(faceless)]
                   + [arg for e in drop for arg in ("--drop-entity", e)], check=True,
                   capture_output=True, stdin=subprocess.DEVNULL)
    shot = tmp_path / "faceless.png"
    with pytest.raises(ViewerCheckError, match="6 panels show no data") as e:
        check_viewer(faceless, screenshot=shot, size="1280x720", baseline=False, settle=20,
                     progress=None)
    assert str(shot) in str(e.value) and shot.is_file()


@pytest.mark.slow
@needs_browser
def test_the_demo_in_the_viewer(tmp_path):
    from mimo_social.experiments.demo import record_demo

    run = record_demo(tmp_path / "demo.rrd", progress=False)
    result = check_viewer(run.path, screenshot=tmp_path / "demo.png", at=0.8, wait=4,
                          progress=None)     # as docs/demo_viewer.png is made
    assert len(result.pixels) == 2 and min(result.pixels.values()) >= 150
    assert result.scene is not None
