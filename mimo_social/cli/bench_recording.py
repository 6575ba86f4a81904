"""``mimo-social bench recording``: what recording with the Rerun recorder costs (share of the env
step time) and how big the file grows (MB per simulated minute), for the configurations of
:data:`mimo_social.bench.recording_cost.BENCH_CONFIGS`; ``--eyes``: the plain step, recording
without eyes and with eyes side by side in one run
(:func:`mimo_social.bench.recording_cost.bench_eye_cost`)."""

from __future__ import annotations

import argparse
import sys

from ..bench import recording_cost
from ._args import comma_choices, output_dir, positive_float

__all__ = ["NAME", "HELP", "add_parser", "run"]

#: its name under ``mimo-social bench`` and its line in the list of measurements
NAME = "recording"
HELP = "what recording costs: share of the env step and MB per simulated minute"


def add_parser(subparsers, name: str = NAME, **kw) -> argparse.ArgumentParser:
    """Add the parser as ``name`` (``kw``: more of argparse's ``add_parser`` settings, e.g.
    ``help``; none: not listed)."""
    parser = subparsers.add_parser(
        name, **kw,
        description="Cost (share of the env step time) and size (MB per simulated minute) of "
                    "recording with the Recorder, for 2 infants without images, with touch and "
                    "with 2 x 64x64 eyes each. --eyes: the plain step beside recording without and "
                    "with eyes (2 infants, 64x64 eyes, touch on), in turns in one run: eye images "
                    "are logged at 25 Hz by default (every 4th step; a replay is watched at about "
                    "video rate) and encoded on a worker thread; Recorder(eye_every_k_steps=1) "
                    "logs every frame (the last row).")
    parser.add_argument("--sim-seconds", type=positive_float, default=None,
                        help="simulated seconds per configuration (default: 60; --eyes: 40; "
                             "under 30, --eyes 20, the costs and sizes are left out)")
    indices = [str(i) for i in range(len(recording_cost.BENCH_CONFIGS))]
    parser.add_argument("--only", default=None, type=comma_choices(indices, "index"),
                        help="comma-separated indices of the configurations to run "
                             f"({', '.join(indices)})")
    parser.add_argument("--eyes", action="store_true",
                        help="run the eye-cost comparison instead (default 40 simulated s per "
                             "run, in blocks of one 4 s flush interval)")
    parser.add_argument("--folder", default=None, type=output_dir,
                        help="where to keep the .rrd files")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    if args.eyes and args.only:
        print(f"mimo-social bench {NAME}: error: --only picks configurations of the size and "
              "cost table; --eyes runs its own comparison; allowed: one of them", file=sys.stderr)
        return 2
    least = recording_cost.MIN_EYE_SIM_SECONDS if args.eyes else recording_cost.MIN_SIM_SECONDS
    if args.sim_seconds is not None and args.sim_seconds < least:
        print(f"mimo-social bench {NAME}: warning: --sim-seconds {args.sim_seconds:g}: too short "
              f"for a {'median cost over rounds' if args.eyes else 'cost or a size per minute'}"
              f" (they are left out); give --sim-seconds >= {least:g}", file=sys.stderr)
    if args.eyes:
        results = recording_cost.bench_eye_cost(args.sim_seconds or 40.0, folder=args.folder)
        print(recording_cost.format_eye_table(results))
        return 0
    configs = dict(recording_cost.BENCH_CONFIGS)
    if args.only:
        keep = {int(x) for x in args.only}
        configs = {k: v for i, (k, v) in enumerate(configs.items()) if i in keep}
    results = recording_cost.bench_recording(configs, args.sim_seconds or 60.0,
                                             folder=args.folder)
    print(recording_cost.format_table(results))
    return 0
