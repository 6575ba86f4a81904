"""``mimo-social bench-recording``: what recording with the Rerun recorder costs (share of the env
step time) and how big the file grows (MB per simulated minute), for the configurations of
:data:`mimo_social.bench.recording_cost.BENCH_CONFIGS`."""

from __future__ import annotations

import argparse

from ..bench import recording_cost

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "bench-recording", help="recording benchmark: cost per env step and MB per sim. minute",
        description="Cost (share of the env step time) and size (MB per simulated minute) of "
                    "recording with the Recorder, for 2 infants without images, with touch and "
                    "with 2 x 64x64 eyes each.")
    parser.add_argument("--sim-seconds", type=float, default=60.0)
    parser.add_argument("--only", default=None,
                        help="comma-separated indices of the configurations to run (0, 1, 2)")
    parser.add_argument("--folder", default=None, help="where to keep the .rrd files")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    configs = dict(recording_cost.BENCH_CONFIGS)
    if args.only:
        try:
            keep = {int(x) for x in args.only.split(",")}
        except ValueError:
            raise SystemExit(f"mimo-social bench-recording: --only {args.only!r}: "
                             "comma-separated integers, e.g. 0,2") from None
        configs = {k: v for i, (k, v) in enumerate(configs.items()) if i in keep}
    results = recording_cost.bench_recording(configs, args.sim_seconds, folder=args.folder)
    print(recording_cost.format_table(results))
    return 0
