"""``mimo-social bench soak``: long runs of free play (touch; vision + recording) that sample
resident memory, OS threads and open file descriptors, and report their growth per 100k steps
(the library: :mod:`mimo_social.bench.soak`).

    mimo-social bench soak --out soak              # 1e6 touch steps, 1e5 vision + recording
    mimo-social bench soak --steps 50000 --vision-steps 25000 --out /tmp/soak

A phase shorter than :func:`mimo_social.bench.soak.min_phase_steps` (22,223 steps with the
default warm-up and episodes) runs, but a warning before the run says so and the summary gives
no growth for it ("too short", with the minimum). ``--vision-steps`` defaults to a tenth of
``--steps`` (so ``--steps 10`` is a short run, not 1e5 steps of vision); with ``--steps 0``, 1e5.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..bench import soak as soak_lib
from ._args import non_negative_int, output_dir

__all__ = ["NAME", "HELP", "add_parser", "run"]

#: its name under ``mimo-social bench`` and its line in the list of measurements
NAME = "soak"
HELP = "long free-play runs: growth of memory, threads and open files"


def _count(text: str) -> int:
    """A step count: an integer >= 0, written ``1000000`` or ``1e6``."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give a whole number of steps >= 0, "
                                         "e.g. 100000 or 1e5") from None
    if not value >= 0 or value != int(value) or value > 1e12:
        raise argparse.ArgumentTypeError(f"{text!r}: give a whole number of steps >= 0 "
                                         "(at most 1e12), e.g. 100000 or 1e5")
    return int(value)


def _positive(text: str) -> int:
    value = _count(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: give a whole number >= 1")
    return value


def _eye_size(text: str) -> int:
    value = _count(text)
    if not 8 <= value <= 2048:
        raise argparse.ArgumentTypeError(f"{text!r}: give a whole number of pixels, 8 to 2048")
    return value


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 <= value <= 0.9:
        raise argparse.ArgumentTypeError(f"{text!r}: give a number in [0, 0.9]")
    return value


def add_parser(subparsers, name: str = NAME, **kw) -> argparse.ArgumentParser:
    """Add the parser as ``name`` (``kw``: more of argparse's ``add_parser`` settings, e.g.
    ``help``; none: not listed)."""
    parser = subparsers.add_parser(
        name, **kw,
        description="Run free play with touch (--steps) and then with 2 eyes and every episode "
                    "recorded to its own .rrd file (--vision-steps), with smooth random "
                    "actions; sample resident memory (MB), OS threads and open file "
                    "descriptors every --sample-every steps; write soak.csv, soak.json and "
                    "soak.png to --out and print the growth of each per 100k steps (slope of a "
                    "least-squares line after the warm-up) and the steps per second.")
    parser.add_argument("--steps", type=_count, default=1_000_000, metavar="N",
                        help="steps of free play with touch (default: 1e6; 0 skips it)")
    parser.add_argument("--vision-steps", type=_count, default=None, metavar="N",
                        help="steps of free play with vision + recording (default: a tenth of "
                             "--steps, 1e5 with --steps 0; 0 skips it)")
    parser.add_argument("--out", default="soak", metavar="DIR", type=output_dir,
                        help="folder for soak.csv, soak.json, soak.png (default: ./soak)")
    parser.add_argument("--seed", type=non_negative_int, default=0, help="seed of actions and resets")
    parser.add_argument("--sample-every", type=_positive, default=10_000, metavar="N",
                        help="steps between samples (default: 1e4; at least 20 samples a phase)")
    parser.add_argument("--episode-steps", type=_positive, default=1000, metavar="N",
                        help="steps per episode; the recording rotates to a new file every "
                             "episode (default: 1000)")
    parser.add_argument("--vision-size", type=_eye_size, default=64, metavar="PX",
                        help="eye image edge in pixels, 8 to 2048 (default: 64)")
    parser.add_argument("--warmup", type=_fraction, default=0.1, metavar="F",
                        help="share of each phase's steps left out of the fit (default: 0.1)")
    parser.add_argument("--keep-recordings", default=None, metavar="DIR", type=output_dir,
                        help="keep every recording in DIR (default: a temporary folder, "
                             "each file deleted once closed)")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    parser.set_defaults(func=run)
    return parser


def _command(args) -> str:
    parts = ["mimo-social bench soak", f"--steps {args.steps}",
             f"--vision-steps {args.vision_steps}", f"--out {args.out}", f"--seed {args.seed}"]
    for flag, value, default in (("--sample-every", args.sample_every, 10_000),
                                 ("--episode-steps", args.episode_steps, 1000),
                                 ("--vision-size", args.vision_size, 64),
                                 ("--warmup", args.warmup, 0.1)):
        if value != default:
            parts.append(f"{flag} {value:g}")
    if args.keep_recordings:
        parts.append(f"--keep-recordings {args.keep_recordings}")
    return " ".join(parts)


def _warn_short(args) -> None:
    """One line on stderr per phase too short for a growth figure, before it runs."""
    least = soak_lib.min_phase_steps(args.episode_steps, args.warmup)
    flags = {"touch": "--steps", "vision+recording": "--vision-steps"}
    for phase, n in soak_lib.short_phases(args.steps, args.vision_steps, args.episode_steps,
                                          args.warmup).items():
        print(f"mimo-social bench {NAME}: warning: {flags[phase]} {n}: too short for a growth "
              f"figure of {phase} (its growth is left out); give at least {least} steps (a "
              f"warm-up of {args.warmup:g} of the steps, at least "
              f"{soak_lib.WARMUP_EPISODES} episodes, then {soak_lib.MIN_FIT_STEPS} steps to "
              "fit)", file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    if args.vision_steps is None:        # a tenth of --steps, as the defaults 1e6 and 1e5
        args.vision_steps = args.steps // 10 if args.steps else 100_000
    if args.steps + args.vision_steps == 0:
        print(f"mimo-social bench {NAME}: error: --steps 0 and --vision-steps 0: nothing to run",
              file=sys.stderr)
        return 2
    _warn_short(args)
    try:                                   # a folder that cannot be made: say so before the run
        Path(args.out).mkdir(parents=True, exist_ok=True)
    except OSError as e:                   # (--out was checked; this is a race or a full disk)
        print(f"mimo-social bench {NAME}: error: --out {args.out}: cannot make the folder: "
              f"{e.strerror or e}", file=sys.stderr)
        return 1
    try:
        result = soak_lib.soak(args.steps, args.vision_steps, seed=args.seed,
                               sample_every=args.sample_every, episode_steps=args.episode_steps,
                               vision_size=args.vision_size, warmup=args.warmup,
                               folder=args.keep_recordings,
                               keep_recordings=args.keep_recordings is not None,
                               progress=not args.no_progress)
        paths = soak_lib.write_outputs(result, args.out, _command(args))
    except OSError as e:
        where = f" {e.filename}" if e.filename else ""
        print(f"mimo-social bench {NAME}: error: cannot write the outputs{where}: "
              f"{e.strerror or e}", file=sys.stderr)
        return 1
    print(soak_lib.format_summary(result))
    print("wrote " + ", ".join(str(p) for p in paths.values()))
    return 0
