"""Pilot (issue 30): the seventh session's 200-episode clone of joint attention's follower, now
with the auxiliary label (``bc_kwargs`` ``aux_label="target"``: the toy the partner looks at);
the clone plays fresh episodes while the follower labels them.

Arguments: episodes, k (every k-th pair kept), epochs, DART noise, episodes played, aux weight
(0: none, the seventh session's pilot) (README.md beside it).
"""
import functools
import sys
import time

import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import DummyVecEnv

from mimo_social.core.episodes import run_episode
from mimo_social.train.auxiliary import features_and_distribution
from mimo_social.train.dagger import Labeller
from mimo_social.train.demonstrations import (Demonstrations, clone, demonstrator,
                                              record_demonstrations)
from mimo_social.train.encoders import policy_for
from mimo_social.train.envs import make_env

TASK = "joint_attention"


def kept(d: Demonstrations, keep) -> Demonstrations:
    return Demonstrations({k: v[keep] for k, v in d.obs.items()}, d.actions[keep],
                          d.rewards[keep], d.ends[keep], d.seeds, d.returns, d.lengths,
                          d.successes, None if d.labels is None else d.labels[keep])


def head_accuracy(model, obs, labels) -> float:
    """The auxiliary head's accuracy on these observations' labelled steps (the head kept for
    the policy by the cloning)."""
    from mimo_social.train.auxiliary import aux_head
    head = aux_head(model.policy, labels)
    right = total = 0
    for s in range(0, len(labels), 256):
        o = model.policy.obs_to_tensor({k: v[s:s + 256] for k, v in obs.items()})[0]
        with torch.no_grad():
            latent, _ = features_and_distribution(model.policy, o)
        r, n = head.accuracy(latent, labels[s:s + 256])
        right, total = right + r, total + n
    return right / max(1, total)


def main():
    episodes, every, epochs = map(int, sys.argv[1:4])
    noise, play, weight = float(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6])
    torch.set_num_threads(1)
    env = make_env(TASK)
    venv = DummyVecEnv([lambda: make_env(TASK)])
    policy, kw = policy_for(venv.observation_space, {}, True, min_std=0.01)
    model = PPO(policy, venv, seed=0, device="cpu", **kw)
    t0 = time.time()
    parts = []
    for c in range(0, episodes, 20):
        d = record_demonstrations(TASK, env, min(20, episodes - c), 20_000 + c, {}, noise,
                                  aux_label="target")
        parts.append(kept(d, np.arange(len(d)) % every == (c // 20) % every))
        rate = np.mean([s for p in parts for s in p.successes])
        print(f"recorded {c + 20} episodes, success {rate:.2f}, {time.time() - t0:.0f} s",
              flush=True)
    demos = functools.reduce(Demonstrations.joined, parts)
    del parts
    if weight == 0:
        demos.labels = None
    for e in range(epochs):
        fit = clone(model, demos, 1, lr=3e-4, seed=e, aux_weight=weight or 1.0)
        acc = fit.get("aux_accuracy_after")
        print(f"epoch {e + 1}: {len(demos)} pairs, loss {fit['loss_before']:.4g} -> "
              f"{fit['loss_after']:.4g}" + ("" if acc is None else f", head {acc:.2f}")
              + f", {time.time() - t0:.0f} s", flush=True)
    controller = demonstrator(TASK, {})
    wins = 0
    for seed in range(1000, 1000 + play):
        lab = Labeller(controller, env, model, "target")
        ep = run_episode(env, lab, seed, on_step=lab.on_step)
        obs = {k: np.stack([o[k] for o in lab.obs]) for k in lab.obs[0]}
        pred, _ = model.predict(obs, deterministic=True)
        err = np.abs(pred - np.stack(lab.actions)).mean(1)
        won = bool(ep.success(next(iter(ep.returns))))
        wins += won
        labels = np.asarray(lab.labels)
        reading = "" if weight == 0 else f", head {head_accuracy(model, obs, labels):.2f}"
        per = [round(float(err[i:i + 100].mean()), 3) for i in range(0, len(err), 100)]
        print(f"  seed {seed}: success {won}, return "
              f"{float(next(iter(ep.returns.values()))):.1f}{reading} (labelled steps "
              f"{int((labels >= 0).sum())}), error/100 steps {per}", flush=True)
    print(f"clone: {wins} / {play}")


if __name__ == "__main__":
    main()
