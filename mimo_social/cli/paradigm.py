"""``mimo-social paradigm TASK``: a paradigm's measures for several learners, side by side.

``mimo-social paradigm still_face --learner scripted random zero runs/sf/ppo_seed0 --episodes 10
--seed 1000 --markdown sf.md --json sf.json`` runs each learner on the same seeded episodes of
the paradigm (``still_face``: per phase; ``contingency``: per condition, in blocks of a live, a
replay and a non-contingent episode; ``imitation``: per demonstrated action) and prints one
markdown table, a column per learner, and for still face and contingency a second one of the
paradigm's effect (still face: the still phase's drop of smiling and gaze, their reunion
recovery, the rise of self-touch; contingency: live minus replay and live minus non-contingent);
:mod:`mimo_social.train.paradigms` says what each learner and measure is (the measures and
effects are the task modules' own).
"""

from __future__ import annotations

import argparse
import sys

from ..train.paradigms import LEARNER_NAMES, PARADIGMS
from ._args import env_kwargs, output_file, positive_int, seed, write_file

__all__ = ["add_parser"]


def learner(text: str) -> str:
    """A built-in learner name or a run folder holding config.json (checked against the task
    when the command runs)."""
    from pathlib import Path
    if text in LEARNER_NAMES:
        return text
    path = Path(text)
    if not path.is_dir() or not (path / "config.json").is_file():
        raise argparse.ArgumentTypeError(
            f"{text!r} is neither a learner name nor a run folder with config.json; allowed: "
            f"{', '.join(LEARNER_NAMES)} or a folder written by 'mimo-social train' / 'compare'")
    return text


def _main(args) -> int:
    from ..train.paradigms import run_paradigm, side_by_side, to_json
    from ..train.tasks import TrainInputError
    try:
        res = run_paradigm(args.task, args.learner or list(LEARNER_NAMES), args.episodes,
                           args.seed, env_kwargs=args.env_kwargs, model=args.model,
                           deterministic=not args.stochastic, progress=True)
    except (TrainInputError, FileNotFoundError) as e:
        print(f"mimo-social paradigm: error: {e}", file=sys.stderr)
        return 2
    table = side_by_side(res)
    print(table, end="")
    if args.markdown:
        write_file(args.markdown, table)
        print(f"wrote {args.markdown}")
    if args.json:
        write_file(args.json, to_json(res))
        print(f"wrote {args.json}")
    return 0


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "paradigm", help="a paradigm's per-phase / per-condition / per-action measures and its "
        "effect for several learners side by side",
        description="Run a paradigm (still_face: per phase; contingency and turn_taking: per "
        "condition; imitation: per demonstrated action) with each learner on the same seeded "
        "episodes and print its measures as one markdown table, a column per learner, and for "
        "still_face, contingency and turn_taking a table of the paradigm's effect (still face: "
        "still-phase drop and reunion recovery of smiling and gaze, rise of self-touch; "
        "contingency: live minus replay, live minus non-contingent; turn taking: contingent "
        "minus non-contingent vocalisation rate and speech-like share). Learners: scripted (the "
        "task's scripted infant baseline), random, zero (the resting action) or a run folder of "
        "'mimo-social train' / 'compare' (--mode scripted) on the same task.")
    p.add_argument("task", choices=PARADIGMS, help="the paradigm (a catalogue task)")
    p.add_argument("--learner", nargs="+", action="extend", default=[], type=learner,
                   metavar="LEARNER", help="scripted, random, zero or a run folder (default: "
                   "scripted random zero)")
    p.add_argument("--episodes", type=positive_int, default=5,
                   help="episodes per learner (contingency: blocks of three episodes)")
    p.add_argument("--seed", type=seed, default=0, help="seed of the first episode")
    p.add_argument("--model", default="final", choices=("final", "best"),
                   help="a run's final (model.zip) or best (best_model.zip) policy")
    p.add_argument("--stochastic", action="store_true",
                   help="a run's policy samples its actions as in training (seeded per "
                   "episode) instead of taking the most likely one")
    p.add_argument("--env-kwargs", type=env_kwargs, default=None,
                   help="JSON keyword arguments for the env of every learner (default: those "
                   "the runs were trained with)")
    p.add_argument("--markdown", default=None, metavar="FILE", type=output_file,
                   help="also write the table here")
    p.add_argument("--json", default=None, metavar="FILE", type=output_file,
                   help="write every number as JSON")
    p.set_defaults(func=_main)
