#!/usr/bin/env python3
"""Open a recording in Rerun's web viewer in headless Chromium, take a screenshot and check that
the 3D view shows the bodies (a developer's check; docs/viewer_check.md).

    python3 scripts/check_viewer.py recordings/demo.rrd --screenshot docs/demo_viewer.png

See :mod:`viewer_check.check` (beside this script) for what is served, started and looked for.
Needs Chromium (``chromium`` on the ``PATH`` or ``$MIMO_SOCIAL_CHROMIUM``), the Python package
``playwright`` (no browser download: the system Chromium is driven) and ``rerun`` (rerun-sdk).
Exit code 0 when the bodies and every panel's data show, 1 when they do not (the message says
which colours were missing or which panels were empty, and where the screenshot is) or a tool is
missing, 2 for a bad argument.
"""

from __future__ import annotations

import argparse
import math
import sys

from mimo_social.cli._args import input_file, output_file
from viewer_check import TIMEOUT, ViewerCheckError, check_viewer

PROG = "scripts/check_viewer.py"


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(t) for t in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not WIDTHxHEIGHT; allowed: e.g. "
                                         f"1920x1080") from None
    if not (640 <= w <= 7680 and 480 <= h <= 4320):
        raise argparse.ArgumentTypeError(f"{text!r} not allowed; allowed: width 640 to 7680, "
                                         f"height 480 to 4320")
    return w, h


def _number(lo: float, hi: float | None, allowed: str):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number; allowed: {allowed}") \
                from None
        if not math.isfinite(value) or value < lo or (hi is not None and value > hi):
            raise argparse.ArgumentTypeError(f"{text} not allowed; allowed: {allowed}")
        return value

    parse.__name__ = "number"
    return parse


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="Serve FILE.rrd over HTTP, start `rerun --web-viewer`, open it in headless "
                    "Chromium (software WebGL), wait for the recording to load, save a "
                    "screenshot and check that the 3D view shows every agent's clothes colour, "
                    "beyond what the same view of the recording without the agents shows (the "
                    "play room's furniture has such hues), and that no other panel is empty "
                    "('No data available'). 1 to 3 minutes with software rendering, more on a "
                    "loaded machine.")
    parser.add_argument("file", metavar="FILE.rrd", type=input_file,
                        help="the recording to open")
    parser.add_argument("--screenshot", metavar="PATH", type=output_file, default=None,
                        help="where the PNG goes (default: next to the recording, "
                             "<name>_viewer.png)")
    parser.add_argument("--timeout", metavar="S", type=_number(1.0, None, "seconds >= 1"),
                        default=TIMEOUT, help="the most seconds for each page to load and show "
                        f"(an overall limit: the check goes on as soon as the page is ready; "
                        f"default {TIMEOUT:.0f})")
    parser.add_argument("--size", metavar="WxH", type=_size, default=(1920, 1080),
                        help="the browser page's size in pixels (default 1920x1080)")
    parser.add_argument("--at", metavar="FRACTION", default=None,
                        type=_number(0.0, 1.0, "a fraction from 0 to 1"),
                        help="move the time cursor to this fraction (0 to 1) of the recording "
                             "before the screenshot (a click on the time bar)")
    parser.add_argument("--wait", metavar="S", type=_number(0.0, None, "seconds >= 0"), default=0.0,
                        help="seconds more to wait after the bodies show, before the screenshot "
                             "(images decoded, playback on; default 0)")
    parser.add_argument("--no-baseline", action="store_true",
                        help="skip the second page (the recording without the agents): count "
                             "every pixel of the clothes' hues, the scene's included (faster)")
    return parser


def main(argv=None) -> int:
    """Run the check with ``argv`` (default: the command line); the exit code. A bad argument
    is argparse's usage error (exit code 2); a failure is one line on stderr."""
    args = build_parser().parse_args(argv)
    try:
        result = check_viewer(args.file, screenshot=args.screenshot, timeout=args.timeout,
                              size=args.size, at=args.at, wait=args.wait,
                              baseline=not args.no_baseline)
    except ViewerCheckError as e:
        print(f"{PROG}: FAILED: {e}", file=sys.stderr)
        return 1
    except ValueError as e:                  # a bad setting (ConfigError)
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:                     # a screenshot that cannot be written, ...
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    print(result.format())
    return 0


if __name__ == "__main__":
    sys.exit(main())
