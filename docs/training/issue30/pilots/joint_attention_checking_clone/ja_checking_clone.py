"""Pilot (issue 30, twelfth session): clone a joint-attention demonstrator into foveated eyes.

Arguments: demonstrator (``scripted`` or ``checking``), episodes, k (every k-th pair kept),
epochs, DART noise, episodes played, fovea and, optionally, the eyes' field of view in degrees
(default 60; README.md beside it). The learner's eyes: 96x96 with the given fovea; the demonstrations' seeds 20000.., the clone's mean action plays 1000.. while
the demonstrator labels every state. Per episode: success, the share of target steps on target,
the action error (mean absolute) in each of the labeller's modes and, in ``face`` mode, how
often the clone's gaze is within 5 degrees of the partner's face.
"""
import sys
import time

import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import DummyVecEnv

from mimo_social.core.episodes import run_episode
from mimo_social.train.dagger import Labeller
from mimo_social.train.demonstrations import clone, demonstrator, record_demonstrations
from mimo_social.train.encoders import policy_for
from mimo_social.train.envs import make_env


class ModeLabeller(Labeller):
    """The labeller, keeping its controller's mode and whether the learner watches the face."""

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        self.modes, self.watching = [], []

    def act(self, env, agent, obs):
        action = super().act(env, agent, obs)
        c = self.controller
        self.modes.append(getattr(c, "mode", "follow"))
        if hasattr(c, "gaze_to_face_deg"):
            self.watching.append(c.gaze_to_face_deg(self.core.world.data) <= 5.0)
        return action


def setup(fovea: float, fov: float | None):
    """The joint-attention env with the learner's 96x96 eyes (``fovea``, ``fov`` degrees) and a
    fresh PPO model on the recipe's CNN policy."""
    task = "joint_attention"
    vision = {"width": 96, "height": 96, "fovea": fovea, "field_of_view": fov}
    kwargs = {"per_agent": [{"vision": vision}, {}]}
    torch.set_num_threads(1)
    env = make_env(task, **kwargs)
    venv = DummyVecEnv([lambda: make_env(task, **kwargs)])
    policy, kw = policy_for(venv.observation_space, {}, True, min_std=0.01)
    return env, PPO(policy, venv, seed=0, device="cpu", **kw)


def record(env, name: str, episodes: int, every: int, noise: float, t0: float):
    """``episodes`` demonstrations of ``name`` (seeds 20000..), every ``every``-th pair kept."""
    demos = None
    for c in range(0, episodes, 20):
        d = record_demonstrations("joint_attention", env, min(20, episodes - c), 20_000 + c,
                                  None, noise, demonstrator_name=name)
        keep = np.arange(len(d)) % every == (c // 20) % every
        d = type(d)({k: v[keep] for k, v in d.obs.items()}, d.actions[keep], d.rewards[keep],
                    d.ends[keep], d.seeds, d.returns, d.lengths, d.successes)
        demos = d if demos is None else demos.joined(d)
        print(f"recorded {c + len(d.seeds)} episodes, success {np.mean(demos.successes):.2f}, "
              f"{len(demos)} pairs, {time.time() - t0:.0f} s", flush=True)
    return demos


def clone_epochs(model, demos, epochs: int, t0: float) -> None:
    """``epochs`` epochs of cloning at lr 3e-4 (epoch e seeded e), a line each."""
    for e in range(epochs):
        fit = clone(model, demos, 1, lr=3e-4, seed=e)
        print(f"epoch {e + 1}: {len(demos)} pairs, loss {fit['loss_before']:.4g} -> "
              f"{fit['loss_after']:.4g}, {time.time() - t0:.0f} s", flush=True)


def evaluate(model, env, name: str, play: int) -> int:
    """The clone's mean action on seeds 1000.. with ``name`` labelling every state; a line per
    episode; the successes."""
    controller = demonstrator("joint_attention", {"demonstrator": name})
    wins = []
    for seed in range(1000, 1000 + play):
        lab = ModeLabeller(controller, env, model)
        ep = run_episode(env, lab, seed)
        obs = {k: np.stack([o[k] for o in lab.obs]) for k in lab.obs[0]}
        pred, _ = model.predict(obs, deterministic=True)
        err = np.abs(pred - np.stack(lab.actions)).mean(1)
        modes = np.array(lab.modes)
        won = bool(ep.success(next(iter(ep.returns))))
        wins.append(won)
        per_mode = {str(m): round(float(err[modes == m].mean()), 3) for m in np.unique(modes)}
        share = {str(m): round(float(np.mean(modes == m)), 2) for m in np.unique(modes)}
        face = modes == "face"
        watch = (f", watching the face in face mode {np.mean(np.array(lab.watching)[face]):.2f}"
                 if lab.watching and np.any(face) else "")
        on = next(iter(ep.last_infos.values()))["on_target_fraction"]
        print(f"  seed {seed}: success {won}, on target {on:.2f},"
              f" return {float(next(iter(ep.returns.values()))):.1f}, modes {share}, action "
              f"error per mode {per_mode}{watch}", flush=True)
    return sum(wins)


def main():
    name, episodes, every, epochs = sys.argv[1], *map(int, sys.argv[2:5])
    noise, play, fovea = float(sys.argv[5]), int(sys.argv[6]), float(sys.argv[7])
    fov = float(sys.argv[8]) if len(sys.argv) > 8 else None
    env, model = setup(fovea, fov)
    t0 = time.time()
    demos = record(env, name, episodes, every, noise, t0)
    clone_epochs(model, demos, epochs, t0)
    wins = evaluate(model, env, name, play)
    print(f"clone of {name}: {wins} / {play}, {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main()
