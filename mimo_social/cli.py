"""The ``mimo-social`` command: ``demo``, ``bench`` (more subcommands arrive with later milestones).

Each subcommand lives in its own module, which provides ``add_parser(subparsers)`` and sets the
parser's ``func`` to the function that runs it.
"""

from __future__ import annotations

import argparse
import sys

SUBCOMMAND_MODULES = ("demo", "bench", "calibration", "compliance", "replay_cli", "train")


def build_parser() -> argparse.ArgumentParser:
    import importlib

    parser = argparse.ArgumentParser(
        prog="mimo-social",
        description="Several simulated infants (MIMo) in one MuJoCo world.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in SUBCOMMAND_MODULES:
        importlib.import_module(f"mimo_social.{name}").add_parser(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    return int(args.func(args) or 0)


if __name__ == "__main__":
    sys.exit(main())
