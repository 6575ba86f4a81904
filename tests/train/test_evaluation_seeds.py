"""``evaluate`` seeds episode k of an n-episode evaluation with ``seed + k``: it equals a one-episode
evaluation at ``seed + k`` (single-agent, and multi-agent in each mode), and the episodes differ
from one another (one seed reused for every episode would make them all the same)."""

from __future__ import annotations

import pytest
import torch

from mimo_social.train import evaluate, make_env, make_parallel_env, train

torch.set_num_threads(1)

TINY = {"n_steps": 32, "batch_size": 32, "n_epochs": 1}
SEED, EPISODES = 7, 3


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("eval_seeds")
    out = {}
    # one learner: reach (the ball is placed at random at reset)
    out["reach"] = root / "reach"
    train("reach", "ppo", 32, 0, out["reach"], eval_every=10 ** 6, eval_episodes=1,
          checkpoint_every=10 ** 6, progress=False, env_kwargs={"max_steps": 12},
          algo_kwargs=TINY)
    # two infants (high five: the partners are placed at random at reset), each mode
    for mode in ("shared", "independent", "scripted"):
        out[mode] = root / mode
        train("high_five", "ppo", 32, 0, out[mode], mode=mode, eval_every=10 ** 6,
              eval_episodes=1, checkpoint_every=10 ** 6, progress=False,
              env_kwargs={"max_steps": 12}, algo_kwargs=TINY)
    return out


def _episodes(res):
    """Per episode: the returns (per agent for a multi-agent run) and length."""
    if "agents" in res:
        return [tuple((a, d["returns"][k], d["lengths"][k]) for a, d in sorted(res["agents"].items()))
                for k in range(len(res["returns"]))]
    return list(zip(res["returns"], res["lengths"]))


@pytest.mark.parametrize("kind", ["reach", "shared", "independent", "scripted"])
def test_episode_k_equals_a_one_episode_evaluation_at_seed_plus_k(runs, kind):
    run = runs[kind]
    many = _episodes(evaluate(run, episodes=EPISODES, seed=SEED))
    assert len(many) == EPISODES
    singles = [_episodes(evaluate(run, episodes=1, seed=SEED + k))[0] for k in range(EPISODES)]
    assert many == singles
    # and the seeds make a difference: the episodes are not copies of one another
    assert len(set(many)) == EPISODES, many


def test_the_evaluation_reports_its_seed_and_is_repeatable(runs):
    a = evaluate(runs["shared"], episodes=2, seed=SEED)
    b = evaluate(runs["shared"], episodes=2, seed=SEED)
    assert a["seed"] == SEED and _episodes(a) == _episodes(b)
    c = evaluate(runs["shared"], episodes=2, seed=SEED + 100)
    assert _episodes(c) != _episodes(a)


def test_episode_k_is_the_env_reset_with_seed_plus_k(runs):
    """The reference without the evaluation's code: the reloaded policies stepped by hand on an
    env reset with ``seed + k`` give the returns the evaluation reports for episode k."""
    from stable_baselines3 import PPO

    res = evaluate(runs["reach"], episodes=2, seed=SEED)
    model = PPO.load(str(runs["reach"] / "model.zip"), device="cpu")
    env = make_env("reach", max_steps=12)
    for k in range(2):
        obs, _ = env.reset(seed=SEED + k)
        total, done = 0.0, False
        while not done:
            obs, r, term, trunc, _ = env.step(model.predict(obs, deterministic=True)[0])
            total, done = total + float(r), term or trunc
        assert res["returns"][k] == total
    env.close()

    res = evaluate(runs["shared"], episodes=2, seed=SEED)
    model = PPO.load(str(runs["shared"] / "model.zip"), device="cpu")
    env = make_parallel_env("high_five", max_steps=12)
    for k in range(2):
        obs, _ = env.reset(seed=SEED + k)
        totals = dict.fromkeys(env.possible_agents, 0.0)
        while env.agents:
            acts = {a: model.predict(obs[a], deterministic=True)[0] for a in env.agents}
            obs, rew, *_ = env.step(acts)
            for a, r in rew.items():
                totals[a] += float(r)
        for a, t in totals.items():
            assert res["agents"][a]["returns"][k] == t
    env.close()
