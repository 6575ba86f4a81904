"""A real-browser check of a recording: Rerun's web viewer in headless Chromium shows the bodies.

:func:`check_viewer` serves the ``.rrd`` over HTTP (with an ``Access-Control-Allow-Origin``
header: the viewer's page comes from another port), starts ``rerun --web-viewer`` on a free port
(no browser opened; the process group is ended at the end, also on errors), opens the viewer
with the file's URL in headless Chromium (driven by Playwright; software WebGL through
SwiftShader), and polls screenshots until the 3D view shows every agent's clothes colour (read
from the recording's own body shapes). It then saves the screenshot and returns a
:class:`ViewerCheck`; when the colours do not show up it raises :class:`ViewerCheckError`
naming what is missing and where the screenshot is.

The 3D view is found in the screenshot itself: the viewer separates its panels with one-pixel
lines of one grey; the largest region they enclose is the 3D view in the layout of
:mod:`mimo_social.recording.blueprint` (``view=`` gives another region). A pixel counts for a
colour when its hue is within :data:`HUE_TOLERANCE` degrees of the colour's and it is saturated
and bright enough (lighting scales the colour but keeps its hue), so background, floor, skin and
the grey grid do not count.
"""

from __future__ import annotations

import colorsys
import functools
import importlib.util
import http.server
import io
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.parse
import urllib.request
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..util.checks import ConfigError, check_int, check_number

__all__ = ["HUE_TOLERANCE", "MIN_PIXELS", "ViewerCheck", "ViewerCheckError", "browser_missing",
           "check_viewer", "chromium_path", "colour_pixels", "find_3d_view", "time_bar",
           "recording_colours"]

#: degrees of hue a lit pixel may be off its clothes colour
HUE_TOLERANCE = 14.0
#: the fewest pixels of each agent's colour the 3D view must show (at 1920x1080)
MIN_PIXELS = 150
#: the colour of the viewer's one-pixel panel separators (light theme)
SEPARATOR_RGB = (223, 223, 223)
_CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


class ViewerCheckError(RuntimeError):
    """The viewer did not show what it should (or could not be started)."""


@dataclass(frozen=True)
class ViewerCheck:
    """What :func:`check_viewer` saw: the screenshot, each agent's colour (``#rrggbb``) and its
    pixel count in the 3D view, the 3D view's box (x0, y0, x1, y1 in page pixels), the seconds
    from opening the page to the data loaded (None when the viewer did not say) and to the
    bodies shown, and the page size."""

    screenshot: Path
    colours: dict[str, str]
    pixels: dict[str, int]
    view: tuple[int, int, int, int]
    load_s: float | None
    shown_s: float
    size: tuple[int, int]
    console_errors: list[str] = field(default_factory=list)

    def format(self) -> str:
        found = ", ".join(f"{a} {self.colours[a]} {n} px" for a, n in self.pixels.items())
        load = "?" if self.load_s is None else f"{self.load_s:.1f} s"
        x0, y0, x1, y1 = self.view
        return (f"viewer check passed: the 3D view ({x1 - x0}x{y1 - y0} px at {x0},{y0}) shows "
                f"{found}\ndata loaded after {load}, bodies shown after {self.shown_s:.1f} s "
                f"(page {self.size[0]}x{self.size[1]})\nscreenshot: {self.screenshot}")


# ----------------------------------------------------------------------------------- colours

def _hex(rgb) -> str:
    return "#" + "".join(f"{int(round(c)):02x}" for c in rgb[:3])


def recording_colours(path: str | Path, min_saturation: float = 0.25) -> dict[str, tuple]:
    """Each agent's clothes colour (RGB, 0-255) as logged in the recording: the most common
    saturated colour of the static shapes under ``/world/<agent>/`` (skin, eyes and grey are
    not saturated). Agents without a saturated colour are left out."""
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
    out = {}
    for agent, counter in counts.items():
        for rgb, _ in counter.most_common():
            _, s, _ = colorsys.rgb_to_hsv(*(c / 255 for c in rgb))
            if s >= min_saturation:
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

