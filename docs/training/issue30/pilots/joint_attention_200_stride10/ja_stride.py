"""Pilot (issue 30): many demonstrations, every k-th pair kept, cloned; the clone plays.

Arguments: task, episodes, k, epochs, DART noise, episodes played (README.md beside it).
"""
import sys
import time

import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import DummyVecEnv

from mimo_social.core.episodes import run_episode
from mimo_social.train.dagger import Labeller
from mimo_social.train.demonstrations import (Demonstrations, clone, demonstrator,
                                              record_demonstrations)
from mimo_social.train.encoders import policy_for
from mimo_social.train.envs import make_env


def joined(parts):
    return Demonstrations(
        {k: np.concatenate([p.obs[k] for p in parts]) for k in parts[0].obs},
        np.concatenate([p.actions for p in parts]), np.concatenate([p.rewards for p in parts]),
        np.concatenate([p.ends for p in parts]), sum([p.seeds for p in parts], []),
        sum([p.returns for p in parts], []), sum([p.lengths for p in parts], []),
        sum([p.successes for p in parts], []))


def main():
    task, episodes, every, epochs = sys.argv[1], *map(int, sys.argv[2:5])
    noise, play = float(sys.argv[5]), int(sys.argv[6])
    torch.set_num_threads(1)
    env = make_env(task)
    venv = DummyVecEnv([lambda: make_env(task)])
    policy, kw = policy_for(venv.observation_space, {}, True, min_std=0.01)
    model = PPO(policy, venv, seed=0, device="cpu", **kw)
    t0 = time.time()
    parts = []
    for c in range(0, episodes, 20):
        d = record_demonstrations(task, env, min(20, episodes - c), 20_000 + c, {}, noise)
        keep = np.arange(len(d)) % every == (c // 20) % every
        parts.append(Demonstrations({k: v[keep] for k, v in d.obs.items()}, d.actions[keep],
                                    d.rewards[keep], d.ends[keep], d.seeds, d.returns,
                                    d.lengths, d.successes))
        rate = np.mean([s for p in parts for s in p.successes])
        print(f"recorded {c + 20} episodes, success {rate:.2f}, {time.time() - t0:.0f} s",
              flush=True)
    demos = joined(parts)
    del parts
    for e in range(epochs):
        fit = clone(model, demos, 1, lr=3e-4, seed=e)
        print(f"epoch {e + 1}: {len(demos)} pairs, loss {fit['loss_before']:.4g} -> "
              f"{fit['loss_after']:.4g}, {time.time() - t0:.0f} s", flush=True)
    controller = demonstrator(task, {})
    wins = 0
    for seed in range(1000, 1000 + play):
        lab = Labeller(controller, env, model)
        ep = run_episode(env, lab, seed)
        obs = {k: np.stack([o[k] for o in lab.obs]) for k in lab.obs[0]}
        pred, _ = model.predict(obs, deterministic=True)
        err = np.abs(pred - np.stack(lab.actions)).mean(1)
        won = bool(ep.success(next(iter(ep.returns))))
        wins += won
        per = [round(float(err[i:i + 100].mean()), 3) for i in range(0, len(err), 100)]
        print(f"  seed {seed}: success {won}, return "
              f"{float(next(iter(ep.returns.values()))):.1f}, error/100 steps {per}", flush=True)
    print(f"clone: {wins} / {play}")


if __name__ == "__main__":
    main()
