"""A real-browser check of a recording: Rerun's web viewer in headless Chromium shows the bodies
(a developer's check, outside the package: ``python3 scripts/check_viewer.py FILE.rrd``).

:func:`check_viewer` serves the ``.rrd`` over HTTP (with an ``Access-Control-Allow-Origin``
header: the viewer's page comes from another port), starts ``rerun --web-viewer`` on a free port
(no browser opened; the process group is ended at the end, also on errors), opens the viewer
with the file's URL in headless Chromium (driven by Playwright; software WebGL through
SwiftShader), and polls screenshots until the data is loaded and the 3D view shows every
agent's clothes colour (read from the recording's own body shapes). A play room has furniture
and toys of the same hues (a red table, a blue sofa), so it then opens, the same way, a copy of
the recording without the agents (``rerun rrd filter``; same layout and camera) and counts
only the pixels the bodies add. It returns a :class:`ViewerCheck`, or raises
:class:`ViewerCheckError` naming what is missing and where the screenshots are.

The 3D view is found in the screenshot itself: the viewer separates its panels with one-pixel
lines of one grey; the largest region they enclose is the 3D view in the layout of
:mod:`mimo_social.recording.blueprint` (``view=`` gives another region). A pixel counts for a
colour when its hue is within :data:`HUE_TOLERANCE` degrees of the colour's and it is saturated
and bright enough (lighting scales the colour but keeps its hue), so background, floor, skin and
the grey grid do not count. Every other panel must show data (:mod:`.panels`): a face, an eye
or a plot that shows only "No data available" (its data not yet decoded, or not in the file)
fails the check.

Nothing waits a fixed time: the page is polled until the conditions hold (the viewer's page and
canvas loaded, the viewer's console saying the data has finished loading, the bodies and every
panel shown in two agreeing frames), within generous limits (:data:`TIMEOUT` per page,
:data:`SETTLE` after the load); a page that does not load is opened again, a screenshot that
fails is taken again (:mod:`.web_viewer`).
"""

from __future__ import annotations

import colorsys
import io
import os
import shutil
import tempfile
import time
import urllib.parse
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from mimo_social.util.checks import ConfigError, check_int, check_number

from .panels import SEPARATOR_RGB, long_runs, empty_panels, panel_boxes
from .web_viewer import (Browser, FileServer, ViewerCheckError, WebViewer, browser_missing,
                         chromium_path, without_agents)
from .web_viewer import browser_errors, click
from .web_viewer import screenshot as take_screenshot

__all__ = ["HUE_TOLERANCE", "MIN_PIXELS", "SETTLE", "TIMEOUT", "ViewerCheck", "ViewerCheckError",
           "browser_missing", "check_viewer", "chromium_path", "colour_pixels", "find_3d_view",
           "time_bar", "recording_colours", "without_agents"]

#: degrees of hue a lit pixel may be off its clothes colour
HUE_TOLERANCE = 14.0
#: the fewest pixels of each agent's colour the 3D view must show (at 1920x1080)
MIN_PIXELS = 150
#: the most seconds one page may take, from opening it to the verdict (each wait on it, a
#: screenshot included, is bounded by it); on a quiet machine the demo takes 20-60 s
TIMEOUT = 600.0
#: the most seconds to wait, once the viewer has said the data is loaded, for the bodies and
#: every panel's data to show (images are decoded after the load)
SETTLE = 60.0