def _long_runs(mask: np.ndarray, length: int) -> np.ndarray:
    """The pixels of ``mask`` in horizontal runs of at least ``length`` pixels."""
    padded = np.zeros((mask.shape[0], mask.shape[1] + 2), dtype=np.int8)
    padded[:, 1:-1] = mask
    d = np.diff(padded, axis=1)
    out = np.zeros(mask.shape, dtype=bool)
    for y, x in zip(*np.nonzero(d == 1)):
        end = x + np.argmax(d[y, x:] == -1)
        if end - x >= length:
            out[y, x:end] = True
    return out


def find_3d_view(img: np.ndarray) -> tuple[int, int, int, int]:
    """The box (x0, y0, x1, y1) of the largest panel of the viewer page in ``img``: the regions
    enclosed by the viewer's long one-pixel separator lines (gaps at their junctions closed)."""
    from scipy import ndimage

    sep = np.abs(img[..., :3].astype(np.int16) - np.array(SEPARATOR_RGB)).max(axis=-1) <= 1
    lines = _long_runs(sep, 60) | _long_runs(sep.T, 60).T
    lines = ndimage.binary_dilation(lines, iterations=3)
    labels, n = ndimage.label(~lines)
    if n == 0:
        return (0, 0, img.shape[1], img.shape[0])
    sizes = np.bincount(labels.ravel())[1:]
    k = int(np.argmax(sizes))
    ys, xs = ndimage.find_objects(labels)[k]
    return (int(xs.start), int(ys.start), int(xs.stop), int(ys.stop))


# ------------------------------------------------------------------------------- processes

def chromium_path() -> str | None:
    """The Chromium (or Chrome) executable: ``$MIMO_SOCIAL_CHROMIUM`` or the first on the
    ``PATH``; None when there is none."""
    env = os.environ.get("MIMO_SOCIAL_CHROMIUM")
    if env:
        return env if Path(env).is_file() else None
    return next((p for p in map(shutil.which, _CHROMIUM_NAMES) if p), None)


def browser_missing() -> str | None:
    """Why the check cannot run here (no Chromium, no Playwright, no ``rerun``), else None."""
    if chromium_path() is None:
        return f"no Chromium executable ({' / '.join(_CHROMIUM_NAMES)} on the PATH)"
    if importlib.util.find_spec("playwright") is None:
        return "the Python package playwright is not installed (pip install playwright)"
    if _rerun_command() is None:
        return "the `rerun` executable (pip install rerun-sdk) is not on the PATH"
    return None


def _rerun_command() -> list[str] | None:
    exe = shutil.which("rerun") or str(Path(sys.executable).with_name("rerun"))
    return [exe] if Path(exe).is_file() else None


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class _CorsHandler(http.server.SimpleHTTPRequestHandler):
    """Serves one folder with ``Access-Control-Allow-Origin: *``, quietly."""

    def end_headers(self):
        self.send_header("Access-Control-Allow-Origin", "*")
        super().end_headers()

    def log_message(self, format, *args):  # noqa: A002 - the base class's name
        pass


class _FileServer:
    """The recording's folder over HTTP on a free port, in a thread."""

    def __init__(self, folder: Path):
        handler = functools.partial(_CorsHandler, directory=str(folder))
        self.server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
        self.port = self.server.server_address[1]
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.server.shutdown()
        self.server.server_close()


