"""The RND intrinsic bonus (issue 30): non-zero, seeded, falling for what recurs, on flat and
image observations, in a training run, refused where it does not apply."""

from __future__ import annotations

import functools
import json

import numpy as np
import pytest
from stable_baselines3.common.vec_env import DummyVecEnv

from mimo_social.train import train
from mimo_social.train.intrinsic import RNDBonus, check_intrinsic
from mimo_social.train.single import monitored_env
from mimo_social.train.tasks import TrainInputError

SHORT = {"max_episode_steps": 30}


def _venv(task="reach", n=2, **kw):
    return DummyVecEnv([functools.partial(monitored_env, task, {**SHORT, **kw})] * n)


def _rollout(settings, steps=25, task="reach"):
    venv = RNDBonus(_venv(task), settings)
    venv.seed(3)
    venv.reset()
    rng = np.random.default_rng(0)
    out = []
    for _ in range(steps):
        act = np.stack([venv.action_space.sample() for _ in range(venv.num_envs)]) \
            if task != "reach" else rng.uniform(-1, 1, (2, *venv.action_space.shape))
        obs, rew, done, infos = venv.step(act.astype(np.float32) if task == "reach" else act)
        out.append((rew.copy(), [i["intrinsic_reward"] for i in infos],
                    [i["extrinsic_reward"] for i in infos]))
    venv.close()
    return out


def test_the_bonus_is_positive_seeded_and_added_to_the_task_reward():
    a = _rollout(check_intrinsic({"kind": "rnd", "coef": 0.5}, seed=1))
    b = _rollout(check_intrinsic({"kind": "rnd", "coef": 0.5}, seed=1))
    c = _rollout(check_intrinsic({"kind": "rnd", "coef": 0.5}, seed=2))
    bonus = np.array([x[1] for x in a])
    assert (bonus > 0).all() and np.isfinite(bonus).all()
    for (r1, i1, e1), (r2, i2, e2) in zip(a, b):
        np.testing.assert_array_equal(r1, r2)
        np.testing.assert_allclose(r1, np.array(e1) + 0.5 * np.array(i1), rtol=1e-5, atol=1e-6)
    assert not np.allclose(bonus, np.array([x[1] for x in c]))


def test_a_reward_free_run_sees_the_bonus_only():
    run = _rollout(check_intrinsic({"kind": "rnd", "coef": 1.0, "extrinsic": 0.0}, seed=0))
    for rew, intr, extr in run:
        np.testing.assert_allclose(rew, intr, rtol=1e-5)
        assert any(e != 0 for e in extr)           # the task still pays; the learner sees none


def test_the_bonus_falls_for_an_observation_that_recurs():
    venv = RNDBonus(_venv(), check_intrinsic("rnd", seed=0))
    obs = venv.reset()
    raw = [float(venv.bonus(obs).mean()) for _ in range(200)]
    venv.close()
    assert raw[-1] < 0.2 * raw[0]


def test_image_observations_are_pooled_and_scored():
    venv = RNDBonus(_venv("mirror", n=2), check_intrinsic("rnd", seed=0))
    assert venv.features.n < 2 * 3 * 16 * 16 + 10_000      # images pooled to 16 px at most
    venv.reset()
    for _ in range(3):
        _, _, _, infos = venv.step(np.array([0, 1]))
    assert all(i["intrinsic_reward"] > 0 for i in infos)
    venv.close()


def test_a_run_with_the_bonus_records_it(tmp_path):
    res = train("reach", "ppo", 128, 0, tmp_path, progress=False, env_kwargs=SHORT,
                algo_kwargs={"n_steps": 64, "batch_size": 64, "n_epochs": 1}, n_envs=2,
                n_cpus=0, intrinsic={"kind": "rnd", "coef": 0.1})
    config = json.loads((tmp_path / "config.json").read_text())
    assert config["intrinsic"] == {"kind": "rnd", "coef": 0.1, "extrinsic": 1.0, "lr": 1e-3,
                                   "hidden": 64, "seed": 0}
    assert res["timesteps"] == 128


@pytest.mark.parametrize("intrinsic, match", [
    ("curiosity", r"intrinsic kind='curiosity'; allowed: \['rnd'\]"),
    ({"kind": "rnd", "coef": -1}, r"intrinsic coef=-1; allowed: a finite number >= 0"),
    ({"kind": "rnd", "lr": 0}, r"intrinsic lr=0; allowed: a finite number > 0"),
    ({"kind": "rnd", "beta": 1}, r"unknown setting\(s\) \['beta'\]"),
    ({"coef": 0.1}, r"intrinsic kind=None"),
    (3, r"intrinsic=3; allowed: None, 'rnd' or a mapping"),
])
def test_bad_settings_are_refused_before_anything_is_written(tmp_path, intrinsic, match):
    with pytest.raises(TrainInputError, match=match):
        train("reach", "ppo", 64, 0, tmp_path / "run", intrinsic=intrinsic)
    assert not (tmp_path / "run").exists()


def test_the_independent_mode_refuses_the_bonus(tmp_path):
    with pytest.raises(TrainInputError, match="not --mode independent"):
        train("high_five", "ppo", 64, 0, tmp_path / "run", mode="independent", intrinsic="rnd")
    assert not (tmp_path / "run").exists()


def test_the_command_line_passes_the_bonus_and_its_settings(tmp_path):
    from mimo_social import cli
    assert cli.main(["train", "--task", "reach", "--algo", "ppo", "--steps", "64", "--out",
                     str(tmp_path), "--no-progress", "--n-envs", "1", "--env-kwargs",
                     '{"max_steps": 30}', "--algo-kwargs",
                     '{"n_steps": 64, "batch_size": 64, "n_epochs": 1}', "--intrinsic", "rnd",
                     "--intrinsic-kwargs", '{"coef": 0.2, "extrinsic": 0}']) == 0
    config = json.loads((tmp_path / "config.json").read_text())
    assert (config["intrinsic"]["coef"], config["intrinsic"]["extrinsic"]) == (0.2, 0.0)
