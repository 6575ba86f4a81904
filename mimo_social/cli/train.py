"""``mimo-social train | eval | compare``: the command line of :mod:`mimo_social.train`.

``mimo-social train --task reach --algo ppo --steps 200000 --seed 0 --out runs/reach_ppo``
    Trains with Stable-Baselines3's default hyperparameters and writes ``config.json``,
    ``model.zip``, ``best_model.zip``, ``checkpoints/``, ``progress.csv``, ``episodes.csv`` and
    ``learning_curve.png`` to ``--out`` (:mod:`mimo_social.train.runner`). A social task takes
    ``--mode shared | independent | scripted`` (docs/training_multi.md).
    ``--algo-kwargs '{"n_steps": 512}'`` and ``--env-kwargs '{"max_steps": 200}'`` override.
    ``--algo recurrent_ppo``: sb3-contrib's RecurrentPPO (an LSTM policy: memory);
    ``--normalize-reward``: SB3's VecNormalize on the rewards, saved as ``vecnormalize.pkl``.
    ``--categorical-heads``: the face (and voice) sampled as categorical choices beside the
    Gaussian motors (:mod:`mimo_social.train.categorical_heads`).
    ``--curriculum selfbody`` (env options by stage) and ``--bc-episodes N`` (a warm start
    cloned from the scripted controller): docs/training.md. ``--growth forward:1-12`` (the
    infant's age by training step: forward, inverse or stochastic): docs/training.md, "Growth".

``mimo-social eval DIR --episodes 10 [--record run.rrd] [--video run.mp4 | --frames DIR]``
    Reloads ``DIR/model.zip`` (``--model best`` or a path for another), runs the episodes with the
    deterministic policy (the mean action) and the stochastic one (sampled actions; only one:
    ``--deterministic`` / ``--stochastic``), prints the mean return, success rate and length of
    each and writes ``DIR/eval_results.json`` (:mod:`mimo_social.train.evaluation`).
    ``--ages 1,3,6,9,12``: the same episodes at each age, both policies, into a cross-age table
    and figure (``cross_age.csv`` / ``.md`` / ``.png`` / ``.json`` in DIR or ``--out``;
    :mod:`mimo_social.train.cross_age`).

``mimo-social compare --task standup --algos ppo,sac --seeds 3 --steps 50000 --out runs/cmp``
    Trains every algorithm with seeds 0..n-1 (``--jobs`` processes at a time) into
    ``OUT/<algo>_seed<k>`` and plots them together, over environment steps and over wall time,
    to ``OUT/compare.png`` / ``OUT/compare.csv`` (``--plot-only`` re-plots existing runs).
    ``--steps-per-algo ppo=100000,sac=20000`` gives each algorithm its own budget.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from ..train import (ALGOS, ALL_TASKS, MULTI_TASKS, TASKS, TrainInputError, VideoUnavailable,
                     compare, evaluate, train)
from ..train.comparison import parse_steps_per_algo
from ._args import (env_kwargs, input_dir, json_object, non_negative_float, non_negative_int,
                    output_dir, output_file, positive_float, positive_int, seed)

__all__ = ["add_parser"]


_json_arg = json_object   # (kept for callers of the old name)


def _common(p, steps_required: bool = True):
    p.add_argument("--task", required=True, choices=sorted(ALL_TASKS),
                   help=f"one-agent: {', '.join(TASKS)}; multi-agent: {', '.join(MULTI_TASKS)}")
    p.add_argument("--mode", default=None, choices=("shared", "independent", "scripted"),
                   help="multi-agent tasks: shared (one policy for all agents, the default), "
                   "independent (one policy per agent) or scripted (one learner, the partner "
                   "scripted)")
    p.add_argument("--steps", type=positive_int, required=steps_required,
                   help="environment steps to train for")
    p.add_argument("--eval-every", type=positive_int, default=None,
                   help="steps between evaluations (default: a schedule that spends at most "
                   "10%% of the training steps on evaluation, none before the first update)")
    p.add_argument("--eval-episodes", type=positive_int, default=5,
                   help="episodes per evaluation, of each policy (deterministic and sampled)")
    p.add_argument("--checkpoint-every", type=non_negative_int, default=None,
                   help="steps between checkpoints (default: steps / 5; 0: none)")
    p.add_argument("--env-kwargs", type=env_kwargs, default={},
                   help="JSON keyword arguments for the env, e.g. '{\"max_steps\": 200}'")
    p.add_argument("--algo-kwargs", type=json_object, default={},
                   help="JSON keyword arguments for the SB3 algorithm, over the hyperparameters "
                   "shipped for the task (docs/hyperparameters.md); every key is checked before "
                   "anything runs")
    p.add_argument("--normalize-obs", action=argparse.BooleanOptionalAction, default=None,
                   help="normalise the (non-image) observation inputs by running statistics "
                   "inside the policy (saved in the model); default: the task's shipped setting")


#: train options of --engine rllib only, with their defaults
_RLLIB_OPTS = {"address": None, "num_env_runners": 1, "num_envs_per_runner": 1,
               "num_cpus_per_learner": 1, "num_gpus_per_learner": 0.0}


def ray_address(text: str) -> str:
    """``auto``, ``HOST:PORT`` or ``ray://HOST:PORT`` (a Ray cluster to join)."""
    allowed = "auto, HOST:PORT or ray://HOST:PORT"
    rest = text[len("ray://"):] if text.startswith("ray://") else text
    if text == "auto":
        return text
    host, sep, port = rest.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise argparse.ArgumentTypeError(f"{text!r} not allowed; allowed: {allowed}")
    return text


