"""``mimo-social bench gpu``: agent-steps per second of two-infant high five on MuJoCo Warp at
1, 64, 1024 and 4096 worlds, on a GPU when Warp sees one, else on Warp's CPU device, which the
output names (:mod:`mimo_social.bench.gpu`; docs/gpu.md). Needs the ``gpu`` extra.

    mimo-social bench gpu                              # 1, 64, 1024, 4096 worlds, 100 steps
    mimo-social bench gpu --worlds 1,64 --steps 20     # what a CPU manages in minutes
    mimo-social bench gpu --with-task                  # the task's logic and resets too
    mimo-social bench gpu --with-task --reset-bank 4096   # resets from 4096 starts kept
    mimo-social bench gpu --eyes 64                    # both eyes of each infant, 64x64
"""

from __future__ import annotations

import argparse
import json
import sys

from ._args import non_negative_int, output_file, positive_int, write_file

__all__ = ["NAME", "HELP", "add_parser", "run"]

#: its name under ``mimo-social bench`` and its line in the list of measurements
NAME = "gpu"
HELP = "MuJoCo Warp: high five agent-steps/s at 1 to 4096 worlds"


def _worlds(text: str) -> list[int]:
    """A comma-separated list of positive integers."""
    out = []
    for part in text.split(","):
        try:
            n = int(part)
        except ValueError:
            n = 0
        if n < 1:
            raise argparse.ArgumentTypeError(
                f"{text!r} not allowed; allowed: positive integers separated by commas, "
                f"e.g. 1,64,1024,4096")
        out.append(n)
    return out


def add_parser(subparsers, name: str = NAME, **kw) -> argparse.ArgumentParser:
    """Add the parser as ``name`` (``kw``: more of argparse's ``add_parser`` settings)."""
    parser = subparsers.add_parser(
        name, **kw,
        description="Agent-steps per second of two-infant high five on MuJoCo Warp, N worlds "
                    "stepped together (random actions, proprioception, vestibular sense and hand "
                    "skins read each step; with "
                    "--with-task the task's rewards, success, terminations and resets too). "
                    "Runs on a GPU when Warp sees one, else on Warp's CPU device, and says "
                    "which.")
    parser.add_argument("--worlds", type=_worlds, default=[1, 64, 1024, 4096],
                        help="numbers of worlds, comma-separated (default 1,64,1024,4096)")
    parser.add_argument("--steps", type=positive_int, default=100,
                        help="timed control steps per number of worlds (default 100)")
    parser.add_argument("--warmup", type=non_negative_int, default=2,
                        help="control steps before the timing (default 2)")
    parser.add_argument("--device", choices=("auto", "cpu", "cuda"), default="auto",
                        help="auto (default): a GPU when Warp sees one, else the CPU")
    parser.add_argument("--with-task", action="store_true",
                        help="time the task's logic and the autoresets of finished worlds "
                             "(BatchedTaskEnv) with the physics")
    parser.add_argument("--reset-bank", type=positive_int, default=None, metavar="K",
                        help="with --with-task: reset finished worlds from K starts made once "
                             "and kept (default: a CPU reset per finished world)")
    parser.add_argument("--eyes", type=positive_int, default=None, metavar="N",
                        help="render both eyes of each infant on the device each step, N x N "
                             "pixels (MuJoCo Warp's batch renderer; default: no eyes)")
    parser.add_argument("--no-touch", dest="touch", action="store_false",
                        help="leave the hand skins out (default: read on the device each step)")
    parser.add_argument("--json", default=None, type=output_file, help="write all results here")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    from ..bench import gpu

    device = None if args.device == "auto" else args.device
    if args.reset_bank is not None and not args.with_task:
        print(f"mimo-social bench {NAME}: --reset-bank {args.reset_bank} needs --with-task (the "
              "resets are the task's)", file=sys.stderr)
        return 2
    try:
        out = gpu.measure(args.worlds, args.steps, args.warmup, device,
                          with_task=args.with_task, touch=args.touch,
                          reset_bank=args.reset_bank, eyes=args.eyes,
                          progress=lambda r: print(f"  {r['worlds']} worlds: "
                                                   f"{r['agent_steps_per_s']:.1f} agent-steps/s",
                                                   flush=True))
    except (ImportError, ValueError) as e:
        print(f"mimo-social bench {NAME}: {e}", file=sys.stderr)
        return 1
    print(gpu.format_results(out))
    if args.json:
        write_file(args.json, json.dumps(out, indent=1))
    return 0
