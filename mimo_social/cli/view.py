"""``mimo-social view TASK``: watch a catalogue env live in MuJoCo's viewer, every agent under
one control (the loop: :mod:`mimo_social.experiments.viewer`).

Without a display (or where the viewer does not open) it prints one line saying why and what to
do instead, and exits with code 2."""

from __future__ import annotations

import argparse
import math
import sys

from ..body.tables import AGE_RANGE
from ..envs.catalog import names
from ..experiments import viewer
from ._args import Bad, positive_int, seed

__all__ = ["add_parser", "run", "age"]


def age(text: str) -> float:
    """An infant's age in months, within the growth tables' range."""
    lo, hi = AGE_RANGE
    allowed = f"months from {lo:g} to {hi:g}"
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise Bad(f"{text!r} is not a number; allowed: {allowed}") from None
    if not math.isfinite(value) or not lo <= value <= hi:
        raise Bad(f"{text} not allowed; allowed: {allowed}")
    return value


age.__name__ = "age"


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "view", help="watch a task live in MuJoCo's viewer (needs a display)",
        description="Open a catalogue env in MuJoCo's native viewer, every agent under one "
                    "control, stepping in real time and resetting at the end of each episode. "
                    "Needs a display; without one it says so and exits with code 2 (record "
                    "with 'mimo-social demo' instead).")
    parser.add_argument("task", choices=names(), help="the task (the catalogue's names)")
    parser.add_argument("--control", choices=viewer.CONTROLS, default="scripted",
                        help="scripted: the task's scripted controller (a social task's "
                             "partner scripted too; zero actions where the task has none); "
                             "zero: resting actions; random: sampled actions (default: "
                             "scripted)")
    parser.add_argument("--age", type=age, default=None, metavar="MONTHS",
                        help="age of every infant agent in months (default: the task's, the "
                             "18-month-old)")
    parser.add_argument("--seed", type=seed, default=0,
                        help="seed of the first episode (episode k: seed + k; default: 0)")
    parser.add_argument("--steps", type=positive_int, default=None,
                        help="stop after this many control steps (default: until the window "
                             "is closed)")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    problem = viewer.display_problem()
    if problem is not None:
        print(f"mimo-social view: error: {problem}; {viewer.INSTEAD}", file=sys.stderr)
        return 2
    setup = viewer.view_env(args.task, args.control, args.age)
    for note in setup.notes:
        print(f"note: {note}")
    try:
        handle = viewer.open_viewer(setup.env.unwrapped.world.model,
                                    setup.env.unwrapped.world.data)
    except viewer.ViewerUnavailable as e:
        setup.env.close()
        print(f"mimo-social view: error: {e}", file=sys.stderr)
        return 2
    viewer.frame_agents(handle, setup.env)
    print(f"viewing {args.task} ({args.control}, agents {', '.join(setup.env.possible_agents)}"
          f", seed {args.seed}); close the window to stop")
    try:
        out = viewer.run_viewer(setup, handle, seed=args.seed, steps=args.steps)
    finally:
        handle.close()
        setup.env.close()
    print(f"{out.steps} steps, {out.episodes} episode(s)")
    return 0
