"""Pilot (issue 30, twelfth session): clone the checking follower into an LSTM policy with wide,
foveated eyes, by sequences; the clone plays.

Arguments: demonstrator (``checking`` or ``scripted``), episodes, epochs, seq_len, seq_batch,
DART noise, episodes played, fovea, field of view (degrees) and, optionally, the
demonstrator's keyword arguments as JSON (README.md beside it). The learner:
RecurrentPPO's ``MultiInputLstmPolicy`` (the package's CNN before the LSTM, observations
normalised with the scale floored at 0.01), every step of every demonstration kept
(seeds 20000..), cloned at lr 3e-4 by sequences (``SequenceCloner`` of
mimo_social/train/sequence_cloning.py; the mean minibatch loss printed per epoch); then the
clone's mean action plays seeds 1000.. (its LSTM state carried through each episode) while the
demonstrator labels every state. Per episode as the feed-forward pilot prints
(``../joint_attention_checking_clone/ja_checking_clone.py``).
"""
import json
import sys
import time

import numpy as np
import torch
from sb3_contrib import RecurrentPPO
from stable_baselines3.common.vec_env import DummyVecEnv

from mimo_social.core.episodes import run_episode
from mimo_social.train.dagger import Labeller
from mimo_social.train.demonstrations import demonstrator, record_demonstrations
from mimo_social.train.encoders import policy_for
from mimo_social.train.envs import make_env
from mimo_social.train.sequence_cloning import SequenceCloner


class RecurrentLabeller(Labeller):
    """The labeller, the model's LSTM state carried through the episode; keeps the modes."""

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        self.modes, self.watching, self.played = [], [], []
        self.state, self.start = None, np.ones(1, bool)

    def act(self, env, agent, obs):
        super(Labeller, self).act(env, agent, obs)          # the controller's label, recorded
        batch = {k: v[None] for k, v in obs.items()}
        action, self.state = self.model.predict(batch, state=self.state,
                                                episode_start=self.start, deterministic=True)
        self.start = np.zeros(1, bool)
        self.played.append(action[0])
        c = self.controller
        self.modes.append(getattr(c, "mode", "follow"))
        if hasattr(c, "gaze_to_face_deg"):
            self.watching.append(c.gaze_to_face_deg(self.core.world.data) <= 5.0)
        return action[0]


def main():
    name, episodes, epochs, seq_len, seq_batch = sys.argv[1], *map(int, sys.argv[2:6])
    noise, play, fovea, fov = float(sys.argv[6]), int(sys.argv[7]), *map(float, sys.argv[8:10])
    ck = json.loads(sys.argv[10]) if len(sys.argv) > 10 else None
    task = "joint_attention"
    vision = {"width": 96, "height": 96, "fovea": fovea, "field_of_view": fov}
    kwargs = {"per_agent": [{"vision": vision}, {}]}
    torch.set_num_threads(1)
    env = make_env(task, **kwargs)
    venv = DummyVecEnv([lambda: make_env(task, **kwargs)])
    policy, kw = policy_for(venv.observation_space, {}, True, recurrent=True, min_std=0.01)
    model = RecurrentPPO(policy, venv, seed=0, device="cpu", **kw)
    t0 = time.time()
    demos = None
    for c in range(0, episodes, 10):
        d = record_demonstrations(task, env, min(10, episodes - c), 20_000 + c, ck, noise,
                                  demonstrator_name=name)
        demos = d if demos is None else demos.joined(d)
        print(f"recorded {c + len(d.seeds)} episodes, success {np.mean(demos.successes):.2f}, "
              f"{len(demos)} pairs, {time.time() - t0:.0f} s", flush=True)
    cloner = SequenceCloner(model, demos, seq_len, lr=3e-4)
    print(f"{len(cloner.seqs)} sequences of {seq_len}; loss before "
          f"{cloner.mean_loss(seq_batch):.4g}, {time.time() - t0:.0f} s", flush=True)
    rng = np.random.default_rng(0)
    for e in range(epochs):
        model.policy.set_training_mode(True)
        order, losses = rng.permutation(len(cloner.seqs)), []
        for k in range(0, len(order), seq_batch):
            chosen = [cloner.seqs[j] for j in order[k:k + seq_batch]]
            cloner.optimiser.zero_grad()
            loss = cloner.loss(chosen)
            loss.backward()
            cloner.optimiser.step()
            losses.append(float(loss.detach()))
        print(f"epoch {e + 1}: mean minibatch loss {np.mean(losses):.4g}, "
              f"{time.time() - t0:.0f} s", flush=True)
    print(f"loss after {cloner.mean_loss(seq_batch):.4g}, {time.time() - t0:.0f} s", flush=True)
    model.policy.set_training_mode(False)
    controller = demonstrator(task, {"demonstrator": name, "controller": ck})
    wins = []
    for seed in range(1000, 1000 + play):
        lab = RecurrentLabeller(controller, env, model)
        ep = run_episode(env, lab, seed)
        err = np.abs(np.stack(lab.played) - np.stack(lab.actions)).mean(1)
        modes = np.array(lab.modes)
        won = bool(ep.success(next(iter(ep.returns))))
        wins.append(won)
        share = {str(m): round(float(np.mean(modes == m)), 2) for m in np.unique(modes)}
        face = modes == "face"
        watch = (f", watching the face in face mode {np.mean(np.array(lab.watching)[face]):.2f}"
                 if lab.watching and np.any(face) else "")
        on = next(iter(ep.last_infos.values()))["on_target_fraction"]
        print(f"  seed {seed}: success {won}, on target {on:.2f}, return "
              f"{float(next(iter(ep.returns.values()))):.1f}, the labeller's modes {share}"
              f"{watch}, action error {err.mean():.3f}",
              flush=True)
    print(f"recurrent clone of {name}: {sum(wins)} / {play}, {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main()
