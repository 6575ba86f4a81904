"""``mimo-social fig8``: the paper's Fig. 8 (PPO and SAC on reach, stand-up, self-body and catch,
several seeds) in one command, the shipped recipes beside them with ``--recipes``.

``mimo-social fig8 --seeds 5 --jobs 2 --out runs/fig8`` trains every run (finished ones reused:
an interrupted reproduction goes on), then writes ``OUT/fig8.png``, ``OUT/fig8.md`` and per task
``compare.png`` and ``baselines.md`` (:mod:`mimo_social.train.fig8`).
"""

from __future__ import annotations

from ..train.fig8 import FIG8_STEPS, FIG8_TASKS, fig8, redraw
from ._args import comma_choices, non_negative_int, output_dir, positive_int, seed

__all__ = ["add_parser"]


def _main(args) -> int:
    if args.redraw:
        png = redraw(args.redraw, args.recipe_runs, tasks=args.tasks)
        print(f"wrote {png}")
        return 0
    if args.out is None:
        raise ValueError("--out is needed (or --redraw FIGURE_DIR); allowed: a directory")
    steps = {t: {k: v for k, v in (("ppo", args.ppo_steps), ("sac", args.sac_steps)) if v}
             for t in args.tasks}
    png = fig8(args.out, args.seeds, args.tasks, steps=steps, jobs=args.jobs,
               eval_episodes=args.eval_episodes, recipes=args.recipes,
               recipe_steps=args.recipe_steps, episodes=args.episodes, eval_seed=args.eval_seed,
               plot_only=args.plot_only, progress=not args.no_progress)
    print(f"wrote {png} and {args.out}/fig8.md")
    return 0


def add_parser(subparsers) -> None:
    budgets = "; ".join(f"{t} PPO {b['ppo']:,}, SAC {b['sac']:,}" for t, b in FIG8_STEPS.items())
    p = subparsers.add_parser(
        "fig8", help="the paper's Fig. 8: PPO and SAC on its four tasks, several seeds",
        description="Train PPO and SAC (SB3 defaults, one env per run) with several seeds on "
        "reach, standup, selfbody and catch (and the shipped recipes with --recipes), then plot "
        "the learning curves over environment steps and wall time and evaluate the final "
        f"models. Default budgets: {budgets}.")
    p.add_argument("--out", type=output_dir, default=None, help="output directory")
    p.add_argument("--seeds", type=positive_int, default=5, help="seeds per algorithm (0..n-1)")
    p.add_argument("--tasks", type=comma_choices(FIG8_TASKS, "task"), default=list(FIG8_TASKS),
                   help="comma-separated subset of " + ",".join(FIG8_TASKS))
    p.add_argument("--jobs", type=positive_int, default=1, help="runs trained at a time")
    p.add_argument("--ppo-steps", type=positive_int, default=None,
                   help="PPO's budget on every task (default: the table above)")
    p.add_argument("--sac-steps", type=positive_int, default=None,
                   help="SAC's budget on every task (default: the table above)")
    p.add_argument("--recipes", action="store_true", help="train the shipped recipes too")
    p.add_argument("--recipe-steps", type=positive_int, default=None,
                   help="the recipes' budget (default: each recipe's own)")
    p.add_argument("--eval-episodes", type=positive_int, default=3,
                   help="episodes per evaluation during training")
    p.add_argument("--episodes", type=non_negative_int, default=10,
                   help="episodes per policy in the final table (0: each run's last evaluation "
                   "during training instead)")
    p.add_argument("--eval-seed", type=seed, default=1000, help="seed of the first of them")
    p.add_argument("--plot-only", action="store_true", help="plot and tabulate existing runs")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    p.add_argument("--redraw", metavar="FIGURE_DIR", default=None,
                   help="draw FIGURE_DIR/fig8.png again from its <task>/compare.csv files (no "
                   "models needed, nothing trained)")
    p.add_argument("--recipe-runs", metavar="DIR", default=None,
                   help="with --redraw: the recipe runs DIR/<task>/seed<k> (config.json, "
                   "progress.csv) beside the learners")
    p.set_defaults(func=_main)
