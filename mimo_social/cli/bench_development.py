"""``mimo-social bench-development``: build time per age and for the adult, and the cost per step
of sensorimotor delays and of the acuity filter (:mod:`mimo_social.bench.development`).

    mimo-social bench-development                      # the figures of BENCHMARKS.md
    mimo-social bench-development --steps 50 --rounds 2 --json out.json
"""

from __future__ import annotations

import argparse
import json

from ..bench import development
from ._args import output_file, positive_int, write_file

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "bench-development", help="cost of developing bodies: build time per age, delays, acuity",
        description="Build time per age and for the adult; ms per step with and without "
                    "sensorimotor delays and the acuity filter, measured in turns.")
    parser.add_argument("--steps", type=positive_int, default=300,
                        help="steps per turn of each compared env (default 300)")
    parser.add_argument("--rounds", type=positive_int, default=5,
                        help="turns per env; each figure is the median (default 5)")
    parser.add_argument("--repeats", type=positive_int, default=3,
                        help="builds per body; the median is shown (default 3)")
    parser.add_argument("--json", default=None, type=output_file, help="write all results here")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    results = development.measure(args.steps, args.rounds, args.repeats)
    print(development.format_results(results))
    if args.json:
        write_file(args.json, json.dumps(results, indent=1))
    return 0
