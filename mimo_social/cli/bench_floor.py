"""``mimo-social bench floor``: the env step against a bare ``mj_step`` loop on the same model and
trajectory, for 1, 2 and 8 infants, without and with touch (:mod:`mimo_social.bench.floor`).

    mimo-social bench floor                          # the figures of BENCHMARKS.md
    mimo-social bench floor --chunks 3 --chunk 50 --json out.json
"""

from __future__ import annotations

import argparse
import json

from ..bench import floor
from ._args import comma_choices, output_file, positive_int, seed, write_file

__all__ = ["NAME", "HELP", "add_parser", "run"]

#: its name under ``mimo-social bench`` and its line in the list of measurements
NAME = "floor"
HELP = "the env step against bare mj_step on the same model and trajectory"


def add_parser(subparsers, name: str = NAME, **kw) -> argparse.ArgumentParser:
    """Add the parser as ``name`` (``kw``: more of argparse's ``add_parser`` settings)."""
    parser = subparsers.add_parser(
        name, **kw,
        description="CPU time per control step of the env (free play, spring-damper motors, "
                    "no eyes) and of a bare mj_step loop replaying the same trajectory on the "
                    "same model, chunk by chunk in turns, for 1, 2 and 8 infants without and "
                    "with touch.")
    counts = sorted({str(c.n_agents) for c in floor.FLOOR_CONFIGS}, key=int)
    parser.add_argument("--agents", type=comma_choices(counts, "agent count"),
                        default=counts, help=f"the agent counts to measure (default "
                                             f"{','.join(counts)}), each without and with touch")
    parser.add_argument("--jacobian", type=comma_choices(("default", "dense", "sparse", "auto"),
                                                         "jacobian"), default=["default"],
                        help="the constraint Jacobians to measure, each configuration with each "
                             "in turn (default: the default physics'; e.g. dense,sparse)")
    parser.add_argument("--chunks", type=positive_int, default=10,
                        help="chunks per configuration; the median is shown (default 10)")
    parser.add_argument("--chunk", type=positive_int, default=100,
                        help="control steps per chunk (default 100)")
    parser.add_argument("--seed", type=seed, default=0, help="seed of the actions (default 0)")
    parser.add_argument("--json", default=None, type=output_file, help="write all results here")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    configs = [floor.FloorConfig(c.n_agents, c.touch, None if j == "default" else j)
               for c in floor.FLOOR_CONFIGS if str(c.n_agents) in args.agents
               for j in args.jacobian]
    results = floor.measure(configs, chunks=args.chunks, chunk=args.chunk, seed=args.seed,
                            progress=True)
    print(floor.format_results(results))
    if args.json:
        write_file(args.json, json.dumps(results, indent=1))
    return 0