def _engine_conflicts(args) -> str | None:
    """Options of the other engine given with this one, as an error text (None if none)."""
    given = lambda name, default: getattr(args, name) not in (None, default)  # noqa: E731
    if args.engine == "sb3":
        bad = [f"--{k.replace('_', '-')}" for k in _RLLIB_OPTS if given(k, None)]
        if args.algo == "appo":
            bad.append("--algo appo")
        if bad:
            return f"{', '.join(bad)}: for --engine rllib (the default engine is sb3)"
        return None
    bad = [f for f, k in (("--n-envs", "n_envs"), ("--n-cpus", "n_cpus"))
           if given(k, None)]
    if bad:
        return (f"{', '.join(bad)}: for --engine sb3; with --engine rllib use --num-env-runners "
                "and --num-envs-per-runner")
    bad = [f for f, k, d in (("--normalize-reward", "normalize_reward", False),
                             ("--categorical-heads", "categorical_heads", False),
                             ("--obs-min-std", "obs_min_std", None),
                             ("--algo recurrent_ppo", "algo", None),
                             ("--curriculum", "curriculum", None),
                             ("--bc-episodes", "bc_episodes", None),
                             ("--bc-epochs", "bc_epochs", None),
                             ("--bc-kwargs", "bc_kwargs", None),
                             ("--intrinsic", "intrinsic", None),
                             ("--intrinsic-kwargs", "intrinsic_kwargs", None),
                             ("--growth", "growth", None))
           if given(k, d) and (k != "algo" or args.algo == "recurrent_ppo")]
    if bad:
        return f"{', '.join(bad)}: for --engine sb3 (the default engine)"
    return None


def _train_rllib(args) -> dict:
    from ..train.rllib import require_ray
    require_ray()
    from ..train.rllib import train_rllib
    opts = {k: (d if getattr(args, k) is None else getattr(args, k))
            for k, d in _RLLIB_OPTS.items()}
    return train_rllib(args.task, args.algo, args.steps, args.seed, args.out, mode=args.mode,
                       eval_every=args.eval_every, eval_episodes=args.eval_episodes,
                       checkpoint_every=args.checkpoint_every, progress=not args.no_progress,
                       env_kwargs=args.env_kwargs, algo_kwargs=args.algo_kwargs,
                       normalize_obs=bool(args.normalize_obs),
                       flat_obs=bool(getattr(args, "flat_obs", False)),
                       frame_stack=getattr(args, "frame_stack", None) or 1, **opts)


def _sb3_train_kwargs(args) -> dict:
    """Options of the sb3 engine given on the command line (their defaults are train's)."""
    kw = {}
    if args.n_envs is not None:
        kw["n_envs"] = args.n_envs
    if args.worker_timeout is not None:
        kw["worker_timeout"] = args.worker_timeout
    if getattr(args, "flat_obs", False):
        kw["flat_obs"] = True
    if getattr(args, "frame_stack", None) is not None:
        kw["frame_stack"] = args.frame_stack
    if getattr(args, "normalize_reward", False):
        kw["normalize_reward"] = True
    if getattr(args, "categorical_heads", False):
        kw["categorical_heads"] = True
    if getattr(args, "obs_min_std", None) is not None:
        kw["obs_min_std"] = args.obs_min_std
    for key in ("curriculum", "bc_episodes", "bc_epochs", "bc_kwargs", "growth"):
        if getattr(args, key, None) is not None:
            kw[key] = getattr(args, key)
    if getattr(args, "intrinsic", None) is not None:
        kw["intrinsic"] = {"kind": args.intrinsic, **(args.intrinsic_kwargs or {})}
    elif getattr(args, "intrinsic_kwargs", None) is not None:
        kw["intrinsic"] = dict(args.intrinsic_kwargs)    # (refused: no kind)
    return kw


