"""Does a clone act as its demonstrator where it plays itself? Clone, then play the clone.

A warm start's clone can fit its pairs to a tiny loss and still fail every fresh episode: an
input the demonstrations never vary (a held joint's jitter) lets the network tell the pairs
apart without what matters. This script measures it before any RL step: it records
``--episodes`` episodes of the task's catalogue controller (made with ``--controller``, as
``bc_kwargs`` ``controller`` makes it; its actions perturbed by ``--noise``, DART, as
``bc_kwargs`` ``noise``), clones them ``--epochs`` epochs into the policy a run builds (the
task's eyes through the CNN, ``--normalize-obs`` / ``--obs-min-std`` as in ``train``), then
lets the clone's mean action play ``--play`` fresh episodes (seeds ``--seed`` onwards) while
the controller labels every state it meets (DAgger's labeller). It prints per episode the
clone's success, length and its mean action error (the clone's action minus the label,
mean absolute, per 50 steps), and the success rate. docs/training.md cites:

    python3 scripts/clone_play.py imitation --controller '{"prepare": 0.5, "move_s": 0.02}' \
        --noise 0.1 --epochs 20 --lr 3e-4 --obs-min-std 0.01
    python3 scripts/clone_play.py imitation --controller '{"prepare": 0.5, "move_s": 0.02}' \
        --noise 0.1 --epochs 20 --lr 3e-4 --obs-min-std 0
    python3 scripts/clone_play.py joint_attention --epochs 5 --lr 3e-4 --obs-min-std 0.01 --play 5
"""

from __future__ import annotations

import argparse
import json

import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import DummyVecEnv

from mimo_social.cli._args import env_kwargs
from mimo_social.core.episodes import run_episode
from mimo_social.train.dagger import Labeller
from mimo_social.train.demonstrations import clone, demonstrator, record_demonstrations
from mimo_social.train.encoders import policy_for
from mimo_social.train.envs import make_env


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("task")
    p.add_argument("--controller", type=json.loads, default={},
                   help="JSON keyword arguments of the task's controller")
    p.add_argument("--demonstrator", default=None,
                   help="one of the task's named controllers (bc_kwargs demonstrator)")
    p.add_argument("--episodes", type=int, default=20, help="demonstrations cloned")
    p.add_argument("--noise", type=float, default=0.0, help="DART noise on the demonstrator")
    p.add_argument("--epochs", type=int, default=20)
    p.add_argument("--lr", type=float, default=1e-3, help="the cloning's learning rate")
    p.add_argument("--normalize-obs", action=argparse.BooleanOptionalAction, default=True)
    p.add_argument("--obs-min-std", type=float, default=0.0)
    p.add_argument("--play", type=int, default=20, help="fresh episodes the clone plays")
    p.add_argument("--seed", type=int, default=1000)
    p.add_argument("--env-kwargs", type=env_kwargs, default={},
                   help="JSON keyword arguments of the learner's env (a recipe's env_kwargs)")
    a = p.parse_args(argv)
    torch.set_num_threads(1)
    env = make_env(a.task, **a.env_kwargs)
    venv = DummyVecEnv([lambda: make_env(a.task, **a.env_kwargs)])
    policy, kw = policy_for(venv.observation_space, {}, a.normalize_obs,
                            min_std=a.obs_min_std if a.normalize_obs else 0.0)
    model = PPO(policy, venv, seed=0, device="cpu", **kw)
    demos = record_demonstrations(a.task, env, a.episodes, 20_000, a.controller, a.noise,
                                  demonstrator_name=a.demonstrator)
    fit = clone(model, demos, a.epochs, lr=a.lr, seed=0)
    print(f"{a.task}: {len(demos)} pairs from {a.episodes} episodes (noise {a.noise}), "
          f"{a.epochs} epochs at lr {a.lr:g}: {fit['loss']} loss {fit['loss_before']:.4g} -> "
          f"{fit['loss_after']:.4g}; normalize_obs {a.normalize_obs}, obs_min_std "
          f"{a.obs_min_std}", flush=True)
    controller = demonstrator(a.task, {"controller": a.controller,
                                       "demonstrator": a.demonstrator})
    wins = 0
    for seed in range(a.seed, a.seed + a.play):
        lab = Labeller(controller, env, model)
        ep = run_episode(env, lab, seed)
        obs = ({k: np.stack([o[k] for o in lab.obs]) for k in lab.obs[0]}
               if isinstance(lab.obs[0], dict) else np.stack(lab.obs))
        pred, _ = model.predict(obs, deterministic=True)
        err = np.abs(pred - np.stack(lab.actions)).mean(1)
        won = bool(ep.success(next(iter(ep.returns))))
        wins += won
        print(f"  seed {seed}: success {won}, length {ep.length}, action error per 50 steps "
              f"{[round(float(err[i:i + 50].mean()), 3) for i in range(0, len(err), 50)]}",
              flush=True)
    print(f"the clone's mean action: success {wins} / {a.play} "
          f"(seeds {a.seed}-{a.seed + a.play - 1})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
