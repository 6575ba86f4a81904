"""``mimo-social bench engines``: SB3 and RLlib training throughput side by side.

``mimo-social bench engines --tasks high_five,mirror --workers 1,2 --seconds 30 --out DIR``
    PPO with one shared policy (64x64 MLP) on each task, with SB3 (``workers`` spawned worker
    processes) and with RLlib (``workers`` env runners), ``--seconds`` of training each after a
    warm-up iteration; prints env steps per second and the scaling efficiency from 1 to n workers
    and writes ``DIR/engines.json``, ``DIR/engines.md`` and ``DIR/engines.png``
    (:mod:`mimo_social.bench.engines`, :mod:`mimo_social.train.throughput`). Needs RLlib
    (``pip install -e '.[rllib]'``, see docs/scaling.md) unless ``--engines sb3``.
    ``--address auto|HOST:PORT`` runs RLlib's side on an existing Ray cluster (default: a local
    Ray with ``max(workers) + 1`` CPUs).

``--to-success 0.8 [--success-steps 300000]``
    Also trains high five with each engine (PPO, each engine's defaults, ``--success-workers``
    workers, 1 by default) and reports the wall time to the first evaluation with that success rate (long).
"""

from __future__ import annotations

import argparse
import functools
import shlex
from pathlib import Path

from ..bench import engines as bench
from ..train import MULTI_TASKS
from ..train.throughput import ENGINES, rllib_throughput, sb3_throughput, time_to_success
from ._args import comma_choices, output_dir, positive_float, positive_int, seed, write_file

__all__ = ["NAME", "HELP", "add_parser", "run"]

#: its name under ``mimo-social bench`` and its line in the list of measurements
NAME = "engines"
HELP = "SB3 vs RLlib: env steps/s while training, 1 and 2 workers"


def _ints(text: str) -> list[int]:
    try:
        values = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values or min(values) < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: expected positive integers, e.g. 1,2")
    return values


