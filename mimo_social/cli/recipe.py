"""``mimo-social recipe TASK``: train a task with its shipped recipe and check what it learnt.

``mimo-social recipe reach --seeds 0,1 --out runs/recipe_reach --jobs 2`` trains the shipped
recipe (``mimo_social/train/recipes/reach.toml``: algorithm, budget, options) with each seed into
``OUT/seed<k>`` (runs already there are reused), then runs every final model, the scripted
controller, random and zero on the same 30 seeded episodes and writes ``OUT/recipe.md`` /
``OUT/recipe.json``: per seed the success rate of the mean action and of sampled actions and
whether it reaches 80 % of the scripted controller's (:mod:`mimo_social.train.recipes`).
``mimo-social recipe --list`` prints the shipped recipes.
"""

from __future__ import annotations

from ..train.recipes import check_recipe, load_recipe, recipe_markdown, shipped_recipes
from ._args import output_dir, positive_int, seed

__all__ = ["add_parser"]


def _seeds(text: str) -> list[int]:
    out = []
    for part in (p.strip() for p in text.split(",") if p.strip()):
        try:
            out.append(seed(part))
        except Exception:
            raise ValueError(f"--seeds {text!r}: {part!r} is not a seed; allowed: integers "
                             ">= 0 separated by commas, e.g. 0,1") from None
    if not out:
        raise ValueError(f"--seeds {text!r}: no seed; e.g. 0,1")
    return out


def _list() -> int:
    print("| recipe | description | status |\n|---|---|---|")
    for name in shipped_recipes():
        r = load_recipe(name)
        print(f"| {name} | {r.description} | {r.status} |")
    return 0


def _main(args) -> int:
    if args.list:
        return _list()
    if args.recipe is None or args.out is None:
        raise ValueError("give a recipe (a task name or a .toml file) and --out DIR, or --list")
    res = check_recipe(args.recipe, _seeds(args.seeds), args.out, jobs=args.jobs,
                       episodes=args.episodes, eval_seed=args.eval_seed, steps=args.steps,
                       model=args.model, progress=not args.no_progress)
    print(recipe_markdown(res), end="")
    print(f"wrote {args.out}/recipe.md and {args.out}/recipe.json")
    return 0


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "recipe", help="train a task with its shipped recipe and check what it learnt",
        description="Train the task's shipped recipe (algorithm, budget, options: "
        "mimo_social/train/recipes/<task>.toml, or a .toml file) with each seed, then evaluate "
        "every final model beside the scripted controller on the same seeded episodes, "
        "deterministic and sampled; a seed passes at 80 %% of the scripted success rate.")
    p.add_argument("recipe", nargs="?", default=None,
                   help=f"a shipped recipe ({', '.join(shipped_recipes())}) or a .toml file")
    p.add_argument("--list", action="store_true", help="list the shipped recipes and stop")
    p.add_argument("--seeds", default="0,1", help="seeds to train, comma-separated (default 0,1)")
    p.add_argument("--out", type=output_dir, default=None,
                   help="output directory (runs in OUT/seed<k>)")
    p.add_argument("--jobs", type=positive_int, default=1,
                   help="runs trained at a time, each in its own process")
    p.add_argument("--steps", type=positive_int, default=None,
                   help="another budget than the recipe's (environment steps)")
    p.add_argument("--episodes", type=positive_int, default=30,
                   help="evaluation episodes per policy (default 30)")
    p.add_argument("--eval-seed", type=seed, default=1000,
                   help="seed of the first evaluation episode (default 1000)")
    p.add_argument("--model", choices=("final", "best"), default=None,
                   help="judge each run's final model or its best evaluated one (default: the "
                   "recipe's 'model', final unless it says best)")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    p.set_defaults(func=_main)

