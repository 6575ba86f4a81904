"""The ``mimo-social`` command: one module per subcommand.

Each subcommand module provides ``add_parser(subparsers)``, which adds its parser and sets the
parser's ``func`` to the function that runs it. ``bench`` is a group: ``mimo-social bench
MEASUREMENT``, one module per measurement (:mod:`.bench`, which also keeps the old names of the
measuring commands for one release).
"""

from __future__ import annotations

import argparse
import errno
import os
import sys

from . import (baselines, bench, calibrate, compliance, demo, docs, fig8, figure, paradigm,
               recipe, replay, train, train_gpu, view)

#: the modules of the top-level commands (the measurements are under ``bench``:
#: :data:`.bench.MEASUREMENTS`)
SUBCOMMANDS = (demo, bench, calibrate, compliance, replay, train, figure, docs, baselines,
               paradigm, recipe, fig8, view, train_gpu)


class UsageError(SystemExit):
    """argparse's exit for a bad argument (code 2) whose text is the message it printed."""

    def __init__(self, message: str):
        super().__init__(2)
        self.message = message

    def __str__(self) -> str:
        return self.message


class Parser(argparse.ArgumentParser):
    """argparse's parser (usage and one error line on stderr, exit code 2); the SystemExit
    raised also carries the message (for callers of :func:`main`)."""

    def error(self, message):
        self.print_usage(sys.stderr)
        text = f"{self.prog}: error: {message}"
        print(text, file=sys.stderr)
        raise UsageError(text)


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="mimo-social",
        description="Several simulated infants (MIMo) in one MuJoCo world.",
        epilog="Errors are one line, 'mimo-social COMMAND: error: ...', with exit code 2 for a "
        "bad argument or setting and 1 for a failure while running (a file that cannot be "
        "written, a full disk, ...); --debug (or MIMO_SOCIAL_DEBUG=1) shows the traceback.")
    parser.add_argument("--debug", action="store_true",
                        help="show the traceback of an error (also: MIMO_SOCIAL_DEBUG=1)")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module in SUBCOMMANDS:
        module.add_parser(sub)
    return parser


def main(argv=None) -> int:
    """Run ``mimo-social ARGS``; its exit code. Errors are one line on stderr (see the epilog)."""
    parser = build_parser()
    argv = bench.old_form(sys.argv[1:] if argv is None else list(argv))   # note on an old name
    args = parser.parse_args(argv)   # a bad argument: argparse's usage error, exit code 2
    try:
        return int(args.func(args) or 0)
    except (Exception, KeyboardInterrupt) as e:
        if args.debug or os.environ.get("MIMO_SOCIAL_DEBUG", "") not in ("", "0"):
            raise
        code, message = _error(e)
        name = " ".join(filter(None, (args.command, getattr(args, "measurement", None),
                                      getattr(args, "parameter", None))))
        print(f"mimo-social {name}: error: {message}", file=sys.stderr)
        return code


def _error(e: BaseException) -> tuple[int, str]:
    """(exit code, one-line message): 2 for a bad value (ValueError: ConfigError and the
    training's input errors), 1 for a failure while running."""
    if isinstance(e, KeyboardInterrupt):
        return 130, "interrupted"
    if isinstance(e, OSError):
        where = " -> ".join(str(f) for f in (e.filename, e.filename2) if f is not None)
        why = e.strerror or str(e)
        if e.errno == errno.ENOSPC:
            why += " (the disk is full)"
        return 1, f"{where}: {why}" if where else why
    text = " ".join(str(e).split()) or type(e).__name__
    if isinstance(e, ValueError):
        return 2, text
    if isinstance(e, RuntimeError):
        return 1, text
    return 1, (f"{type(e).__name__}: {text} (an internal error: rerun with --debug for the "
               "traceback and report it)")


