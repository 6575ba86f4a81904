"""The one-learner vector env: several envs per spawned worker give what envs in this process
give, and every VecEnv method reaches the env it names."""

from __future__ import annotations

import functools

import gymnasium as gym
import numpy as np
import pytest

from mimo_social.train.single import monitored_env
from mimo_social.train.workers import TimedSubprocVecEnv, blocks, one_learner_vec_env

SHORT = {"max_episode_steps": 20}


class Counter(gym.Env):
    """Observation: the steps since the reset and the last action; ends after 3 steps."""
    observation_space = gym.spaces.Box(-10, 10, (2,))
    action_space = gym.spaces.Box(-1, 1, (1,))
    tag = "none"

    def reset(self, seed=None, options=None):
        self.t = 0
        return np.zeros(2, np.float32), {"start": (options or {}).get("start", 0)}

    def step(self, action):
        self.t += 1
        return (np.array([self.t, action[0]], np.float32), float(self.t), self.t >= 3, False,
                {})

    def double(self, x):
        return 2 * x


def test_blocks_cover_every_env_once_in_order():
    for n in range(1, 12):
        for w in range(1, n + 1):
            b = blocks(n, w)
            assert [i for r in b for i in r] == list(range(n))
            assert max(map(len, b)) - min(map(len, b)) <= 1


def test_envs_in_two_workers_step_as_envs_in_this_process():
    fn = functools.partial(monitored_env, "reach", SHORT)
    here = one_learner_vec_env(fn, 5, n_workers=0)
    there = one_learner_vec_env(fn, 5, n_workers=2)
    try:
        assert isinstance(there, TimedSubprocVecEnv) and len(there.processes) == 2
        for v in (here, there):
            v.seed(7)
        a, b = here.reset(), there.reset()
        np.testing.assert_array_equal(a, b)
        rng = np.random.default_rng(0)
        ends = 0
        for _ in range(45):    # two episode ends in every env (auto-reset, terminal obs)
            act = rng.uniform(-1, 1, (5, *here.action_space.shape)).astype(np.float32)
            (o1, r1, d1, i1), (o2, r2, d2, i2) = here.step(act), there.step(act)
            np.testing.assert_array_equal(o1, o2)
            np.testing.assert_allclose(r1, r2)
            np.testing.assert_array_equal(d1, d2)
            for x, y in zip(i1, i2):
                assert x.keys() == y.keys()
                if "terminal_observation" in x:
                    ends += 1
                    np.testing.assert_array_equal(x["terminal_observation"],
                                                  y["terminal_observation"])
                    assert x["TimeLimit.truncated"] == y["TimeLimit.truncated"]
        assert ends == 10
    finally:
        here.close()
        there.close()


def test_methods_and_attributes_reach_the_envs_they_name():
    venv = TimedSubprocVecEnv([Counter] * 5, n_workers=2)
    try:
        venv.set_options([{"start": k} for k in range(5)])
        venv.reset()
        assert [i["start"] for i in venv.reset_infos] == list(range(5))
        venv.set_attr("tag", "set", indices=[1, 4])
        assert venv.get_attr("tag") == ["none", "set", "none", "none", "set"]
        assert venv.env_method("double", 3, indices=[4, 0]) == [6, 6]
        assert venv.env_is_wrapped(gym.Wrapper) == [False] * 5
        obs, rew, done, infos = venv.step(np.full((5, 1), 0.5, np.float32))
        assert obs.shape == (5, 2) and rew.tolist() == [1.0] * 5 and not done.any()
        for _ in range(2):
            obs, rew, done, infos = venv.step(np.zeros((5, 1), np.float32))
        assert done.all() and (obs == 0).all()       # reset after the third step
        assert all(i["terminal_observation"][0] == 3 for i in infos)
    finally:
        venv.close()


@pytest.mark.parametrize("n_workers", [-1, 4])
def test_more_workers_than_envs_is_refused(n_workers):
    with pytest.raises(ValueError, match=f"n_workers={n_workers}; allowed: 0 .in this process. "
                       "to n_envs .3."):
        one_learner_vec_env(Counter, 3, n_workers=n_workers)


def test_the_runner_refuses_more_worker_processes_than_envs(tmp_path):
    from mimo_social.train import train
    from mimo_social.train.tasks import TrainInputError
    with pytest.raises(TrainInputError, match="n_cpus=3; allowed: 0 .every env in this "
                       "process. to n_envs=2"):
        train("reach", "ppo", 64, 0, tmp_path / "run", n_envs=2, n_cpus=3)
    assert not (tmp_path / "run").exists()


def test_a_run_steps_one_env_per_core_by_default(tmp_path):
    import json

    from mimo_social.train import train
    from mimo_social.train.workers import default_n_envs, default_workers
    res = train("reach", "ppo", 64, 0, tmp_path, progress=False, env_kwargs=SHORT,
                algo_kwargs={"n_epochs": 1})
    config = json.loads((tmp_path / "config.json").read_text())
    assert config["n_envs"] == default_n_envs() == default_workers(10**6)
    assert config["n_cpus"] == default_workers(config["n_envs"])
    assert res["timesteps"] >= 64