def growth_spec(text: str):
    """A growth schedule spec (``forward:1-12``, ``inverse:1-12:200000``, ``stochastic:3-9``),
    checked: a :class:`~mimo_social.train.growth.Growth`."""
    from ..train.growth import parse_growth
    try:
        return parse_growth(text)
    except TrainInputError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def _success(last: dict, key: str) -> str:
    """``, success 80% (mean action), 100% (sampled actions)`` of a progress row (the parts it
    has; NaN: the task reports no success)."""
    parts = []
    for k, what in ((key, "mean action"), (key + "_stochastic", "sampled actions")):
        value = last.get(k)
        if value is not None and not math.isnan(value):
            parts.append(f"{value:.0%} ({what})")
    return (", success " + ", ".join(parts)) if parts else ""


def _train_main(args) -> int:
    conflict = _engine_conflicts(args)
    if conflict:
        print(f"mimo-social train: error: {conflict}", file=sys.stderr)
        return 2
    try:
        if args.engine == "rllib":
            res = _train_rllib(args)
        else:
            res = train(args.task, args.algo, args.steps, args.seed, args.out,
                        eval_every=args.eval_every, eval_episodes=args.eval_episodes,
                        checkpoint_every=args.checkpoint_every, progress=not args.no_progress,
                        env_kwargs=args.env_kwargs, algo_kwargs=args.algo_kwargs,
                        mode=args.mode, n_cpus=args.n_cpus, normalize_obs=args.normalize_obs,
                        **_sb3_train_kwargs(args))
    except TrainInputError as e:
        print(f"mimo-social train: error: {e}", file=sys.stderr)
        return 2
    last = res["last_eval"]
    mode = f" ({res['mode']})" if res.get("mode") else ""
    engine = " with RLlib" if args.engine == "rllib" else ""
    stopped = " (interrupted)" if res.get("interrupted") else ""
    print(f"trained {args.algo.upper()}{engine} on {args.task}{mode} for {res['timesteps']} steps "
          f"in {res['wall_time_s']:.0f} s{stopped}; last evaluation: return "
          f"{last['eval_return_mean']:.3g}" + _success(last, "eval_success_rate"))
    for a in res.get("agents", ()):
        print(f"  {a}: return {last[f'eval_return_mean_{a}']:.3g}"
              + _success(last, f"eval_success_rate_{a}"))
    models = sorted({Path(m).name for m in res.get("models", {"": res["model"]}).values()})
    print(f"wrote {res['out']}/" + ("{" + ", ".join(models) + "}" if len(models) > 1 else models[0])
          + ", progress.csv, learning_curve.png")
    if res.get("interrupted"):
        from ..train.interrupt import exit_code
        print(f"mimo-social train: stopped by signal {res['signal']}; the run is saved as it "
              f"stood at step {res['timesteps']} (config.json: \"interrupted\": true)",
              file=sys.stderr)
        return exit_code(res["signal"])
    return 0


def _run_engine(run) -> str:
    """``rllib`` for a run of --engine rllib (its config.json says so), else ``sb3``."""
    try:
        return json.loads((Path(run) / "config.json").read_text()).get("engine", "sb3")
    except (OSError, ValueError, AttributeError):
        return "sb3"   # (evaluate says what is missing)


def _eval_lines(res: dict, head: str, which: str, models: dict | None) -> None:
    success = res["success_rate"]
    print(f"{head}: {res['episodes']} episodes, {which}: return {res['return_mean']:.4g} +- "
          f"{res['return_std']:.3g}, length {res['length_mean']:.0f}"
          + ("" if math.isnan(success) else f", success {success:.0%}"))
    for a, r in res.get("agents", {}).items():
        s = r["success_rate"]
        print(f"  {a} ({Path(models[a]).name}): return {r['return_mean']:.4g} +- "
              f"{r['return_std']:.3g}" + ("" if math.isnan(s) else f", success {s:.0%}"))


