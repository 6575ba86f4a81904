"""``mimo-social demo``: record a short free-play demo to a Rerun ``.rrd`` file (the run:
:mod:`mimo_social.experiments.demo`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..experiments import demo

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "demo", help="record a short free-play demo to a Rerun .rrd file",
        description="Infants face to face in free play with smooth random movements and "
                    "changing facial expressions, recorded to a Rerun .rrd file.")
    parser.add_argument("--record", metavar="FILE.rrd", default=demo.DEFAULT_RECORDING,
                        help=f"where to write the recording (default: {demo.DEFAULT_RECORDING}; "
                             "the folder is created)")
    parser.add_argument("--seconds", type=float, default=10.0,
                        help="simulated seconds to run (default: 10)")
    parser.add_argument("--n-agents", type=int, default=2, help="number of infants (default: 2)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default: 0)")
    parser.set_defaults(func=run)
    return parser


def _open_hint(path: Path) -> str:
    return f"  rerun {path}\n  mimo-social replay {path}"


def run(args: argparse.Namespace) -> int:
    if not args.seconds > 0:
        raise SystemExit(f"mimo-social demo: --seconds {args.seconds}: must be positive")
    if not 1 <= args.n_agents <= 8:
        raise SystemExit(f"mimo-social demo: --n-agents {args.n_agents}: allowed 1 to 8")
    out = demo.record_demo(args.record, args.seconds, args.n_agents, args.seed)
    size = out.path.stat().st_size
    print(f"Recorded {out.seconds:.2f} s of simulated time ({out.steps} steps, {out.n_agents} "
          f"infant{'s' if out.n_agents != 1 else ''}) to {out.path} ({size / 1e6:.1f} MB).")
    if out.stopped:
        print(f"The episode ended early: {out.stopped}")
    print("Open it with:\n" + _open_hint(out.path))
    return 0
