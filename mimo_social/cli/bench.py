"""``mimo-social bench MEASUREMENT``: the measuring commands, one module each.

    mimo-social bench sim          real s per simulated s by component     (cli/bench_sim.py)
    mimo-social bench floor        the env step against bare mj_step       (cli/bench_floor.py)
    mimo-social bench vision       eye images per OpenGL backend           (cli/bench_vision.py)
    mimo-social bench recording    the Rerun recording's cost and size     (cli/bench_recording.py)
    mimo-social bench development  build time per age, delays, acuity      (cli/bench_development.py)
    mimo-social bench engines      SB3 vs RLlib training throughput        (cli/bench_engines.py)
    mimo-social bench training     PPO's steps/s against the env alone     (cli/bench_training.py)
    mimo-social bench soak         growth of memory, threads, open files   (cli/bench_soak.py)
    mimo-social bench ages         age change at reset vs fresh build      (cli/bench_ages.py)
    mimo-social bench gpu          MuJoCo Warp worlds: agent-steps/s       (cli/bench_gpu.py)

Each module has ``NAME``, ``HELP``, ``add_parser(subparsers, name, **kw)`` and ``run(args)``.

**Old names, for one release**: the top-level commands ``bench-vision``, ``bench-recording``,
``bench-development``, ``bench-engines`` and ``soak`` (:data:`OLD_NAMES`), and ``mimo-social
bench --option ...`` without a measurement (the simulation benchmark's old form), still run as
before; :func:`old_form` prints one line on stderr naming the new command. They go in the next
release.
"""

from __future__ import annotations

import argparse
import functools
import sys

from . import bench_ages, bench_development, bench_engines, bench_floor, bench_recording
from . import bench_gpu, bench_sim, bench_soak, bench_training, bench_vision

__all__ = ["MEASUREMENTS", "OLD_NAMES", "add_parser", "old_form"]

#: measurement -> its module, in the order of the help
MEASUREMENTS = {module.NAME: module for module in (bench_sim, bench_floor, bench_vision,
                                                   bench_recording, bench_development,
                                                   bench_engines, bench_training,
                                                   bench_soak, bench_ages, bench_gpu)}
#: old top-level command -> its measurement (kept for one release, not listed in the help)
OLD_NAMES = {"bench-vision": "vision", "bench-recording": "recording",
             "bench-development": "development", "bench-engines": "engines", "soak": "soak"}


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Add ``bench`` with a parser per measurement, and the old names (unlisted)."""
    parser = subparsers.add_parser(
        "bench", help="measure: " + ", ".join(MEASUREMENTS) + " (mimo-social bench MEASUREMENT)",
        description="Measure the package's speed and costs. Each measurement is its own command "
                    "with its own options: mimo-social bench MEASUREMENT --help.",
        epilog="The old names bench-vision, bench-recording, bench-development, bench-engines "
               "and soak, and 'mimo-social bench --option ...' for 'bench sim', still run in "
               "this release, with a one-line note; they go in the next release.")
    sub = parser.add_subparsers(dest="measurement", metavar="MEASUREMENT", title="measurements")
    for name, module in MEASUREMENTS.items():
        module.add_parser(sub, name, help=module.HELP)
    parser.set_defaults(func=functools.partial(_missing, parser))
    for old, new in OLD_NAMES.items():
        MEASUREMENTS[new].add_parser(
            subparsers, old, epilog=f"The old name of 'mimo-social bench {new}': it goes in "
                                    "the next release.")
    return parser


def _missing(parser: argparse.ArgumentParser, args: argparse.Namespace) -> int:
    """``mimo-social bench`` alone: a usage error that lists the measurements."""
    parser.error("give a measurement: " + ", ".join(MEASUREMENTS)
                 + "; e.g. mimo-social bench sim (see mimo-social bench --help)")


def old_form(argv: list[str]) -> list[str]:
    """``argv`` (the arguments after ``mimo-social``) as the parser reads them, with a one-line
    note on stderr when it uses an old name: an old command runs as before (its parser is
    kept); ``bench`` followed by an option is ``bench sim``."""
    at = next((i for i, a in enumerate(argv) if not a.startswith("-")), None)
    if at is None:
        return argv
    word, rest = argv[at], argv[at + 1:]
    if word in OLD_NAMES:
        _note(f"'{word}' is now 'bench {OLD_NAMES[word]}'; the old name goes in the next release")
    elif word == "bench" and rest and rest[0].startswith("-") and rest[0] not in ("-h", "--help"):
        _note("'bench' without a measurement is now 'bench sim'; the old form goes in the next "
              "release")
        return [*argv[:at + 1], bench_sim.NAME, *rest]
    return argv


def _note(text: str) -> None:
    print(f"mimo-social: {text}", file=sys.stderr)