def _ages_main(args) -> int:
    """``eval --ages``: the cross-age table (printed) and figure."""
    from ..train.cross_age import evaluate_ages
    from ..train.growth import check_ages
    given = [f for f, v in (("--record", args.record), ("--video", args.video),
                            ("--frames", args.frames), ("--stochastic", args.stochastic),
                            ("--deterministic", args.deterministic)) if v]
    try:
        ages = check_ages(args.ages, "--ages")
        if given:
            raise TrainInputError(f"{', '.join(given)} with --ages; allowed there: --episodes, "
                                  "--model, --seed, --env-kwargs, --out (both policies are "
                                  "always run)")
        if _run_engine(args.dir) != "sb3":
            raise TrainInputError("--ages: for runs of --engine sb3")
        res = evaluate_ages(args.dir, ages, args.episodes, model=args.model, seed=args.seed,
                            out=args.out, env_kwargs=args.env_kwargs,
                            progress=not args.no_progress)
    except (FileNotFoundError, TrainInputError) as e:
        print(f"mimo-social eval: error: {e}", file=sys.stderr)
        return 2
    print(res["markdown"])
    print(f"wrote {res['csv']}, {res['md']}, {res['png']} and {res['json']}")
    return 0


def _eval_main(args) -> int:
    if args.ages is not None:
        return _ages_main(args)
    if args.out is not None:
        print("mimo-social eval: error: --out is the folder of the cross-age files: give it "
              "with --ages (without, eval writes DIR/eval_results.json)", file=sys.stderr)
        return 2
    if args.stochastic and args.deterministic:
        print("mimo-social eval: error: --stochastic and --deterministic: give at most one "
              "(neither: both policies)", file=sys.stderr)
        return 2
    both = not (args.stochastic or args.deterministic)
    kwargs = dict(model=args.model, seed=args.seed, deterministic=not args.stochastic,
                  record=args.record, video=args.video, frames=args.frames,
                  frame_every=args.frame_every, env_kwargs=args.env_kwargs)
    try:
        if _run_engine(args.dir) == "rllib":
            from ..train.rllib import require_ray
            require_ray()
            from ..train.rllib import evaluate_rllib
            both = False
            res = evaluate_rllib(args.dir, args.episodes, **kwargs)
        else:
            res = evaluate(args.dir, args.episodes, both=both, progress=not args.no_progress,
                           **kwargs)
    except (VideoUnavailable, FileNotFoundError, TrainInputError) as e:
        print(f"mimo-social eval: error: {e}", file=sys.stderr)
        return 2
    mode = f" {res['mode']}" if res.get("mode") else ""
    head = f"{res['task']} {res['algo'].upper()}{mode} {Path(res['model']).name}"
    _eval_lines(res, head, "mean action (deterministic)" if res["deterministic"]
                else "sampled actions (stochastic)", res.get("models"))
    if both:
        _eval_lines({"episodes": res["episodes"], **res["stochastic"]}, head,
                    "sampled actions (stochastic)", res.get("models"))
    for key in ("record", "video", "frames"):
        if key in res:
            print(f"wrote {res[key]}")
    if res.get("video_error"):
        print(f"mimo-social eval: error: --video: {res['video_error']}", file=sys.stderr)
        return 1
    return 0


def _compare_main(args) -> int:
    algos = [a.strip() for a in args.algos.split(",") if a.strip()]
    try:
        png = _compare_run(args, algos)
    except TrainInputError as e:
        print(f"mimo-social compare: error: {e}", file=sys.stderr)
        return 2
    print(f"wrote {png} and {png.with_suffix('.csv')}")
    return 0


def _compare_steps(args, algos):
    """--steps for every algorithm, overridden per algorithm by --steps-per-algo."""
    per = {}
    if args.steps_per_algo and args.engine == "rllib":   # (appo too)
        for part in filter(None, (x.strip() for x in args.steps_per_algo.split(","))):
            algo, _, value = part.partition("=")
            if not value.strip().isdigit() or int(value) < 1:
                raise TrainInputError(f"steps per algorithm {part!r}: expected ALGO=STEPS, "
                                      "e.g. ppo=100000,appo=100000")
            per[algo.strip()] = int(value)
    elif args.steps_per_algo:
        per = parse_steps_per_algo(args.steps_per_algo)
    unknown = [a for a in per if a not in algos]
    if unknown:
        raise TrainInputError(f"--steps-per-algo names {', '.join(unknown)}, which --algos "
                              f"({','.join(algos)}) does not compare")
    missing = [a for a in algos if a not in per]
    if args.steps is None and missing and not args.plot_only:
        raise TrainInputError(f"no step budget for {', '.join(missing)}: give --steps (every "
                              "algorithm) or --steps-per-algo with an entry for each")
    return {a: per.get(a, 1 if args.steps is None else args.steps) for a in algos}


