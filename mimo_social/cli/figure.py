"""``mimo-social figure NAME OUT.png``: draw one of the package's figures for people
(:data:`mimo_social.figures.FIGURES`, e.g. ``skin-hand-ball``: a hand holding a ball, its skin
coloured by force)."""

from __future__ import annotations

import argparse

from .. import figures
from ._args import draw_to, output_file

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "figure", help="draw a figure (e.g. skin-hand-ball) as a PNG",
        description="Draw one of the package's figures as a PNG: "
                    + "; ".join(f"{k}: {what}" for k, (_, what) in figures.FIGURES.items()))
    parser.add_argument("name", choices=sorted(figures.FIGURES), help="which figure")
    parser.add_argument("out", metavar="OUT.png", type=output_file, help="where to write it")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    draw, _ = figures.FIGURES[args.name]
    print(draw_to(args.out, draw))
    return 0
