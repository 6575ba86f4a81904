"""The ``mimo-social`` command: one module per subcommand.

Each subcommand module provides ``add_parser(subparsers)``, which adds its parser and sets the
parser's ``func`` to the function that runs it.
"""

from __future__ import annotations

import argparse

from . import train
from . import bench, bench_vision, calibrate, compliance, demo, figure, replay
from . import docs
from . import bench_recording
from . import baselines
from . import soak

SUBCOMMANDS = (demo, bench, calibrate, compliance, replay, train, bench_vision, figure, docs,
               bench_recording, baselines, soak)


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