#: compare options of --engine rllib only, with their defaults
_RLLIB_COMPARE_OPTS = {"address": None, "num_env_runners": 1, "num_envs_per_runner": 1,
                       "num_cpus_per_learner": 1, "num_gpus_per_learner": 0.0,
                       "max_concurrent": None, "num_cpus": None}


def _compare_rllib(args, algos, steps):
    from ..train.rllib import require_ray
    require_ray()
    from ..train.rllib.tune import compare_rllib
    if args.jobs != 1:
        raise TrainInputError("--jobs is for --engine sb3; with --engine rllib, Ray Tune runs as "
                              "many runs at once as the cluster's CPUs hold (--max-concurrent "
                              "caps it)")
    opts = {k: (d if getattr(args, k) is None else getattr(args, k))
            for k, d in _RLLIB_COMPARE_OPTS.items()}
    return compare_rllib(args.task, algos, args.seeds, steps, args.out,
                         plot_only=args.plot_only, mode=args.mode, eval_every=args.eval_every,
                         eval_episodes=args.eval_episodes,
                         checkpoint_every=args.checkpoint_every, env_kwargs=args.env_kwargs,
                         algo_kwargs=args.algo_kwargs, normalize_obs=bool(args.normalize_obs),
                         **opts)


def _compare_run(args, algos):
    steps = _compare_steps(args, algos)
    if args.engine == "rllib":
        return _compare_rllib(args, algos, steps)
    bad = [f"--{k.replace('_', '-')}" for k in _RLLIB_COMPARE_OPTS if getattr(args, k) is not None]
    if bad:
        raise TrainInputError(f"{', '.join(bad)}: for --engine rllib (the default engine is sb3)")
    return compare(args.task, algos, args.seeds, steps, args.out, jobs=args.jobs,
                   plot_only=args.plot_only, mode=args.mode, eval_every=args.eval_every,
                   eval_episodes=args.eval_episodes, checkpoint_every=args.checkpoint_every,
                   env_kwargs=args.env_kwargs, algo_kwargs=args.algo_kwargs,
                   normalize_obs=args.normalize_obs)


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("train", help="train PPO, SAC or RecurrentPPO on a one-agent or "
                              "social task",
                              description="Train a Stable-Baselines3 policy (default "
                              "hyperparameters) with periodic evaluation, checkpoints and a "
                              "learning curve (CSV and PNG); --engine rllib trains with RLlib "
                              "on Ray (a local Ray, or a cluster with --address).")
    _common(p)
    p.add_argument("--algo", required=True, choices=(*ALGOS, "appo"),
                   help="ppo, sac, recurrent_ppo (sb3-contrib's RecurrentPPO: an LSTM policy, "
                   "memory across steps); appo with --engine rllib")
    p.add_argument("--seed", type=seed, default=0)
    p.add_argument("--out", required=True, type=output_dir, help="output directory")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--n-envs", type=positive_int, default=None, help="envs stepped together "
                   "(one learner: one-agent tasks, --mode scripted) or worlds (--mode shared: "
                   "one VecEnv slot per agent of each; --mode independent: each agent's model "
                   "a slot per world), in --n-cpus worker processes. Default: one per CPU "
                   "core (more per worker: faster, but PPO learnt reach less per step)")
    p.add_argument("--flat-obs", action="store_true", help="a learner with eyes sees one flat "
                   "vector (its images flattened, an MLP) instead of its images through the "
                   "CNN (docs/training_vision.md)")
    p.add_argument("--frame-stack", type=positive_int, default=None, help="frames of each eye "
                   "image the CNN sees at once (default 1): memory of the last k steps")
    p.add_argument("--obs-min-std", type=float, default=None, metavar="S", help="with "
                   "--normalize-obs: the running normaliser's scale is at least S (default 0: "
                   "none), so that inputs which only jitter (held joints) are not scaled up to "
                   "the size of the ones that move (docs/training.md)")
    p.add_argument("--normalize-reward", action="store_true", help="scale the rewards the "
                   "learner sees by a running estimate of the return's spread (SB3's "
                   "VecNormalize, saved as vecnormalize.pkl next to each model; evaluations "
                   "report the env's own returns); not with --mode independent")
    p.add_argument("--categorical-heads", action="store_true", help="PPO, A2C: the learner's "
                   "face (and voice) sampled as categorical choices beside its Gaussian motors "
                   "instead of as Gaussian logits (docs/training.md, 'Categorical heads')")
    p.add_argument("--worker-timeout", type=positive_float, default=None, metavar="SECONDS",
                   help="an env worker process that does not answer within this time is an "
                   "error naming it (default 600)")
    p.add_argument("--n-cpus", type=non_negative_int, default=None, help="spawned worker "
                   "processes stepping the --n-envs envs or worlds, each a block of them (0: all "
                   "in this process). Default: one per CPU core, at most one per env")
    c = p.add_argument_group("curriculum and demonstrations (one learner: a one-agent task or "
                             "--mode scripted; docs/training.md)")
    c.add_argument("--curriculum", default=None, metavar="NAME|FILE",
                   help="env options that change by stage as the run trains: a shipped "
                   "curriculum's name (e.g. selfbody) or a .toml / .json file; evaluations run "
                   "on its last stage")
    c.add_argument("--bc-episodes", type=non_negative_int, default=None, metavar="N",
                   help="behaviour-cloning warm start: N seeded episodes of the task's scripted "
                   "controller cloned into the policy before any RL step (default 0: none)")
    c.add_argument("--bc-epochs", type=positive_int, default=None,
                   help="epochs over the demonstrations (default 20)")
    c.add_argument("--bc-kwargs", type=json_object, default=None,
                   help="JSON settings of the warm start: batch_size (64), lr (1e-3), loss "
                   "(mse or nll), log_std (PPO: the log-std after cloning), critic_epochs (PPO: "
                   "epochs fitting the value function to the demonstrations' returns; 0)")
    c.add_argument("--intrinsic", choices=("rnd",), default=None,
                   help="an intrinsic novelty bonus added to the learner's rewards: rnd "
                   "(random network distillation; not --mode independent)")
    c.add_argument("--intrinsic-kwargs", type=json_object, default=None,
                   help='JSON settings of the bonus: coef (0.01), extrinsic (1.0; 0: a '
                   'reward-free run), lr (1e-3), hidden (64), seed (the run\'s)')
    c.add_argument("--growth", type=growth_spec, default=None, metavar="KIND:A-B[:STEPS]",
                   help="the infant's age as training goes (one-agent tasks): forward:1-12 "
                   "(1 to 12 months linearly over the run; :STEPS over that many env steps, "
                   "then 12), inverse:1-12 (12 down to 1), stochastic:1-12 (each episode's "
                   "age drawn uniformly from 1-12 by the env's seeded generator)")
    g = p.add_argument_group("RLlib engine (--engine rllib; needs the rllib extra)")
    g.add_argument("--engine", choices=("sb3", "rllib"), default="sb3",
                   help="sb3 (Stable-Baselines3, the default) or rllib (RLlib on Ray)")
    g.add_argument("--address", type=ray_address, default=None,
                   help="join this Ray cluster (auto or HOST:PORT; default: start a local Ray)")
    g.add_argument("--num-env-runners", type=non_negative_int, default=None,
                   help="env runner processes (default 1; 0: sample in this process)")
    g.add_argument("--num-envs-per-runner", type=positive_int, default=None,
                   help="envs stepped together in each runner (default 1)")
    g.add_argument("--num-cpus-per-learner", type=positive_int, default=None,
                   help="CPUs of the learner (default 1)")
    g.add_argument("--num-gpus-per-learner", type=non_negative_float, default=None,
                   help="GPUs of the learner (default 0; a fraction shares one)")
    p.set_defaults(func=_train_main)

    p = subparsers.add_parser("eval", help="run a trained policy (optionally record or film it)",
                              description="Reload the policy of a 'train' directory and run "
                              "episodes with it.")
    p.add_argument("dir", type=input_dir, help="a directory written by 'mimo-social train'")
    p.add_argument("--episodes", type=positive_int, default=10)
    p.add_argument("--model", default="final", help="final (model.zip), best (best_model.zip) "
                   "or a path to a .zip")
    p.add_argument("--seed", type=seed, default=0, help="seed of the first episode")
    p.add_argument("--stochastic", action="store_true", help="only the stochastic policy "
                   "(sampled actions; default: the deterministic and the stochastic policy)")
    p.add_argument("--deterministic", action="store_true", help="only the deterministic "
                   "policy (the mean action)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--record", default=None, type=output_file,
                   help="write a Rerun recording (.rrd)")
    p.add_argument("--video", default=None, type=output_file, help="write an MP4 video (needs "
                   "imageio with its ffmpeg plugin, in the train extra, or an ffmpeg program; "
                   "tried before the episodes start)")
    p.add_argument("--frames", default=None, type=output_dir, help="write every frame as a PNG "
                   "file into this directory")
    p.add_argument("--frame-every", type=positive_int, default=1, help="keep every k-th frame")
    p.add_argument("--env-kwargs", type=env_kwargs, default={},
                   help="JSON keyword arguments for the env, over those of the training run")
    p.add_argument("--ages", default=None, metavar="A,B,...",
                   help="a cross-age evaluation: the same episodes with the infant at each age "
                   "(months 0-33, e.g. 1,3,6,9,12), both policies; writes cross_age.csv, .md, "
                   ".png and .json into DIR (or --out) and prints the table")
    p.add_argument("--out", default=None, type=output_dir,
                   help="with --ages: the folder of the cross-age files (default: DIR)")
    p.set_defaults(func=_eval_main)

    p = subparsers.add_parser("compare", help="train several algorithms and seeds, plot them "
                              "together", description="Train each algorithm with several seeds "
                              "and plot the learning curves together over environment steps and "
                              "over wall time (the paper's Fig. 8). --algo-kwargs may give one "
                              "object per algorithm: '{\"ppo\": {\"n_steps\": 512}, "
                              "\"sac\": {}}'.")
    _common(p, steps_required=False)
    p.add_argument("--steps-per-algo", default=None, metavar="ALGO=STEPS,...",
                   help="a step budget per algorithm over --steps, e.g. ppo=100000,sac=20000 "
                   "(SAC costs far more per step than PPO)")
    p.add_argument("--algos", default="ppo,sac", help="comma-separated: ppo,sac,recurrent_ppo "
                   "(--engine rllib: ppo,appo,sac)")
    p.add_argument("--seeds", type=positive_int, default=3, help="seeds 0 .. n-1 per algorithm")
    p.add_argument("--out", required=True, type=output_dir,
                   help="output directory (one sub-directory a run)")
    p.add_argument("--jobs", type=positive_int, default=1, help="runs at a time, each in its own "
                   "process with torch on one thread (the runs' files are the same as with "
                   "--jobs 1, apart from wall times)")
    p.add_argument("--plot-only", action="store_true", help="only re-plot existing runs")
    g = p.add_argument_group("RLlib engine (--engine rllib: each run a Ray Tune trial; needs "
                             "the rllib extra, docs/scaling.md)")
    g.add_argument("--engine", choices=("sb3", "rllib"), default="sb3",
                   help="sb3 (Stable-Baselines3, the default) or rllib (RLlib, runs as Ray Tune "
                   "trials in parallel across the Ray cluster)")
    g.add_argument("--address", type=ray_address, default=None,
                   help="join this Ray cluster (auto or HOST:PORT; default: start a local Ray); "
                   "--out must then be on a file system every node writes to")
    g.add_argument("--num-cpus", type=positive_int, default=None,
                   help="CPUs of the local Ray started without --address (default: all)")
    g.add_argument("--max-concurrent", type=positive_int, default=None,
                   help="runs at a time at most (default: as many as the cluster's resources hold)")
    g.add_argument("--num-env-runners", type=non_negative_int, default=None,
                   help="env runner processes per run (default 1; 0: sample in the run's process)")
    g.add_argument("--num-envs-per-runner", type=positive_int, default=None,
                   help="envs stepped together in each runner (default 1)")
    g.add_argument("--num-cpus-per-learner", type=positive_int, default=None,
                   help="CPUs of each run's learner (default 1)")
    g.add_argument("--num-gpus-per-learner", type=non_negative_float, default=None,
                   help="GPUs of each run's learner (default 0; a fraction shares one)")
    p.set_defaults(func=_compare_main)
