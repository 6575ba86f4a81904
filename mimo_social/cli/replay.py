"""``mimo-social replay FILE.rrd``: open a recording in the Rerun viewer, or summarise it.

Without ``--summary`` the viewer is started (``rerun FILE``, in its own session, so the command
returns at once) when one can be shown: a display is set (``DISPLAY`` or ``WAYLAND_DISPLAY``) and
the ``rerun`` executable (installed with ``rerun-sdk``) is on the ``PATH``. Otherwise it says how
to open the file elsewhere and exits 0.

``--summary`` prints, with no viewer, what :func:`mimo_social.recording.summary.summarize` reads
from the file: the agents, the simulated duration, the number of steps and of pose rows, the
entity paths grouped by agent and kind, whether eye images and skin points are there, and the
contact events between agents. A file whose last frame was cut off mid-write (a run killed while
Rerun wrote it) is summarised up to its last whole frame, and says so.

``--salvage [OUT]`` writes the whole frames of such a file to ``OUT`` (default
``FILE.salvaged.rrd``), which Rerun's viewer and reader open; without it, the viewer is not
started on a torn file (Rerun's reader refuses it), and the command says what to run.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

from ..recording.summary import format_summary, summarize
from ..recording.torn import salvage, whole_length

__all__ = ["add_parser", "run", "viewer_available"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "replay", help="open a Rerun recording (.rrd) in the viewer, or summarise it",
        description="Open a recording made by mimo-social (e.g. `mimo-social demo`) in the Rerun "
                    "viewer when a display is available, or print what it holds (--summary).")
    parser.add_argument("file", metavar="FILE.rrd", help="the recording to open")
    parser.add_argument("--summary", action="store_true",
                        help="print agents, duration, entities, steps, pose rows, eye images, "
                             "skin points and contact events; no viewer")
    parser.add_argument("--salvage", nargs="?", const="", default=None, metavar="OUT",
                        help="write the whole frames of a recording cut off mid-write (a killed "
                             "run) to OUT (default: FILE.salvaged.rrd)")
    parser.set_defaults(func=run)
    return parser


def viewer_available() -> str | None:
    """The ``rerun`` executable when a viewer can be shown here (a display is set), else None."""
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        return None
    return shutil.which("rerun")


def run(args: argparse.Namespace) -> int:
    path = Path(args.file)
    if not path.is_file():
        print(f"mimo-social replay: error: {path}: no such file", file=sys.stderr)
        return 2
    if args.salvage is not None:
        return _salvage(path, Path(args.salvage) if args.salvage else
                        path.with_name(path.stem + ".salvaged.rrd"))
    if args.summary:
        try:
            summary = summarize(path)
        except Exception as e:  # not a readable .rrd
            print(f"mimo-social replay: error: cannot read {path} as a Rerun recording: {e}",
                  file=sys.stderr)
            return 2
        print(format_summary(summary))
        return 0
    try:
        torn = path.stat().st_size - whole_length(path)
    except ValueError as e:
        print(f"mimo-social replay: error: cannot read {path} as a Rerun recording: {e}",
              file=sys.stderr)
        return 2
    if torn:
        print(f"{path}: its last {torn} bytes are a frame cut off mid-write (the run was killed "
              f"while writing); Rerun does not open it as it is. Write the whole part with:\n"
              f"  mimo-social replay {path} --salvage")
        return 1
    exe = viewer_available()
    if exe is not None:
        proc = subprocess.Popen([exe, str(path)], stdin=subprocess.DEVNULL,
                                start_new_session=True)
        print(f"Opened {path} in the Rerun viewer (process {proc.pid}).")
        return 0
    why = ("no display (DISPLAY / WAYLAND_DISPLAY are not set)"
           if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
           else "the `rerun` executable is not on the PATH")
    print(f"Cannot show a viewer here: {why}.\n"
          f"To watch {path}, on a machine with a display (pip install rerun-sdk~=0.41.0) run:\n"
          f"  rerun {path}\n"
          f"To see what it holds here:\n"
          f"  mimo-social replay {path} --summary")
    return 0


def _salvage(path: Path, out: Path) -> int:
    try:
        dropped = salvage(path, out)
    except (ValueError, OSError) as e:
        print(f"mimo-social replay: error: --salvage: {e}", file=sys.stderr)
        return 2
    what = (f"left out the last {dropped} bytes (a frame cut off mid-write)" if dropped
            else "nothing was torn: a plain copy")
    print(f"Wrote {out} ({out.stat().st_size} bytes; {what}).\n  mimo-social replay {out}")
    return 0