@dataclass(frozen=True)
class ViewerCheck:
    """What :func:`check_viewer` saw: the screenshot; each agent's colour (``#rrggbb``); the
    pixels of that colour in the 3D view (``shown``), in the same view of the recording without
    the agents (``scene``: furniture and toys of the same hue; None without a baseline) and
    their difference, the bodies' own (``pixels``); the 3D view's box (x0, y0, x1, y1 in page
    pixels); the seconds from opening the page to the data loaded (None when the viewer did not
    say) and to the colours shown; the baseline's load time; the page size."""

    screenshot: Path
    colours: dict[str, str]
    pixels: dict[str, int]
    shown: dict[str, int]
    scene: dict[str, int] | None
    view: tuple[int, int, int, int]
    load_s: float | None
    shown_s: float
    baseline_load_s: float | None
    size: tuple[int, int]
    console_errors: list[str] = field(default_factory=list)

    def format(self) -> str:
        def one(a):
            scene = "" if self.scene is None else (
                f" ({self.shown[a]} in the view, {self.scene[a]} without the agents)")
            return f"{a} {self.colours[a]} {self.pixels[a]} px{scene}"

        load = "?" if self.load_s is None else f"{self.load_s:.1f} s"
        base = ("" if self.scene is None else ", the recording without the agents after "
                + ("?" if self.baseline_load_s is None else f"{self.baseline_load_s:.1f} s"))
        x0, y0, x1, y1 = self.view
        return (f"viewer check passed: the 3D view ({x1 - x0}x{y1 - y0} px at {x0},{y0}) shows "
                f"the bodies: " + ", ".join(one(a) for a in self.pixels)
                + f"\ndata loaded after {load} (colours shown after {self.shown_s:.1f} s){base};"
                f" page {self.size[0]}x{self.size[1]}\nscreenshot: {self.screenshot}")


# ----------------------------------------------------------------------------------- colours

def _hex(rgb) -> str:
    return "#" + "".join(f"{int(round(c)):02x}" for c in rgb[:3])


def recording_colours(path: str | Path, min_saturation: float = 0.35) -> dict[str, tuple]:
    """Each agent's clothes colour (RGB, 0-255) as logged in the recording: the most common
    saturated colour of the static shapes under ``/world/<agent>/`` that not every agent
    wears (skin, eyes and grey are not saturated, or shared). Agents without one are left
    out."""
    from rerun.chunk import RrdReader

    counts: dict[str, Counter] = {}
    for chunk in RrdReader(Path(path)).stream().to_chunks():
        parts = chunk.entity_path.strip("/").split("/")
        if not chunk.is_static or len(parts) < 3 or parts[0] != "world" \
                or parts[1] in ("scene", "props"):
            continue
        batch = chunk.to_record_batch()
        for name in batch.schema.names:
            if name.endswith(":colors") or name.endswith(":albedo_factor"):
                for cell in batch.column(name).to_pylist():
                    for packed in cell or []:
                        rgb = ((packed >> 24) & 255, (packed >> 16) & 255, (packed >> 8) & 255)
                        counts.setdefault(parts[1], Counter())[rgb] += 1
    shared = set.intersection(*(set(c) for c in counts.values())) if len(counts) > 1 else set()
    out = {}
    for agent, counter in counts.items():
        for rgb, _ in counter.most_common():
            _, s, _ = colorsys.rgb_to_hsv(*(c / 255 for c in rgb))
            if s >= min_saturation and rgb not in shared:
                out[agent] = rgb
                break
    return dict(sorted(out.items(), key=lambda kv: _natural(kv[0])))


def _natural(name: str):
    head = name.rstrip("0123456789")
    tail = name[len(head):]
    return (head, int(tail) if tail else -1)


