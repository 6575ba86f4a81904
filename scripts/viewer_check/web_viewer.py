"""The processes of the viewer check (:mod:`viewer_check.check`): the
recording's folder over HTTP with a CORS header, ``rerun --web-viewer`` on free ports, headless
Chromium driven by Playwright, and ``rerun rrd filter`` for a copy without the agents."""

from __future__ import annotations

import contextlib
import functools
import http.server
import importlib.util
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path

__all__ = ["Browser", "FileServer", "ViewerCheckError", "WebViewer", "browser_missing",
           "browser_errors", "chromium_path", "click", "launch_args", "rerun_command", "screenshot",
           "without_agents"]

_CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


class ViewerCheckError(RuntimeError):
    """The viewer did not show what it should (or could not be started)."""


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
    if rerun_command() is None:
        return "the `rerun` executable (pip install rerun-sdk) is not on the PATH"
    return None


def rerun_command() -> list[str] | None:
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


class FileServer:
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


class WebViewer:
    """``rerun --web-viewer`` on free ports, in its own process group (ended on exit)."""

    def __init__(self, log_path: Path, start_timeout: float = 30.0):
        self.port, self.grpc_port = _free_port(), _free_port()
        self.log_path, self.start_timeout = log_path, start_timeout
        self.proc: subprocess.Popen | None = None

    def __enter__(self):
        cmd = rerun_command()
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


def launch_args() -> list[str]:
    args = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
            "--disable-dev-shm-usage", "--no-first-run"]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        args.append("--no-sandbox")                  # Chromium refuses its sandbox as root
    return args


def _first_line(error: BaseException) -> str:
    text = str(error).strip()
    return (text.splitlines()[0] if text else type(error).__name__)[:200]


class Browser:
    """Headless Chromium driven by Playwright (software WebGL).

    Every wait on the page is bounded by the check's own limit (:meth:`open` sets it as the
    page's default), never by Playwright's 30 s: with software WebGL on a loaded machine one
    frame of a 1920x1080 page can take longer than that. A page that fails to load is opened
    again (:meth:`open`), a screenshot that fails is taken again (:func:`screenshot`).
    """

    def __enter__(self):
        from playwright.sync_api import sync_playwright

        self._pw = sync_playwright().start()
        exe = chromium_path()
        try:
            self.browser = self._pw.chromium.launch(executable_path=exe, headless=True,
                                                    args=launch_args())
        except Exception as e:
            self._pw.stop()
            first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
            raise ViewerCheckError(f"Chromium ({exe}) could not be started: {first[:200]}") \
                from None
        except BaseException:
            self._pw.stop()
            raise
        return self

    def __exit__(self, *exc):
        try:
            self.browser.close()
        finally:
            self._pw.stop()

    def open(self, url: str, size: tuple[int, int], limit: float, on_console=None,
             say=lambda _line: None, attempts: int = 3):
        """A new page at ``size`` showing ``url``, once its document has loaded and the viewer's
        canvas is on it; each wait of the page (this one, its screenshots, clicks) may take up
        to ``limit`` seconds. A page that does not load (a timeout, a crashed or closed page, a
        refused connection) is closed and opened again, ``attempts`` times in all.
        ``on_console`` gets the page's console messages from the start."""
        from playwright.sync_api import Error

        why = "not tried"
        for attempt in range(1, attempts + 1):
            page = self.browser.new_page(viewport={"width": size[0], "height": size[1]},
                                         color_scheme="light")
            page.set_default_timeout(limit * 1000)
            page.set_default_navigation_timeout(limit * 1000)
            if on_console is not None:
                page.on("console", on_console)
            try:
                page.goto(url, wait_until="load")
                page.wait_for_selector("canvas", state="attached")
                return page
            except Error as e:
                why = _first_line(e)
                _close(page)
                if attempt < attempts:
                    say(f"  the viewer's page did not load ({why}); opening it again "
                        f"({attempt + 1} of {attempts})")
        raise ViewerCheckError(f"the viewer's page did not load in {attempts} attempts of up to "
                               f"{limit:.0f} s each: {why}")


def _close(page) -> None:
    try:
        page.close()
    except Exception:                 # already closed, or the browser went with it
        pass


@contextlib.contextmanager
def browser_errors(what: str):
    """Turns an error of the browser that was not taken again (Playwright's ``Error``) into a
    :class:`ViewerCheckError` naming ``what`` was being done: one line, not a traceback."""
    from playwright.sync_api import Error

    try:
        yield
    except Error as e:
        raise ViewerCheckError(f"the browser failed while {what}: {_first_line(e)}") from None


def click(page, x: float, y: float, attempts: int = 3) -> None:
    """A mouse click on ``page`` at (x, y), taken again when the browser fails it."""
    from playwright.sync_api import Error

    for attempt in range(attempts):
        try:
            page.mouse.click(x, y)
            return
        except Error:
            if attempt == attempts - 1 or page.is_closed():
                raise


def screenshot(page, limit: float, attempts: int = 3) -> bytes:
    """A PNG of ``page``, waiting up to ``limit`` seconds for the frame (the page's compositor
    draws one first; software WebGL under load can take long); a failed one is taken again,
    ``attempts`` times in all, unless the page is gone."""
    from playwright.sync_api import Error

    why = "not tried"
    for _ in range(attempts):
        try:
            return page.screenshot(timeout=limit * 1000)
        except Error as e:
            why = _first_line(e)
            if page.is_closed():
                break
    raise ViewerCheckError(f"no screenshot of the viewer's page in {attempts} attempts of up "
                           f"to {limit:.0f} s each: {why}")


def without_agents(path: str | Path, agents, out: str | Path) -> Path:
    """A copy of the recording at ``out`` without the entities under ``/world/<agent>/`` of
    ``agents`` (their bodies and skin points; ``rerun rrd filter``): the scene alone, in the
    recording's own layout."""
    from rerun.chunk import RrdReader

    prefixes = tuple(f"/world/{a}" for a in agents)
    drop = sorted({c.entity_path for c in RrdReader(Path(path)).stream().to_chunks()
                   if c.entity_path.startswith(prefixes)
                   and c.entity_path[len("/world/"):].split("/")[0] in agents})
    cmd = rerun_command()
    if cmd is None:
        raise ViewerCheckError("the `rerun` executable (pip install rerun-sdk) is not on the PATH")
    args = cmd + ["rrd", "filter", str(path), "-o", str(out)]
    for e in drop:
        args += ["--drop-entity", e]
    done = subprocess.run(args, stdin=subprocess.DEVNULL, capture_output=True, text=True,
                          timeout=300)
    if done.returncode != 0 or not Path(out).is_file():
        raise ViewerCheckError(f"`rerun rrd filter` could not remove the agents from {path}: "
                               f"{done.stderr.strip()[-400:]}")
    return Path(out)
