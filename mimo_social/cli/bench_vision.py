"""``mimo-social bench vision``: what the eyes cost, per OpenGL backend, each in its own process.

Prints milliseconds per eye image for each variant of
:data:`mimo_social.bench.vision_cost.BENCH_VARIANTS` and real seconds per simulated second of
whole env steps with vision; ``--json`` keeps all results.
"""

from __future__ import annotations

import argparse
import json

from ..bench import vision_cost
from ._args import comma_choices, output_file, positive_float, positive_int, write_file

BACKENDS = ["egl", "osmesa", "glfw"]

__all__ = ["NAME", "HELP", "add_parser", "run"]

#: its name under ``mimo-social bench`` and its line in the list of measurements
NAME = "vision"
HELP = "ms per eye image by variant, and env steps with vision, per OpenGL backend"


def add_parser(subparsers, name: str = NAME, **kw) -> argparse.ArgumentParser:
    """Add the parser as ``name`` (``kw``: more of argparse's ``add_parser`` settings, e.g.
    ``help``; none: not listed)."""
    parser = subparsers.add_parser(
        name, **kw,
        description="Vision benchmark: ms per eye image by variant, and real s per simulated s "
                    "of whole env steps; each backend in its own process.")
    parser.add_argument("--backends", default="egl,osmesa",
                        type=comma_choices(BACKENDS, "backend", as_text=True),
                        help="MUJOCO_GL values to compare, comma-separated (default: egl,osmesa)")
    parser.add_argument("--rounds", type=positive_int, default=5)
    parser.add_argument("--sim-seconds", type=positive_float, default=5.0)
    parser.add_argument("--json", default=None, type=output_file, help="write all results here")
    parser.add_argument("--fovea", action="store_true",
                        help="only the cost of foveated eyes: one infant, 64x64 and 128x128 "
                             "eyes, fovea off, strength 2 and 4, taking turns, in this process")
    parser.add_argument("--worker", action="store_true",
                        help="measure in this process only and print one JSON line")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    if args.fovea:
        results = vision_cost.bench_fovea(args.sim_seconds)
        print(vision_cost.format_fovea(results))
        if args.json:
            write_file(args.json, json.dumps(results, indent=1))
        return 0
    if args.worker:
        print("JSON" + json.dumps(vision_cost.measure(args.rounds, args.sim_seconds)))
        return 0
    results = {}
    for backend in args.backends.split(","):
        try:
            results[backend] = vision_cost.measure_backend(backend, args.rounds,
                                                           args.sim_seconds)
        except RuntimeError as e:
            print(e)
    print(vision_cost.format_results(results))
    if args.json:
        write_file(args.json, json.dumps(results, indent=1))
    return 0
