"""``mimo-social demo``: record a short free-play demo to a Rerun ``.rrd`` file (the run:
:mod:`mimo_social.experiments.demo`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..experiments import demo
from ._args import int_range, output_file, positive_float, seed

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "demo", help="record a short free-play demo to a Rerun .rrd file",
        description="Infants face to face in free play with smooth random movements and "
                    "changing facial expressions, recorded to a Rerun .rrd file.")
    parser.add_argument("--record", metavar="FILE.rrd", type=output_file,
                        default=demo.DEFAULT_RECORDING,
                        help=f"where to write the recording (default: {demo.DEFAULT_RECORDING}; "
                             "the folder is created)")
    parser.add_argument("--seconds", type=positive_float, default=10.0,
                        help="simulated seconds to run (default: 10)")
    parser.add_argument("--n-agents", type=int_range(1, 8), default=2,
                        help="number of infants, 1 to 8 (default: 2)")
    parser.add_argument("--seed", type=seed, default=0, help="random seed (default: 0)")
    parser.set_defaults(func=run)
    return parser


def _open_hint(path: Path) -> str:
    return f"  rerun {path}\n  mimo-social replay {path}"


def run(args: argparse.Namespace) -> int:
    out = demo.record_demo(args.record, args.seconds, args.n_agents, args.seed)
    size = out.path.stat().st_size
    print(f"Recorded {out.seconds:.2f} s of simulated time ({out.steps} steps, {out.n_agents} "
          f"infant{'s' if out.n_agents != 1 else ''}) to {out.path} ({size / 1e6:.1f} MB).")
    if out.stopped:
        print(f"The episode ended early: {out.stopped}")
    print("Open it with:\n" + _open_hint(out.path))
    return 0
