"""``mimo-social train-gpu``: PPO on batched MuJoCo Warp worlds, collecting and learning on the
device (:mod:`mimo_social.train.gpu_ppo`; docs/gpu.md). Needs the ``gpu`` extra.

    mimo-social train-gpu --task reach --worlds 256 --steps 1500000 --seed 0 --out runs/r
    mimo-social train-gpu --task high_five --worlds 64 --steps 200000 --out runs/hf

Writes ``config.json``, ``progress.csv`` (one row per iteration: timesteps, wall time, mean
return and success rate of the episodes that finished), ``policy.pt`` and
``learning_curve.png`` to ``--out``. Runs on
a GPU when Warp sees one (``--device auto``), else on Warp's CPU device, and says which.
"""

from __future__ import annotations

import argparse

from ._args import non_negative_float, output_dir, positive_float, positive_int, seed

__all__ = ["NAME", "add_parser", "run"]

NAME = "train-gpu"
#: the names of :data:`mimo_social.train.gpu_ppo.TASKS`, spelt out so that building the parser
#: imports no torch (tests/gpu/test_gpu_ppo.py checks that the two agree)
TASKS = ("reach", "high_five", "selfbody", "standup", "catch", "rollover")


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        NAME, help="PPO on MuJoCo Warp's batched worlds, on the device (reach, high five, "
             "self-body, stand-up, catch, roll-over)",
        description="PPO (TorchRL's ClipPPOLoss and GAE) on N batched MuJoCo Warp worlds of "
                    "reach, of self-body, of stand-up, of catch, of roll-over or of the high "
                    "five with its scripted partner, collected and learnt on the device: a GPU "
                    "when Warp sees one, else Warp's CPU device.")
    parser.add_argument("--task", choices=TASKS, required=True, help="the task to learn")
    parser.add_argument("--worlds", type=positive_int, default=64,
                        help="worlds stepped together (default 64)")
    parser.add_argument("--steps", type=positive_int, default=100_000,
                        help="world-steps in all, rounded up to whole iterations "
                             "(default 100000)")
    parser.add_argument("--seed", type=seed, default=0, help="the run's seed (default 0)")
    parser.add_argument("--out", type=output_dir, required=True,
                        help="folder for config.json, progress.csv and policy.pt")
    parser.add_argument("--lr", type=positive_float, default=3e-4,
                        help="Adam's learning rate (default 3e-4)")
    parser.add_argument("--epochs", type=positive_int, default=10,
                        help="passes over each rollout (default 10)")
    parser.add_argument("--minibatch", type=positive_int, default=512,
                        help="samples per gradient step, at most worlds x rollout "
                             "(default 512)")
    parser.add_argument("--rollout", type=positive_int, default=32,
                        help="control steps of every world per iteration (default 32)")
    parser.add_argument("--max-steps", type=positive_int, default=None,
                        help="episode length (default: the task's)")
    parser.add_argument("--entropy-coeff", type=non_negative_float, default=0.0,
                        help="the entropy bonus' weight (default 0)")
    parser.add_argument("--no-touch", dest="touch", action="store_false",
                        help="leave the touch skin out of the learner's observation (default: "
                             "observed where the task's env has touch: self-body, high five)")
    parser.add_argument("--eyes", type=positive_int, default=None, metavar="SIDE",
                        help="the learner also sees through its two eyes: square images of "
                             "SIDE pixels (16 to 256), rendered on the device, encoded by a "
                             "small CNN (default: no eyes)")
    parser.add_argument("--device", choices=("auto", "cpu", "cuda"), default="auto",
                        help="auto (default): a GPU when Warp sees one, else the CPU")
    parser.set_defaults(func=run)
    return parser


def run(args: argparse.Namespace) -> int:
    from ..train.gpu_ppo import GpuPPOConfig, plot_progress, train_gpu_ppo

    config = GpuPPOConfig(task=args.task, worlds=args.worlds, steps=args.steps, seed=args.seed,
                          learning_rate=args.lr, epochs=args.epochs, minibatch=args.minibatch,
                          rollout=args.rollout, max_steps=args.max_steps,
                          entropy_coeff=args.entropy_coeff, touch=args.touch, eyes=args.eyes,
                          device=None if args.device == "auto" else args.device)

    def show(row):
        succ = row["success_rate"] or "-"
        ret = row["episode_return_mean"] or "-"
        print(f"{row['timesteps']:>10} steps {row['wall_time_s']:>9} s  return {ret:>10}  "
              f"success {succ:>6}  ({row['episodes']} episodes, {row['steps_per_s']} "
              f"steps/s)", flush=True)

    out = train_gpu_ppo(config, args.out, progress=show)
    wrote = "config.json, progress.csv, policy.pt"
    try:
        plot_progress(args.out)
        wrote += ", learning_curve.png"
    except (ImportError, ValueError) as e:   # no matplotlib, or no episode finished
        print(f"no learning curve: {e}")
    print(f"device: {out['device']} ({out['device_name']}); {out['iterations']} iterations; "
          f"wrote {wrote} to {args.out}")
    return 0
