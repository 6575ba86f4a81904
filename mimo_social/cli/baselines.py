"""``mimo-social baselines TASK``: random, zero, scripted and trained policies on the same episodes.

``mimo-social baselines reach --episodes 30 --seed 0 --run runs/reach_ppo_s0 runs/reach_sac_s0
--markdown baselines.md --json baselines.json`` runs each policy on episodes seeded 0..29 and
prints a markdown table (policy | episodes | success | return | length | steps to success);
:mod:`mimo_social.train.baselines` says what each policy and column is.
"""

from __future__ import annotations

import sys

from ..train.baselines import baselines, markdown_table, write_json
from ..train.tasks import ALL_TASKS, TrainInputError
from ._args import env_kwargs, output_file, positive_int, seed, write_file

__all__ = ["add_parser"]


def _main(args) -> int:
    try:
        res = baselines(args.task, args.episodes, args.seed, args.run, model=args.model,
                        env_kwargs=args.env_kwargs, progress=not args.no_progress)
    except (TrainInputError, FileNotFoundError) as e:
        print(f"mimo-social baselines: error: {e}", file=sys.stderr)
        return 2
    table = markdown_table(res)
    print(table, end="")
    if args.markdown:
        write_file(args.markdown, table)
        print(f"wrote {args.markdown}")
    if args.json:
        write_json(res, args.json)
        print(f"wrote {args.json}")
    return 0


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "baselines", help="random, zero, scripted and trained policies on the same episodes",
        description="Run a random policy, the zero action, the task's scripted controller and "
        "each trained run on the same seeded episodes; print success rate, return, length and "
        "steps to success as a markdown table.")
    p.add_argument("task", choices=ALL_TASKS, help="a task of the catalogue (social tasks: the "
                   "learner, its partner scripted)")
    p.add_argument("--episodes", type=positive_int, default=30, help="episodes per policy")
    p.add_argument("--seed", type=seed, default=0, help="seed of the first episode (episodes are "
                   "seeded seed .. seed+episodes-1)")
    p.add_argument("--run", nargs="+", action="extend", default=[], metavar="DIR",
                   help="directories written by 'mimo-social train' (their final model)")
    p.add_argument("--model", default="final", choices=("final", "best"),
                   help="final (model.zip) or best "
                   "(best_model.zip) of each run")
    p.add_argument("--env-kwargs", type=env_kwargs, default=None,
                   help="JSON keyword arguments for the env of every policy (default: those the "
                   "runs were trained with)")
    p.add_argument("--markdown", default=None, metavar="FILE", type=output_file,
                   help="also write the table here")
    p.add_argument("--json", default=None, metavar="FILE", type=output_file,
                   help="write every number (and each episode's) as JSON")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=_main)