class _WebViewer:
    """``rerun --web-viewer`` on free ports, in its own process group (ended on exit)."""

    def __init__(self, log_path: Path, start_timeout: float = 30.0):
        self.port, self.grpc_port = _free_port(), _free_port()
        self.log_path, self.start_timeout = log_path, start_timeout
        self.proc: subprocess.Popen | None = None

    def __enter__(self):
        cmd = _rerun_command()
        if cmd is None:
            raise ViewerCheckError("the `rerun` executable (pip install rerun-sdk) is not on "
                                   "the PATH")
        env = dict(os.environ, BROWSER="true")       # the viewer opens no browser itself
        self._log = open(self.log_path, "wb")
        self.proc = subprocess.Popen(
            cmd + ["--web-viewer", "--web-viewer-port", str(self.port), "--port",
                   str(self.grpc_port), "--bind", "127.0.0.1", "--hide-welcome-screen"],
            stdin=subprocess.DEVNULL, stdout=self._log, stderr=subprocess.STDOUT, env=env,
            start_new_session=True)
        try:
            self._wait_up()
        except BaseException:
            self.__exit__()
            raise
        return self

    def _wait_up(self):
        deadline = time.monotonic() + self.start_timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise ViewerCheckError(f"`rerun --web-viewer` exited with code "
                                       f"{self.proc.returncode}: {self._tail()}")
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{self.port}/", timeout=2):
                    return
            except OSError:
                time.sleep(0.3)
        raise ViewerCheckError(f"`rerun --web-viewer` did not answer on port {self.port} "
                               f"within {self.start_timeout:.0f} s: {self._tail()}")

    def _tail(self) -> str:
        try:
            return self.log_path.read_text(errors="replace")[-600:].strip() or "(no output)"
        except OSError:
            return "(no output)"

    def __exit__(self, *exc):
        if self.proc is not None and self.proc.poll() is None:
            for sig, wait in ((signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
                try:
                    os.killpg(self.proc.pid, sig)       # the group started here, no other
                except ProcessLookupError:
                    break
                try:
                    self.proc.wait(wait)
                    break
                except subprocess.TimeoutExpired:
                    continue
        self._log.close()


def _launch_args() -> list[str]:
    args = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
            "--disable-dev-shm-usage", "--no-first-run"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        args.append("--no-sandbox")                  # Chromium refuses its sandbox as root
    return args


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


def check_viewer(path: str | Path, screenshot: str | Path | None = None, timeout: float = 180.0,
                 size="1920x1080", colours: dict | None = None, min_pixels: int = MIN_PIXELS,
                 settle: float = 20.0, view=None, at: float | None = None, wait: float = 0.0,
                 poll: float = 2.0, progress: Callable[[str], None] | None = print
                 ) -> ViewerCheck:
    """Open ``path`` in Rerun's web viewer in headless Chromium and check that its 3D view shows
    the bodies (module docstring). ``screenshot``: where the PNG goes (default: next to the
    recording, ``<name>_viewer.png``); ``timeout``: seconds to wait for the bodies; ``size``:
    the page, ``"WxH"`` or (w, h); ``colours``: agent -> RGB (0-255) to look for (default:
    :func:`recording_colours`); ``min_pixels``: of each colour, scaled with the page's area
    from 1920x1080; ``settle``: seconds to wait once the viewer has said the data is loaded
    before failing; ``view``: the 3D view's box (x0, y0, x1, y1) instead of finding it;
    ``at``: once the bodies show, move the time cursor to this fraction (0 to 1) of the
    recording (a click on the collapsed time panel's bar; playback goes on from there);
    ``wait``: seconds more before the last screenshot (the check is made on that one);
    ``progress``: called with a line per poll (None: quiet). Raises :class:`ViewerCheckError`
    when the bodies do not show (the screenshot is saved first) or a tool is missing."""
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
    with _FileServer(path.resolve().parent) as files, \
            _WebViewer(shot.with_name(shot.stem + "_rerun.log")) as viewer:
        file_url = f"http://127.0.0.1:{files.port}/{urllib.parse.quote(path.name)}"
        page_url = (f"http://127.0.0.1:{viewer.port}/?url="
                    f"{urllib.parse.quote(file_url, safe='')}")
        with _Page(page_url, file_url, (width, height), colours, view, say) as page:
            return _watch(page, shot, need, timeout, settle, at, wait, poll)


def time_bar(img: np.ndarray) -> tuple[int, int, int] | None:
    """The collapsed time panel's bar in a viewer screenshot: (x0, x1, y) of the longest run of
    dark pixels in the page's bottom 60 rows (None when there is none over a third of the
    width)."""
    h, w = img.shape[:2]
    best = None
    for y in range(max(0, h - 60), h):
        dark = img[y, :, :3].max(axis=-1) < 90
        runs = _long_runs(dark[None, :], w // 3)[0]
        if runs.any():
            xs = np.flatnonzero(runs)
            if best is None or xs[-1] - xs[0] > best[1] - best[0]:
                best = (int(xs[0]), int(xs[-1]), y)
    return best


class _Page:
    """Headless Chromium on the viewer's page; :meth:`look` screenshots and counts."""

    def __init__(self, page_url, file_url, size, colours, view, say):
        self.page_url, self.file_url, self.size = page_url, file_url, size
        self.colours, self.view, self.say = colours, view, say
        self.loaded: list[float] = []
        self.errors: list[str] = []

    def __enter__(self):
        from playwright.sync_api import sync_playwright

        self._pw = sync_playwright().start()
        try:
            self.browser = self._pw.chromium.launch(executable_path=chromium_path(),
                                                    headless=True, args=_launch_args())
            self.page = self.browser.new_page(
                viewport={"width": self.size[0], "height": self.size[1]}, color_scheme="light")
            self.page.on("console", self._on_console)
            self.t0 = time.monotonic()
            self.page.goto(self.page_url, wait_until="load", timeout=120_000)
        except BaseException:
            self.__exit__()
            raise
        return self

    def __exit__(self, *exc):
        try:
            if getattr(self, "browser", None) is not None:
                self.browser.close()
        finally:
            self._pw.stop()

    def _on_console(self, msg):
        text = msg.text
        if "has finished" in text and self.file_url in text and not self.loaded:
            self.loaded.append(self.elapsed())
        elif msg.type == "error" and "ERR_NAME_NOT_RESOLVED" not in text \
                and "Failed to fetch" not in text:    # the page's web fonts: no network
            self.errors.append(text.strip().splitlines()[0][:200])

    def elapsed(self) -> float:
        return time.monotonic() - self.t0

    def look(self):
        """A screenshot, the 3D view's box and each agent's pixel count in it."""
        from PIL import Image

        img = np.asarray(Image.open(io.BytesIO(self.page.screenshot())).convert("RGB"))
        box = tuple(self.view) if self.view is not None else find_3d_view(img)
        counts = {a: colour_pixels(img, c, box) for a, c in self.colours.items()}
        state = (f"data loaded after {self.loaded[0]:.1f} s" if self.loaded
                 else "loading the data")
        self.say(f"  {self.elapsed():5.1f} s: {state}; 3D view {box[2] - box[0]}x"
                 f"{box[3] - box[1]} px; " + ", ".join(f"{a} {n} px" for a, n in counts.items()))
        return img, box, counts


def _watch(page: _Page, shot: Path, need: int, timeout, settle, at, wait, poll) -> ViewerCheck:
    from PIL import Image

    streak, first_shown = 0, None
    while True:                                   # until the bodies show, or it gives up
        time.sleep(poll)
        img, box, counts = page.look()
        elapsed = page.elapsed()
        shown = all(n >= need for n in counts.values())
        streak = streak + 1 if shown else 0
        if shown and first_shown is None:
            first_shown = elapsed
        if streak >= 2 and (page.loaded or streak >= 5):     # shown on polls in a row
            break
        if (page.errors and not page.loaded) or elapsed >= timeout \
                or (page.loaded and elapsed - page.loaded[0] >= settle):
            break
    if streak >= 2 and (at is not None or wait > 0):
        bar = time_bar(img)
        if at is not None and bar is not None:
            x0, x1, y = bar
            page.page.mouse.click(x0 + at * (x1 - x0), y)
            page.say(f"  time cursor moved to {at:.0%} of the recording")
        elif at is not None:
            page.say("  no time bar found: the time cursor stays")
        end = time.monotonic() + wait
        while True:
            time.sleep(poll)
            img, box, counts = page.look()
            if time.monotonic() >= end:
                break
        streak = 2 if all(n >= need for n in counts.values()) else 0
    Image.fromarray(img).save(shot)
    loaded = page.loaded[0] if page.loaded else None
    if streak >= 2:
        return ViewerCheck(shot, {a: _hex(c) for a, c in page.colours.items()}, counts, box,
                           loaded, first_shown, page.size, page.errors)
    colours = page.colours
    lacking = [f"{a} ({_hex(colours[a])}: {counts[a]} px)" for a in colours if counts[a] < need]
    if page.errors and not page.loaded:
        why = "the viewer reported errors: " + " | ".join(page.errors[:3])
    else:
        why = (f"after {page.elapsed():.0f} s ("
               + (f"data loaded after {loaded:.1f} s" if loaded is not None
                  else "the viewer never said the data had loaded") + ")")
    x0, y0, x1, y1 = box
    raise ViewerCheckError(
        f"the 3D view (x {x0}-{x1}, y {y0}-{y1} of the page) does not show the bodies: too few "
        f"pixels (need {need}) of " + ", ".join(lacking or ["(none)"])
        + f"; {why}; screenshot: {shot}")
