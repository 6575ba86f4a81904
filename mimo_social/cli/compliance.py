"""``mimo-social compliance``: a ball dropped on the outstretched arm; plot shoulder angle and
torque (the experiment: :mod:`mimo_social.experiments.compliance`)."""

from __future__ import annotations

import argparse

import numpy as np

from ..experiments import compliance
from ._args import draw_to, float_above, output_file

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "compliance", help="drop a ball on the outstretched arm; plot shoulder angle and torque",
        description=compliance.__doc__.split("\n\n")[1])
    parser.add_argument("--out", default="compliance.png", type=output_file,
                        help="the plot (default: compliance.png)")
    parser.add_argument("--hands", choices=("mitten", "five_fingers"), default="mitten",
                        help="body version (default: mitten)")
    parser.add_argument("--seconds", type=float_above(0.3), default=compliance.SECONDS,
                        help=f"simulated seconds, more than 0.3 (default: {compliance.SECONDS})")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    trials = compliance.run_compliance(hands=args.hands, seconds=args.seconds)
    for tr in trials:
        print(f"{tr.label:34s} controls {np.round(tr.controls, 3)}  impact {tr.impact_time:.3f} s  "
              f"deflection {tr.deflection_deg:.2f} deg")
    print(f"wrote {draw_to(args.out, lambda path: compliance.plot_compliance(trials, path))}")
    return 0
