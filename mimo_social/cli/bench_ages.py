"""``mimo-social bench ages``: an infant's age change at reset (in place, the env's model not
compiled again) against a fresh env build at that age, for the high five and free play with
mitten and five-fingered hands, without and with the whole body's skin
(:mod:`mimo_social.bench.ages`).

    mimo-social bench ages                        # the figures of BENCHMARKS.md
    mimo-social bench ages --repeats 12 --json ages.json
"""

from __future__ import annotations

import argparse
import json

from ..bench import ages
from ._args import comma_choices, output_file, positive_int, write_file

__all__ = ["NAME", "HELP", "add_parser", "run"]

#: its name under ``mimo-social bench`` and its line in the list of measurements
NAME = "ages"
HELP = "an age change at reset against a fresh build at that age"


def add_parser(subparsers, name: str = NAME, **kw) -> argparse.ArgumentParser:
    """Add the parser as ``name`` (``kw``: more of argparse's ``add_parser`` settings)."""
    parser = subparsers.add_parser(
        name, **kw,
        description="CPU and wall milliseconds of an infant's age change at reset (set_age, "
                    "then the reset that writes the new body into the live model) against a "
                    "plain reset and a fresh env build at that age, for the high five (two "
                    "infants) and free play (one) with mitten and five-fingered hands, without "
                    "and with the whole body's skin; median, smallest and largest over the "
                    "repeats.")
    parser.add_argument("--hands", type=comma_choices(("mitten", "five_fingers"), "hands"),
                        default=["mitten", "five_fingers"],
                        help="the hand versions to measure (default mitten,five_fingers)")
    parser.add_argument("--tasks", type=comma_choices(("high_five", "free_play"), "task"),
                        default=["high_five", "free_play"],
                        help="the tasks to measure (default high_five,free_play)")
    parser.add_argument("--repeats", type=positive_int, default=6,
                        help="changes and builds per configuration, cycling through the ages "
                             f"{', '.join(f'{a:g}' for a in ages.AGES)} months (default 6)")
    parser.add_argument("--json", default=None, type=output_file, help="write all results here")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    configs = [c for c in ages.AGE_CONFIGS if c.hands in args.hands and c.task in args.tasks]
    results = ages.measure(configs, repeats=args.repeats, progress=True)
    print(ages.format_results(results))
    if args.json:
        write_file(args.json, json.dumps(results, indent=1))
    return 0
