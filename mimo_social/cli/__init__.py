"""The ``mimo-social`` command: one module per subcommand.

Each subcommand module provides ``add_parser(subparsers)``, which adds its parser and sets the
parser's ``func`` to the function that runs it.
"""

from __future__ import annotations

import argparse

from ..bench import suite as bench
from ..experiments import calibration, compliance, demo
from ..train import runner as train
from . import bench_vision, docs, figure, replay

SUBCOMMANDS = (demo, bench, calibration, compliance, replay, train, docs, bench_vision, figure)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="mimo-social",
        description="Several simulated infants (MIMo) in one MuJoCo world.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module in SUBCOMMANDS:
        module.add_parser(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    return int(args.func(args) or 0)


