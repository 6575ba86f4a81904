"""``mimo-social demo``: an 18-month-old and a kneeling caregiver play a high five, then the
caregiver hands the infant a ball, recorded with eyes and skin to a Rerun ``.rrd`` file (the run:
:mod:`mimo_social.experiments.demo`)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from ..experiments import demo
from ..recording.summary import summarize
from ._args import output_file, positive_float, seed

__all__ = ["add_parser", "run", "report"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "demo", help="record the demo (an infant and a caregiver: a high five, then a handover) "
                     "to a Rerun .rrd file",
        description="An 18-month-old infant and a kneeling adult caregiver, both scripted: a "
                    "high five, then the caregiver hands the infant a ball; faces change with "
                    "what happens. Recorded with both agents' eyes (64x64), skin and contacts "
                    "to one Rerun .rrd file.")
    parser.add_argument("--record", metavar="FILE.rrd", type=output_file,
                        default=demo.DEFAULT_RECORDING,
                        help=f"where to write the recording (default: {demo.DEFAULT_RECORDING}; "
                             "the folder is created)")
    parser.add_argument("--seconds", type=positive_float, default=demo.DEFAULT_SECONDS,
                        help="simulated seconds to record (default: "
                             f"{demo.DEFAULT_SECONDS:g}; the interaction takes about 5; "
                             "fewer cut it short, more let the infant hold the ball longer)")
    parser.add_argument("--seed", type=seed, default=0,
                        help="random seed of the start postures and the scripts (default: 0)")
    parser.add_argument("--scene", choices=demo.SCENES, default=demo.DEFAULT_SCENE,
                        help=f"where it happens (default: {demo.DEFAULT_SCENE})")
    parser.set_defaults(func=run)
    return parser


def _at(t: float | None) -> str:
    return "--" if t is None else f"{t:5.2f} s"


def report(out: demo.DemoRun, wall_s: float, summary: dict | None = None) -> str:
    """What happened in the demo, for people: when the high five and the handover succeeded,
    the faces, the contacts, the file and how to open it."""
    infant, caregiver = out.agents
    size = out.path.stat().st_size
    lines = [f"Recorded {out.seconds:.2f} s of simulated time ({out.steps} steps, scene "
             f"{out.scene}, seed {out.seed}) in {wall_s:.1f} s to {out.path} "
             f"({size / 1e6:.1f} MB).",
             f"  {infant}: 18-month-old infant; {caregiver}: kneeling adult caregiver"]
    if out.high_five_s is not None:
        lines.append(f"  {_at(out.high_five_s)}  high five: both right hands feel the other; "
                     "both smile")
    elif "handover" in out.phases:
        lines.append(f"  high five: none within {demo.HIGH_FIVE_WAIT_S:g} s")
    else:
        lines.append("  high five: not reached in the recorded time")
    if out.handover_s is not None:
        lines.append(f"  {_at(out.handover_s)}  handover: {infant} holds the ball alone; "
                     "both smile")
    else:
        lines.append("  handover: not reached in the recorded time")
    for agent in out.agents:
        shown = [e for _, a, e in out.faces if a == agent]
        lines.append(f"  faces of {agent}: {' -> '.join(shown)}")
    contacts = summary["contact_events"] if summary else []
    first = f" (first: step {contacts[0][0]}, {contacts[0][1]})" if contacts else ""
    count = len(contacts) if summary else out.contact_events
    lines.append(f"  contact events between the two: {count}{first}")
    eyes = summary["eye_images"] if summary else {}
    counts = ", ".join(f"{a} {n['left']} + {n['right']}" for a, n in eyes.items())
    lines.append(f"  eye images ({demo.EYE_SIZE}x{demo.EYE_SIZE}, left + right): "
                 f"{counts or out.eye_frames}; skin points of both agents' arms and hands")
    if out.stopped:
        lines.append(f"The run ended early: {out.stopped}")
    lines.append("Open it with:\n" + _open_hint(out.path))
    return "\n".join(lines)


def _open_hint(path: Path) -> str:
    return f"  rerun {path}\n  mimo-social replay {path}"


def run(args: argparse.Namespace) -> int:
    t0 = time.perf_counter()
    out = demo.record_demo(args.record, args.seconds, args.seed, args.scene)
    wall = time.perf_counter() - t0
    print(report(out, wall, summarize(out.path)))
    return 0
