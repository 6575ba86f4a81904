"""``mimo-social calibrate fmax | vmax | speed``: the muscle model's parameters and its cost
(the procedures: :mod:`mimo_social.experiments.calibration`)."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from ..experiments import calibration as cal
from ._args import int_range, non_negative_int, positive_float, positive_int, seed

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "calibrate", help="calibrate the muscle model (fmax, vmax) and print target vs achieved",
        description=cal.__doc__.split("\n\n")[1] if cal.__doc__ else None)
    which = parser.add_subparsers(dest="parameter", required=True, metavar="PARAMETER")
    f = which.add_parser("fmax", help="maximum isometric forces: held joints, full activation, "
                                      "achieved vs Table I torques")
    f.add_argument("--hands", choices=cal.HAND_CHOICES, default="both",
                   help="body version(s) to calibrate (default: both)")
    f.add_argument("--iterations", type=non_negative_int, default=cal.ITERATIONS,
                   help=f"fmax updates (default: {cal.ITERATIONS}); 0 only checks the shipped "
                        "values")
    f.add_argument("--steps", type=int_range(4), default=cal.PHASE_STEPS,
                   help=f"physics steps per phase, at least 4 (default: {cal.PHASE_STEPS})")
    f.add_argument("--write", action="store_true",
                   help="store the calibrated fmax in mimo_social/body/data/<hands>_muscles.csv")
    f.set_defaults(func=run)
    v = which.add_parser("vmax", help="maximum contraction speeds: floating infant, bang-bang "
                                      "muscles, peak speeds")
    v.add_argument("--hands", choices=cal.HAND_CHOICES, default="mitten",
                   help="body version(s) (default: mitten)")
    v.add_argument("--episodes", type=positive_int, default=30, help="episodes (default: 30)")
    v.add_argument("--seconds", type=positive_float, default=30.0,
                   help="simulated seconds per episode (default: 30)")
    v.add_argument("--seed", type=seed, default=0, help="random seed (default: 0)")
    v.add_argument("--no-scale", action="store_true",
                   help="keep the raw values (no common factor matching the knee reference)")
    v.add_argument("--write", action="store_true",
                   help="store the new vmax in mimo_social/body/data/<hands>_muscles.csv")
    v.set_defaults(func=run)
    sp = which.add_parser("speed", help="the muscle model's cost per physics step and the "
                                        "physics-only speed of one infant")
    sp.add_argument("--hands", choices=cal.HAND_CHOICES, default="both",
                    help="body version(s) (default: both)")
    sp.add_argument("--seconds", type=positive_float, default=20.0,
                    help="simulated seconds per measurement (default: 20)")
    sp.set_defaults(func=run)
    return parser


def _bar(args: argparse.Namespace, what: str):
    """The bodies to calibrate, with a progress bar (one step a body: each takes minutes)."""
    from tqdm import tqdm
    versions = list(cal.hand_versions(args.hands))
    return tqdm(versions, desc=f"calibrate {what}", unit="body", file=sys.stderr,
                dynamic_ncols=True)


def run(args: argparse.Namespace) -> int:
    out = sys.stdout
    if args.parameter == "fmax":
        worst = 0.0
        for hands in _bar(args, "fmax"):
            res = cal.calibrate_fmax(hands, args.iterations, args.steps)
            print(f"\nfmax, {hands} body ({args.iterations} iterations, {args.steps} steps a "
                  "phase, joints held at 0 deg or their nearest limit):", file=out)
            print(cal.fmax_table(res), file=out)
            err = np.abs(np.r_[res["achieved_neg"] / res["target_neg"],
                               res["achieved_pos"] / res["target_pos"]] - 1).max()
            worst = max(worst, float(err))
            if args.write:
                updates = {name: (res["vmax"][k], res["fmax_neg"][k], res["fmax_pos"][k])
                           for k, name in enumerate(res["names"])}
                print(f"wrote {cal.write_parameters(hands, updates)}", file=out)
        return 0 if worst <= 0.05 else 1
    if args.parameter == "speed":
        print(f"{'body':14s} {'physics only':>22s} {'physics + muscles':>22s} "
              f"{'muscle model':>28s}", file=out)
        for hands in _bar(args, "speed"):
            r = cal.measure_speed(hands, args.seconds)
            print(f"{hands:14s} {r['physics_real_per_sim']:11.4f} real s/sim s "
                  f"{r['muscle_real_per_sim']:11.4f} real s/sim s "
                  f"{r['muscle_ms_per_step']:8.4f} ms/physics step ({r['muscle_axes']} axes)",
                  file=out)
        return 0
    # vmax
    for hands in _bar(args, "vmax"):
        res = cal.calibrate_vmax(hands, args.episodes, args.seconds, seed=args.seed,
                                 scale_to_reference=not args.no_scale)
        print(f"\nvmax, {hands} body ({args.episodes} episodes of {args.seconds:g} s):", file=out)
        print(cal.vmax_table(res), file=out)
        if args.write:
            updates = {name: (res["vmax"][k], res["fmax_neg"][k], res["fmax_pos"][k])
                       for k, name in enumerate(res["names"])}
            print(f"wrote {cal.write_parameters(hands, updates)}", file=out)
    return 0
