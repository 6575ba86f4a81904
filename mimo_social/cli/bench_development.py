"""``mimo-social bench development``: build time per age and for the adult, and the cost per step
of sensorimotor delays and of the acuity filter (:mod:`mimo_social.bench.development`).

    mimo-social bench development                      # the figures of BENCHMARKS.md
    mimo-social bench development --sim-seconds 1 --repeats 1 --json out.json
    mimo-social bench development --hearing            # audition's cost (docs/senses.md)

Below ``--sim-seconds`` 15 (:func:`mimo_social.bench.development.min_sim_seconds`) a comparison
has fewer than 10 turns of 100 steps to go on: a warning says so before the run and those
comparisons are left out of the table (the ms per step are still shown).
"""

from __future__ import annotations

import argparse
import json
import sys

from ..bench import development
from ._args import output_file, positive_float, positive_int, write_file

__all__ = ["NAME", "HELP", "add_parser", "run"]

#: its name under ``mimo-social bench`` and its line in the list of measurements
NAME = "development"
HELP = "cost of developing bodies: build time per age, delays, acuity"


def add_parser(subparsers, name: str = NAME, **kw) -> argparse.ArgumentParser:
    """Add the parser as ``name`` (``kw``: more of argparse's ``add_parser`` settings, e.g.
    ``help``; none: not listed)."""
    parser = subparsers.add_parser(
        name, **kw,
        description="Build time per age and for the adult; ms per step with and without "
                    "sensorimotor delays and the acuity filter, measured in turns of 100 steps.")
    parser.add_argument("--sim-seconds", type=positive_float, default=15.0,
                        help="simulated seconds per delay configuration, two thirds of it per "
                             "acuity one, in turns of 100 steps (default 15, the least that "
                             "gives every comparison 10 turns)")
    parser.add_argument("--repeats", type=positive_int, default=3,
                        help="builds per body; the median is shown (default 3)")
    parser.add_argument("--json", default=None, type=output_file, help="write all results here")
    parser.add_argument("--hearing", action="store_true",
                        help="only the cost of hearing: two infants with voices, no vision, "
                             "audition off vs on, in turns of 100 steps; then the update's "
                             "two ways (Python floats, numpy arrays) at 2-8 agents")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    if getattr(args, "hearing", False):
        results = development.hearing_cost(args.sim_seconds)
        print(development.format_hearing(results))
        results["paths"] = development.hearing_paths()
        print("\n" + development.format_hearing_paths(results["paths"]))
        if args.json:
            write_file(args.json, json.dumps(results, indent=1))
        return 0
    least = development.min_sim_seconds()
    if args.sim_seconds < least:
        turns = development.turns_of(args.sim_seconds * development.ACUITY_SHARE)
        print(f"mimo-social bench {NAME}: warning: --sim-seconds {args.sim_seconds:g}: too short "
              f"to compare timings ({turns} turn(s) of 100 steps for the acuity ones; a "
              f"comparison needs {development.MIN_TURNS}, the noise of one turn being tens of "
              f"percent); the comparisons are left out; give --sim-seconds >= {least:g}",
              file=sys.stderr)
    results = development.measure(args.sim_seconds, args.repeats)
    print(development.format_results(results))
    if args.json:
        write_file(args.json, json.dumps(results, indent=1))
    return 0