def _hsv(img: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hue (degrees), saturation and value (0-1) of an RGB uint8 image."""
    rgb = img[..., :3].astype(np.float32) / 255.0
    mx, mn = rgb.max(axis=-1), rgb.min(axis=-1)
    d = mx - mn
    safe = np.where(d > 0, d, 1.0)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    h = np.where(mx == r, (g - b) / safe % 6.0,
                 np.where(mx == g, (b - r) / safe + 2.0, (r - g) / safe + 4.0)) * 60.0
    s = np.where(mx > 0, d / np.where(mx > 0, mx, 1.0), 0.0)
    return np.where(d > 0, h, -1000.0), s, mx


def colour_pixels(img: np.ndarray, rgb, box=None, hue_tolerance: float = HUE_TOLERANCE) -> int:
    """How many pixels of ``img`` (RGB uint8, H x W x 3) inside ``box`` (x0, y0, x1, y1) show
    the colour ``rgb`` lit: hue within ``hue_tolerance`` degrees, saturation at least half the
    colour's (and >= 0.2), value >= 0.15."""
    if box is not None:
        x0, y0, x1, y1 = box
        img = img[y0:y1, x0:x1]
    h, s, v = _hsv(img)
    th, ts, _ = colorsys.rgb_to_hsv(*(c / 255 for c in rgb[:3]))
    diff = np.abs((h - th * 360.0 + 180.0) % 360.0 - 180.0)
    ok = (diff <= hue_tolerance) & (s >= max(0.2, 0.5 * ts)) & (v >= 0.15)
    return int(np.count_nonzero(ok))


# ------------------------------------------------------------------------------ the 3D view

def find_3d_view(img: np.ndarray) -> tuple[int, int, int, int]:
    """The box (x0, y0, x1, y1) of the largest panel of the viewer page in ``img``: the regions
    enclosed by the viewer's long one-pixel separator lines (gaps at their junctions closed)."""
    boxes = panel_boxes(img, min_size=1)
    return boxes[0] if boxes else (0, 0, img.shape[1], img.shape[0])


# ---------------------------------------------------------------------------------- the check

def _parse_size(size) -> tuple[int, int]:
    if isinstance(size, str):
        try:
            w, h = (int(t) for t in size.lower().split("x"))
        except ValueError:
            raise ConfigError(f"viewer check: size {size!r} is not WIDTHxHEIGHT; allowed: e.g. "
                              f"'1920x1080'") from None
        size = (w, h)
    w, h = size
    return (check_int("viewer check", "width", w, 640, 7680),
            check_int("viewer check", "height", h, 480, 4320))


def check_viewer(path: str | Path, screenshot: str | Path | None = None,
                 timeout: float = TIMEOUT, size="1920x1080", colours: dict | None = None,
                 min_pixels: int = MIN_PIXELS, settle: float = SETTLE, view=None,
                 at: float | None = None, wait: float = 0.0, baseline: bool = True,
                 poll: float = 2.0,
                 progress: Callable[[str], None] | None = print) -> ViewerCheck:
    """Open ``path`` in Rerun's web viewer in headless Chromium and check that its 3D view shows
    the bodies and that every other panel shows data (module docstring). ``screenshot``: where
    the PNG goes (default: next to the recording, ``<name>_viewer.png``); ``timeout``: the most
    seconds for each page, from opening it (again, when it does not load) to the verdict; each
    wait on it (a screenshot, a click) is bounded by it, not by a fixed limit; ``size``:
    the page, ``"WxH"`` or (w, h); ``colours``: agent -> RGB (0-255) to look for (default:
    :func:`recording_colours`); ``min_pixels``: of each colour, scaled with the page's area
    from 1920x1080; ``settle``: seconds to wait once the viewer has said the data is loaded
    before failing; ``view``: the 3D view's box (x0, y0, x1, y1) instead of finding it;
    ``at``: once loaded, move the time cursor to this fraction (0 to 1) of the recording (a
    click on the collapsed time panel's bar; playback goes on from there); ``wait``: seconds
    more before the last screenshot; ``baseline``: also open the recording without the agents
    (:func:`without_agents`) and count only the pixels the bodies add (a play room has
    furniture and toys of the clothes' hues); ``progress``: called with a line per poll (None:
    quiet). Raises :class:`ViewerCheckError` when the bodies do not show or a panel shows no
    data (the screenshots are saved first), or a tool is missing."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"viewer check: recording {str(path)!r} is not a file")
    timeout = check_number("viewer check", "timeout", timeout, 1.0)
    settle = check_number("viewer check", "settle", settle, 0.0)
    wait = check_number("viewer check", "wait", wait, 0.0)
    if at is not None:
        at = check_number("viewer check", "at", at, 0.0, 1.0)
    width, height = _parse_size(size)
    shot = Path(screenshot) if screenshot is not None else path.with_name(
        path.stem + "_viewer.png")
    shot.parent.mkdir(parents=True, exist_ok=True)
    if colours is None:
        colours = recording_colours(path)
        if not colours:
            raise ViewerCheckError(f"{path}: no agent body with a saturated clothes colour "
                                   f"under /world/<agent>/: nothing to look for")
    colours = {a: tuple(int(c) for c in rgb[:3]) for a, rgb in colours.items()}
    need = max(1, round(min_pixels * width * height / (1920 * 1080)))
    missing = browser_missing()
    if missing:
        raise ViewerCheckError(f"cannot run the viewer check: {missing}")
    say = progress or (lambda _line: None)
    say(f"viewer check of {path} ({path.stat().st_size / 1e6:.1f} MB) at {width}x{height}; "
        f"looking for " + ", ".join(f"{a} {_hex(c)}" for a, c in colours.items()))
    opts = dict(size=(width, height), colours=colours, view=view, say=say, timeout=timeout,
                settle=settle, at=at, wait=wait, poll=poll, need=need)
    with tempfile.TemporaryDirectory(prefix="mimo_viewer_check_") as tmp:
        folder = Path(tmp)
        try:
            os.symlink(path.resolve(), folder / "recording.rrd")
        except OSError:
            shutil.copyfile(path, folder / "recording.rrd")
        if baseline:
            without_agents(path, list(colours), folder / "without_agents.rrd")
        with FileServer(folder) as files, \
                WebViewer(folder / "rerun.log", start_timeout=timeout) as viewer, \
                Browser() as browser:
            def urls(name):
                file_url = f"http://127.0.0.1:{files.port}/{name}"
                return (f"http://127.0.0.1:{viewer.port}/?url="
                        f"{urllib.parse.quote(file_url, safe='')}", file_url)

            with browser_errors("showing the recording"):
                first = _watch(browser, *urls("recording.rrd"), shot, must_show=True, **opts)
            scene = None
            if baseline and all(n >= need for n in first.counts.values()):
                say("the same view of the recording without the agents (the scene's own "
                    "pixels of these colours):")
                with browser_errors("showing the recording without the agents"):
                    scene = _watch(browser, *urls("without_agents.rrd"),
                                   shot.with_name(shot.stem + "_without_agents.png"),
                                   must_show=False, view=first.box,
                                   **{k: v for k, v in opts.items() if k != "view"})
    return _verdict(first, scene, shot, colours, need, (width, height))


def time_bar(img: np.ndarray) -> tuple[int, int, int] | None:
    """The collapsed time panel's bar in a viewer screenshot: (x0, x1, y) of the longest run of
    dark pixels in the page's bottom 60 rows (None when there is none over a third of the
    width)."""
    h, w = img.shape[:2]
    best = None
    for y in range(max(0, h - 60), h):
        dark = img[y, :, :3].max(axis=-1) < 90
        runs = long_runs(dark[None, :], w // 3)[0]
        if runs.any():
            xs = np.flatnonzero(runs)
            if best is None or xs[-1] - xs[0] > best[1] - best[0]:
                best = (int(xs[0]), int(xs[-1]), y)
    return best


@dataclass
class _Seen:
    """One page's last look: the image, the 3D view's box, each agent's pixel count, the panels
    without data, when the data loaded and when the colours first showed, the console errors."""

    img: np.ndarray
    box: tuple
    counts: dict
    empty: list
    loaded: float | None
    shown: float | None
    elapsed: float
    errors: list


def _watch(browser: Browser, page_url: str, file_url: str, shot: Path, *, size, colours,
           view, say, timeout, settle, at, wait, poll, need, must_show: bool) -> _Seen:
    """Open the viewer on ``file_url`` (opened again when it does not load) and poll
    screenshots until the data is loaded, the frames agree and (when ``must_show``) every
    colour shows in the 3D view and every other panel shows data, or it gives up: ``timeout``
    seconds after opening, ``settle`` seconds after the load (or after the first console error
    while loading); then ``at`` and ``wait``; save the last screenshot to ``shot``."""
    from PIL import Image

    loaded: list[float] = []
    errors: list[tuple[float, str]] = []
    t0 = time.monotonic()

    def on_console(msg):
        text = msg.text
        if "has finished" in text and file_url in text and not loaded:
            loaded.append(time.monotonic() - t0)
        elif msg.type == "error" and "ERR_NAME_NOT_RESOLVED" not in text \
                and "Failed to fetch" not in text:    # the page's web fonts: no network
            errors.append((time.monotonic() - t0, text.strip().splitlines()[0][:200]))

    page = browser.open(page_url, size, timeout, on_console, say)

    def look():
        png = take_screenshot(page, timeout)
        img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))
        box = tuple(view) if view is not None else find_3d_view(img)
        counts = {a: colour_pixels(img, c, box) for a, c in colours.items()}
        others = [b for b in panel_boxes(img) if b != box]
        empty = empty_panels(img, others) if must_show else []
        state = f"data loaded after {loaded[0]:.1f} s" if loaded else "loading the data"
        say(f"  {time.monotonic() - t0:5.1f} s: {state}; 3D view {box[2] - box[0]}x"
            f"{box[3] - box[1]} px; " + ", ".join(f"{a} {n} px" for a, n in counts.items())
            + (f"; {len(empty)} of {len(others)} other panels without data" if must_show
               else ""))
        return img, box, counts, empty

    try:
        streak, shown_at, prev, after = 0, None, None, 0
        while True:     # until two polls after the load agree (and show), or it gives up
            page.wait_for_timeout(poll * 1000)   # console events come in meanwhile
            after += bool(loaded)                 # this poll's screenshot is after the load
            img, box, counts, empty = look()
            elapsed = time.monotonic() - t0
            shows = all(n >= need for n in counts.values())
            if shows and must_show and shown_at is None:
                shown_at = elapsed
            ok = not must_show or (shows and not empty)
            steady = prev is not None and all(
                abs(n - prev[a]) <= max(need, 0.15 * max(n, prev[a])) for a, n in counts.items())
            prev = counts
            streak = streak + 1 if ok and steady else 0
            if streak and (after >= 2 or streak >= 4):
                break
            if elapsed >= timeout or (loaded and elapsed - loaded[0] >= settle) \
                    or (errors and not loaded and elapsed - errors[0][0] >= settle):
                break
        if loaded and (at is not None or wait > 0):
            bar = time_bar(img)
            if at is not None and bar is not None:
                x0, x1, y = bar
                click(page, x0 + at * (x1 - x0), y)
                say(f"  time cursor moved to {at:.0%} of the recording")
            elif at is not None:
                say("  no time bar found: the time cursor stays")
            end = time.monotonic() + wait
            while True:     # the frames after the move: at least one, until ``wait`` is over
                page.wait_for_timeout(poll * 1000)
                img, box, counts, empty = look()
                if time.monotonic() >= end:
                    break
    finally:
        page.close()
    Image.fromarray(img).save(shot)
    return _Seen(img, box, counts, empty, loaded[0] if loaded else None, shown_at,
                 time.monotonic() - t0, [text for _, text in errors])


def _verdict(first: _Seen, scene: _Seen | None, shot: Path, colours: dict, need: int,
             size) -> ViewerCheck:
    """The check's result, or :class:`ViewerCheckError` saying what was missing (and what the
    viewer's console reported, when it did)."""
    x0, y0, x1, y1 = first.box
    where = f"the 3D view (x {x0}-{x1}, y {y0}-{y1} of the page)"
    when = (f"after {first.elapsed:.0f} s ("
            + (f"data loaded after {first.loaded:.1f} s" if first.loaded is not None
               else "the viewer never said the data had loaded") + ")")
    console = ("" if not first.errors else
               "; the viewer's console reported: " + " | ".join(first.errors[:3]))
    own = dict(first.counts)
    if scene is not None and scene.loaded is None:
        raise ViewerCheckError(f"the recording without the agents (the baseline) did not load "
                               f"within the timeout; screenshot: {shot}")
    if scene is not None:
        own = {a: max(0, n - scene.counts[a]) for a, n in first.counts.items()}
    lacking = [a for a in colours if own[a] < need]
    if lacking:
        what = ", ".join(
            f"{a} ({_hex(colours[a])}: {first.counts[a]} px"
            + ("" if scene is None else f", {scene.counts[a]} px without the agents") + ")"
            for a in lacking)
        base = "" if scene is None else (
            f"; without the agents: {shot.with_name(shot.stem + '_without_agents.png')}")
        raise ViewerCheckError(
            f"{where} does not show the bodies: too few pixels (need {need} the bodies add) of "
            f"{what}; {when}{console}; screenshot: {shot}{base}")
    if first.empty:
        boxes = ", ".join(f"x {a}-{c}, y {b}-{d}" for a, b, c, d in first.empty)
        raise ViewerCheckError(
            f"{len(first.empty)} panels show no data (nothing but a line such as 'No data "
            f"available', or nothing): {boxes}; {when}{console}; screenshot: {shot}")
    return ViewerCheck(shot, {a: _hex(c) for a, c in colours.items()}, own, dict(first.counts),
                       None if scene is None else dict(scene.counts), first.box, first.loaded,
                       first.shown if first.shown is not None else first.elapsed,
                       None if scene is None else scene.loaded, size, first.errors)
