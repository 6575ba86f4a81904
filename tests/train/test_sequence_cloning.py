"""Behaviour cloning of a recurrent policy by sequences (mimo_social/train/sequence_cloning.py):
the episodes cut into sequences, an LSTM clone that carries a cue seen only at an episode's first
step (a feed-forward clone cannot), and a recurrent_ppo run's warm start."""

from __future__ import annotations

import json

import numpy as np
import torch
from gymnasium import Env, spaces

from mimo_social.train import train
from mimo_social.train.demonstrations import Demonstrations, clone
from mimo_social.train.sequence_cloning import sequences

torch.set_num_threads(1)


def test_each_episode_is_cut_into_consecutive_sequences():
    ends = np.zeros(12, bool)
    ends[[4, 11]] = True                       # episodes of 5 and 7 pairs
    got = [list(s) for s in sequences(ends, 3)]
    assert got == [[0, 1, 2], [3, 4], [5, 6, 7], [8, 9, 10], [11]]
    unfinished = [list(s) for s in sequences(np.zeros(4, bool), 3)]
    assert unfinished == [[0, 1, 2], [3]]


class CueEnv(Env):
    """A cue (+1 or -1) in the observation at an episode's first step only, then zeros."""

    observation_space = spaces.Box(-1.0, 1.0, (2,), np.float32)
    action_space = spaces.Box(-1.0, 1.0, (1,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t = 0
        return np.zeros(2, np.float32), {}

    def step(self, action):
        self.t += 1
        return np.zeros(2, np.float32), 0.0, False, self.t >= 20, {}


def cue_demonstrations(episodes: int, length: int, rng) -> Demonstrations:
    """Each episode: the cue at its first step (and a marker of the first step), the action
    the cue at every step."""
    cues = rng.choice([-1.0, 1.0], episodes)
    obs = np.zeros((episodes, length, 2), np.float32)
    obs[:, 0, 0], obs[:, 0, 1] = cues, 1.0
    actions = np.repeat(cues[:, None], length, axis=1)[..., None].astype(np.float32)
    ends = np.zeros((episodes, length), bool)
    ends[:, -1] = True
    n = episodes * length
    return Demonstrations(obs.reshape(n, 2), actions.reshape(n, 1), np.zeros(n), ends.ravel(),
                          list(range(episodes)), [0.0] * episodes, [length] * episodes,
                          [None] * episodes)


def recalled(model, cues, length: int) -> np.ndarray:
    """The model's mean action at each episode's last step, the cue shown at its first."""
    out = []
    for c in cues:
        state, start = None, np.ones(1, bool)
        for t in range(length):
            obs = np.array([c, 1.0] if t == 0 else [0.0, 0.0], np.float32)
            a, state = model.predict(obs[None], state=state, episode_start=start,
                                     deterministic=True)
            start = np.zeros(1, bool)
        out.append(float(a[0, 0]))
    return np.array(out)


def test_an_lstm_clone_carries_a_cue_seen_at_the_first_step_and_a_feed_forward_one_cannot():
    from sb3_contrib import RecurrentPPO
    from stable_baselines3 import PPO

    demos = cue_demonstrations(64, 12, np.random.default_rng(0))
    lstm = RecurrentPPO("MlpLstmPolicy", CueEnv(), seed=0, device="cpu",
                        policy_kwargs={"lstm_hidden_size": 16})
    fit = clone(lstm, demos, 150, lr=3e-3, seed=0, seq_len=128, seq_batch=8)
    assert fit["loss"] == "mse, by sequences" and fit["sequences"] == 64
    assert fit["loss_after"] < 0.1 * fit["loss_before"]
    cues = np.array([1.0, -1.0, -1.0, 1.0])
    assert np.all(np.sign(recalled(lstm, cues, 12)) == cues)
    ff = PPO("MlpPolicy", CueEnv(), seed=0, device="cpu")
    flat = clone(ff, demos, 30, lr=3e-3, seed=0)
    assert flat["loss_after"] > 0.5            # at later steps the cue is gone: mean 0, error 1
    assert flat["loss_after"] > 5 * fit["loss_after"]


def test_a_recurrent_run_clones_by_sequences_before_any_rl_step(tmp_path):
    out = tmp_path / "run"
    train("reach", "recurrent_ppo", 256, 0, out, progress=False, eval_episodes=1,
          algo_kwargs={"n_steps": 128, "n_epochs": 1, "batch_size": 128},
          env_kwargs={"max_steps": 40}, bc_episodes=3, bc_epochs=2,
          bc_kwargs={"seq_len": 16, "seq_batch": 2, "log_std": -1.0})
    bc = json.loads((out / "config.json").read_text())["bc"]
    assert bc["loss"] == "mse, by sequences" and bc["seq_len"] == 16
    # each episode (at most 40 steps; a reach ends early) in pieces of at most 16
    assert bc["samples"] / 16 <= bc["sequences"] <= 3 * 3 and bc["sequences"] >= 3
    assert bc["loss_after"] < bc["loss_before"]
    assert bc["updates"] == 2 * -(-bc["sequences"] // 2)   # 2 epochs of 2 sequences a batch


def test_kept_cloning_of_a_recurrent_policy_draws_sequences_and_pulls_it_back():
    from sb3_contrib import RecurrentPPO

    from mimo_social.train.demonstrations import keep_cloning
    from mimo_social.train.sequence_cloning import SequenceCloner

    demos = cue_demonstrations(32, 12, np.random.default_rng(1))
    lstm = RecurrentPPO("MlpLstmPolicy", CueEnv(), seed=0, device="cpu",
                        policy_kwargs={"lstm_hidden_size": 16})
    settings = {"keep_updates": 60, "keep_until": 1.0, "lr": 3e-3, "loss": "mse",
                "batch_size": 64, "seq_len": 12, "seq_batch": 8}
    cb = keep_cloning(lstm, demos, settings, 1000, 0)
    cb.init_callback(lstm)
    loss = SequenceCloner(lstm, demos, 12).mean_loss
    before = loss(8)
    for t in (0, 0, 0, 0, 0):        # the first rollout's start makes none, then 60 each
        lstm.num_timesteps = t
        cb.on_rollout_start()
    assert cb.updates == 4 * 60
    assert loss(8) < 0.5 * before
    assert np.all(np.sign(recalled(lstm, np.array([1.0, -1.0]), 12)) == [1.0, -1.0])


def test_a_recurrent_run_keeps_cloning_during_rl_when_asked(tmp_path):
    out = tmp_path / "run"
    train("reach", "recurrent_ppo", 512, 0, out, progress=False, eval_episodes=1,
          algo_kwargs={"n_steps": 128, "n_epochs": 1, "batch_size": 128},
          env_kwargs={"max_steps": 40}, bc_episodes=3, bc_epochs=2,
          bc_kwargs={"seq_len": 16, "seq_batch": 2, "keep_updates": 4, "keep_until": 1.0})
    bc = json.loads((out / "config.json").read_text())["bc"]
    # after each update 4 x (1 - t / 512) sequences minibatches (t: SB3's timesteps then)
    assert bc["keep_updates"] == 4 and 1 <= bc["keep_updates_made"] <= 3 + 2 + 1
