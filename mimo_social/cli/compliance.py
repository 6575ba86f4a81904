"""``mimo-social compliance``: a ball dropped on the outstretched arm; plot shoulder angle and
torque (the experiment: :mod:`mimo_social.experiments.compliance`)."""

from __future__ import annotations

import argparse

import numpy as np

from ..experiments import compliance

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "compliance", help="drop a ball on the outstretched arm; plot shoulder angle and torque",
        description=compliance.__doc__.split("\n\n")[1])
    parser.add_argument("--out", default="compliance.png",
                        help="the plot (default: compliance.png)")
    parser.add_argument("--hands", choices=("mitten", "five_fingers"), default="mitten",
                        help="body version (default: mitten)")
    parser.add_argument("--seconds", type=float, default=compliance.SECONDS,
                        help=f"simulated seconds (default: {compliance.SECONDS})")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    if not args.seconds > 0.3:
        raise SystemExit(f"mimo-social compliance: --seconds {args.seconds}: must exceed 0.3")
    trials = compliance.run_compliance(hands=args.hands, seconds=args.seconds)
    for tr in trials:
        print(f"{tr.label:34s} controls {np.round(tr.controls, 3)}  impact {tr.impact_time:.3f} s  "
              f"deflection {tr.deflection_deg:.2f} deg")
    print(f"wrote {compliance.plot_compliance(trials, args.out)}")
    return 0