def add_parser(subparsers, name: str = NAME, **kw) -> argparse.ArgumentParser:
    """Add the parser as ``name`` (``kw``: more of argparse's ``add_parser`` settings, e.g.
    ``help``; none: not listed)."""
    p = subparsers.add_parser(
        name, **kw,
        description="PPO training throughput (env steps per second) of SB3 (worker processes) "
        "and RLlib (env runners) side by side on the same tasks with the same policy, and the "
        "scaling efficiency from 1 worker to n.")
    p.add_argument("--tasks", default="high_five,mirror",
                   type=comma_choices(list(MULTI_TASKS), "task", as_text=True),
                   help="social tasks, comma-separated (default: high_five,mirror)")
    p.add_argument("--engines", default="sb3,rllib",
                   type=comma_choices(list(ENGINES), "engine", as_text=True))
    p.add_argument("--workers", default=[1, 2], type=_ints,
                   help="worker processes / env runners to measure, e.g. 1,2 (default)")
    p.add_argument("--seconds", type=positive_float, default=30.0,
                   help="timed training per configuration, after one warm-up iteration")
    p.add_argument("--rollout", type=positive_int, default=1024,
                   help="env steps per training iteration (default 1024)")
    p.add_argument("--minibatch", type=positive_int, default=256,
                   help="samples (agent transitions) per minibatch (default 256)")
    p.add_argument("--epochs", type=positive_int, default=4, help="passes per iteration")
    p.add_argument("--hidden", default=[64, 64], type=_ints,
                   help="policy and value MLP layer sizes (default 64,64)")
    p.add_argument("--seed", type=seed, default=0)
    p.add_argument("--torch-threads", type=positive_int, default=1,
                   help="torch threads of the learner (this process), both engines (default 1)")
    p.add_argument("--address", default=None, help="RLlib: join this Ray cluster (auto or "
                   "HOST:PORT); default: start a local Ray")
    p.add_argument("--to-success", type=positive_float, default=None, metavar="RATE",
                   help="also train high five with each engine (--success-workers workers, "
                   "each engine's PPO defaults) and report the wall time to this evaluation success "
                   "rate, e.g. 0.8 (long: minutes to hours)")
    p.add_argument("--success-steps", type=positive_int, default=300_000,
                   help="--to-success: step budget per engine (default 300000)")
    p.add_argument("--success-eval-every", type=positive_int, default=10_000,
                   help="--to-success: steps between evaluations (default 10000)")
    p.add_argument("--success-workers", type=positive_int, default=1,
                   help="--to-success: worker processes / env runners (default 1: both engines "
                   "then update on 2048 env steps at a time)")
    p.add_argument("--no-throughput", action="store_true",
                   help="skip the steps/s measurements (with --to-success)")
    p.add_argument("--out", required=True, type=output_dir,
                   help="writes engines.json, engines.md and engines.png here")
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    engines = args.engines.split(",")
    if args.to_success is not None and args.to_success > 1:
        raise ValueError(f"--to-success {args.to_success:g}: a success rate from 0 to 1, "
                         "e.g. 0.8")
    kw = dict(seed=args.seed, rollout=args.rollout, minibatch=args.minibatch,
              epochs=args.epochs, hidden=tuple(args.hidden))
    measure = {}
    if "sb3" in engines:
        measure["sb3"] = functools.partial(sb3_throughput, **kw)
    started = False
    if "rllib" in engines:
        try:
            import ray
        except ImportError:
            raise RuntimeError("RLlib is not installed: pip install -e '.[rllib]' (docs/"
                               "scaling.md), or measure SB3 alone with --engines sb3") from None
        if not ray.is_initialized():
            if args.address:
                ray.init(address=args.address, log_to_driver=False)
            else:
                ray.init(num_cpus=max(*args.workers, args.success_workers) + 1,
                         include_dashboard=False,
                         log_to_driver=False)
            started = True
        measure["rllib"] = functools.partial(rllib_throughput, **kw)
    import torch
    torch.set_num_threads(args.torch_threads)      # the learner's threads, both engines alike
    settings = {"algorithm": "PPO, one shared policy", "MLP": "x".join(map(str, args.hidden)),
                "env steps per iteration": args.rollout, "minibatch": args.minibatch,
                "epochs": args.epochs, "seed": args.seed,
                "learner torch threads": args.torch_threads,
                "one world per worker": "SB3 spawned worker processes, RLlib env runners"}
    command = (f"mimo-social bench engines --tasks {args.tasks} --engines {args.engines} "
               f"--workers {','.join(map(str, args.workers))} --seconds {args.seconds:g} "
               f"--rollout {args.rollout} --minibatch {args.minibatch} --epochs {args.epochs} "
               f"--hidden {','.join(map(str, args.hidden))} --seed {args.seed} "
               f"--torch-threads {args.torch_threads} "
               + (f"--address {shlex.quote(args.address)} " if args.address else "")
               + f"--out {shlex.quote(str(args.out))}")
    if args.to_success is not None:
        command += (f" --to-success {args.to_success:g} --success-steps {args.success_steps} "
                    f"--success-eval-every {args.success_eval_every} "
                    f"--success-workers {args.success_workers}")
    if args.no_throughput:
        command += " --no-throughput"
    try:
        res = bench.run({} if args.no_throughput else measure, args.tasks.split(","),
                        args.workers, args.seconds, command=command, settings=settings)
        if args.to_success is not None:
            res["to_success"] = []
            for engine in engines:
                print(f"high_five: {engine} until {args.to_success:.0%} success ...")
                res["to_success"].append(time_to_success(
                    engine, "high_five", Path(args.out) / f"to_success_{engine}",
                    threshold=args.to_success, steps=args.success_steps,
                    workers=args.success_workers, seed=args.seed,
                    eval_every=args.success_eval_every))
    finally:
        if started:
            import ray
            ray.shutdown()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    import json
    write_file(out / "engines.json", json.dumps(res, indent=1))
    table = bench.markdown(res)
    write_file(out / "engines.md", table)
    if res["rows"]:
        bench.plot(res, out / "engines.png")
    print(table)
    print(f"wrote {out}/engines.json, engines.md" + (", engines.png" if res["rows"] else ""))
    return 0
