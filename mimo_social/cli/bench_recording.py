"""``mimo-social bench-recording``: what recording with the Rerun recorder costs (share of the env
step time) and how big the file grows (MB per simulated minute), for the configurations of
:data:`mimo_social.bench.recording_cost.BENCH_CONFIGS`."""

from __future__ import annotations

import argparse

from ..bench import recording_cost
from ._args import comma_choices, output_dir, positive_float

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "bench-recording", help="recording benchmark: cost per env step and MB per sim. minute",
        description="Cost (share of the env step time) and size (MB per simulated minute) of "
                    "recording with the Recorder, for 2 infants without images, with touch and "
                    "with 2 x 64x64 eyes each.")
    parser.add_argument("--sim-seconds", type=positive_float, default=60.0,
                        help="simulated seconds per configuration (default: 60)")
    indices = [str(i) for i in range(len(recording_cost.BENCH_CONFIGS))]
    parser.add_argument("--only", default=None, type=comma_choices(indices, "index"),
                        help="comma-separated indices of the configurations to run "
                             f"({', '.join(indices)})")
    parser.add_argument("--folder", default=None, type=output_dir,
                        help="where to keep the .rrd files")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    configs = dict(recording_cost.BENCH_CONFIGS)
    if args.only:
        keep = {int(x) for x in args.only}
        configs = {k: v for i, (k, v) in enumerate(configs.items()) if i in keep}
    results = recording_cost.bench_recording(configs, args.sim_seconds, folder=args.folder)
    print(recording_cost.format_table(results))
    return 0
