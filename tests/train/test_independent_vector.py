"""``--mode independent`` on several worlds: one SB3 model per agent, each on a VecEnv with a
slot per world (:mod:`mimo_social.train.independent`), the worlds in this process or in spawned
worker processes (:class:`~mimo_social.train.independent.WorldBatch`)."""

import csv
import functools
import json
import os
import signal
import threading
import time

import numpy as np
import pytest
import torch
from gymnasium import spaces
from pettingzoo import ParallelEnv

from mimo_social.train import LockstepError, TrainInputError, read_progress, run_lockstep, train
from mimo_social.train.independent import WorldBatch, agent_vec_env
from mimo_social.train.lockstep import VecLockstep

torch.set_num_threads(1)

FAST = {"n_steps": 64, "batch_size": 32, "n_epochs": 1}
SHORT = {"max_steps": 30}
STEPS = 256            # 128 batch steps of two worlds: episodes end at env steps 60, 120, ...
AGENTS = ["infant_0", "infant_1"]


def _run(out, n_cpus, seed=0, steps=STEPS, **kwargs):
    kw = dict(mode="independent", n_envs=2, n_cpus=n_cpus, eval_every=128, eval_episodes=1,
              checkpoint_every=128, progress=False, env_kwargs=SHORT, algo_kwargs=FAST)
    return train("high_five", "ppo", steps, seed, out, **{**kw, **kwargs})


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("independent_vector")
    return {n_cpus: (root / f"cpus{n_cpus}", _run(root / f"cpus{n_cpus}", n_cpus))
            for n_cpus in (0, 2)}


def _params(path):
    from stable_baselines3 import PPO
    return {k: v.clone() for k, v in PPO.load(str(path), device="cpu").policy.state_dict().items()}


def _same_models(a, b) -> bool:
    pa, pb = _params(a), _params(b)
    return all(torch.equal(pa[k], pb[k]) for k in pa)


def _episodes(out):
    with open(out / "episodes.csv", newline="") as f:
        return list(csv.DictReader(f))


# -- training on two worlds ---------------------------------------------------------------------
@pytest.mark.parametrize("n_cpus", [0, 2])
def test_two_worlds_train_a_model_per_agent_and_log_every_worlds_episodes(runs, n_cpus):
    out, res = runs[n_cpus]
    for name in [f"model_{a}.zip" for a in AGENTS] + [f"best_model_{a}.zip" for a in AGENTS]:
        assert (out / name).stat().st_size > 0, name
    assert sorted(q.name for q in (out / "checkpoints").iterdir()) == sorted(
        f"model_{a}_{n}_steps.zip" for a in AGENTS for n in (128, 256))
    config = json.loads((out / "config.json").read_text())
    assert config["mode"] == "independent" and config["agents"] == AGENTS
    assert (config["n_envs"], config["n_cpus"]) == (2, n_cpus)
    assert config["timesteps_done"] == STEPS == res["timesteps"]   # env steps, both worlds
    assert list(read_progress(out / "progress.csv")["timesteps"]) == [128, 256]
    from stable_baselines3 import PPO
    for a in AGENTS:
        model = PPO.load(str(out / f"model_{a}.zip"), device="cpu")
        assert model.n_envs == 2 and model.num_timesteps == STEPS and model.n_steps == 64
    episodes = _episodes(out)
    for a in AGENTS:   # both worlds end an episode every 30 batch steps = 60 env steps
        mine = [e for e in episodes if e["agent"] == a]
        assert [int(e["timesteps"]) for e in mine] == [60, 60, 120, 120, 180, 180, 240, 240]
        assert all(int(e["length"]) == 30 for e in mine)
        # the two worlds are different worlds (seeded seed and seed + 1)
        assert mine[0]["return"] != mine[1]["return"]
    # in slot order: world 0's agents, then world 1's
    assert [e["agent"] for e in episodes[:4]] == AGENTS * 2


def test_two_worlds_are_deterministic_and_the_same_in_workers(runs, tmp_path):
    out0, _ = runs[0]
    out2, _ = runs[2]
    assert not _same_models(out0 / "model_infant_0.zip", out0 / "model_infant_1.zip")
    again = tmp_path / "again"
    _run(again, 0)
    for a in AGENTS:   # the same seed: the same models, in this process or in workers
        assert _same_models(out0 / f"model_{a}.zip", again / f"model_{a}.zip"), a
        assert _same_models(out0 / f"model_{a}.zip", out2 / f"model_{a}.zip"), a
    for other in (again, out2):
        pa, pb = read_progress(out0 / "progress.csv"), read_progress(other / "progress.csv")
        for k in pa:
            if k != "wall_time_s":
                np.testing.assert_array_equal(pa[k], pb[k], err_msg=k)
        assert [(e["agent"], e["return"]) for e in _episodes(out0)] == \
            [(e["agent"], e["return"]) for e in _episodes(other)]


def test_agents_with_different_spaces_train_on_several_worlds(tmp_path):
    """What --mode shared refuses (one five-fingered infant) trains here, on two worlds."""
    out = tmp_path / "uneven"
    res = _run(out, 0, env_kwargs={**SHORT, "per_agent": [{"hands": "five_fingers"}, {}]},
               eval_every=256, checkpoint_every=0)
    from stable_baselines3 import PPO
    shapes = [PPO.load(str(out / f"model_{a}.zip"), device="cpu").action_space.shape
              for a in AGENTS]
    assert shapes[0] != shapes[1] and res["timesteps"] == STEPS


def test_ppo_keeps_its_shipped_rollout_on_several_worlds(tmp_path):
    """n_steps not given: the shipped rollout split over the worlds (as in --mode shared), so
    that a rollout is as many env steps as on one world."""
    from mimo_social.train import hyperparams
    shipped = hyperparams.load("high_five", "ppo", "independent")["n_steps"]
    out = tmp_path / "rollout"
    res = train("high_five", "ppo", 64, 0, out, mode="independent", n_envs=4, n_cpus=0,
                eval_every=10 ** 6, eval_episodes=1, checkpoint_every=0, progress=False,
                env_kwargs={"max_steps": 20}, algo_kwargs={"batch_size": 256, "n_epochs": 1})
    config = json.loads((out / "config.json").read_text())
    assert config["algo_kwargs"]["n_steps"] == shipped // 4
    assert "n_envs=4" in config["algo_kwargs_provenance"]["n_steps"]
    assert res["timesteps"] == config["steps_planned"] == shipped   # one rollout, 4 worlds


# -- stopping and errors ------------------------------------------------------------------------
def test_a_stop_signal_saves_every_model_and_ends_the_workers(tmp_path):
    out = tmp_path / "stopped"
    done = threading.Event()

    def signal_at_first_checkpoint():
        while not done.is_set():
            if list((out / "checkpoints").glob("model_*_steps.zip")):
                os.kill(os.getpid(), signal.SIGINT)
                return
            time.sleep(0.1)

    watcher = threading.Thread(target=signal_at_first_checkpoint, daemon=True)
    watcher.start()
    try:
        res = _run(out, 2, steps=10 ** 6, checkpoint_every=64, eval_every=10 ** 6)
    finally:
        done.set()
        watcher.join()
    assert res["interrupted"] and res["signal"] == signal.SIGINT
    assert 64 <= res["timesteps"] < 10 ** 6
    config = json.loads((out / "config.json").read_text())
    assert config["interrupted"] is True
    from stable_baselines3 import PPO
    for a in AGENTS:
        assert PPO.load(str(out / f"model_{a}.zip"), device="cpu").n_envs == 2
    import multiprocessing as mp
    assert not [p for p in mp.active_children() if p.name.startswith("mimo_social-worlds")]


def test_the_runner_refuses_more_workers_than_worlds(tmp_path):
    with pytest.raises(TrainInputError, match="n_cpus=3"):
        train("high_five", "ppo", 64, 0, tmp_path / "w", mode="independent", n_envs=2, n_cpus=3,
              progress=False)
    assert not (tmp_path / "w").exists()


# -- the world batch and the vector lockstep, on a toy world --------------------------------------
class _Toy(ParallelEnv):
    """Two agents with different spaces (a Box and a Discrete action); an episode lasts
    ``length`` steps (agent ``b``'s one step less with ``apart``); ``die_at`` / ``hang_at``: the
    process exits with code 3 / sleeps at that step."""

    metadata = {"render_modes": [], "name": "toy"}

    def __init__(self, length=4, apart=False, die_at=None, hang_at=None):
        self.possible_agents = ["a", "b"]
        self.length, self.apart, self.die_at, self.hang_at = length, apart, die_at, hang_at
        self.rng = np.random.default_rng()
        self.t = 0
        self.agents = []

    def observation_space(self, agent):
        return spaces.Box(-np.inf, np.inf, (3,) if agent == "a" else (2,), np.float32)

    def action_space(self, agent):
        return spaces.Box(-1, 1, (2,), np.float32) if agent == "a" else spaces.Discrete(3)

    def _obs(self):
        x = self.rng.normal()
        return {"a": np.array([self.t, x, 0], np.float32), "b": np.array([self.t, -x], np.float32)}

    def reset(self, seed=None, options=None):
        if seed is not None:
            self.rng = np.random.default_rng(seed)
        self.t, self.agents = 0, list(self.possible_agents)
        return self._obs(), {a: {"start": True} for a in self.agents}

    def step(self, actions):
        self.t += 1
        if self.t == self.die_at:
            os._exit(3)
        if self.t == self.hang_at:
            time.sleep(3600)
        rew = {"a": float(np.sum(actions["a"])), "b": float(actions["b"])}
        ends = {"a": self.t >= self.length,
                "b": self.t >= self.length - (1 if self.apart else 0)}
        trunc = {a: ends[a] for a in self.agents}
        self.agents = [a for a in self.agents if not ends[a]]
        return self._obs(), rew, {a: False for a in trunc}, trunc, {a: {} for a in trunc}


def _toy_actions(rng, n):
    return {"a": rng.uniform(-1, 1, (n, 2)).astype(np.float32), "b": rng.integers(0, 3, n)}


def _rollout(batch, steps=6):
    rng = np.random.default_rng(1)
    obs, _ = batch.reset(seed=5)
    out = [obs]
    for _ in range(steps):
        out.append(batch.step(_toy_actions(rng, batch.n_worlds)))
    return out


def test_world_batch_in_workers_gives_what_it_gives_in_this_process():
    local = WorldBatch(_Toy, 3)
    remote = WorldBatch(_Toy, 3, 2)
    try:
        assert remote.possible_agents == ["a", "b"]
        assert remote.observation_space("b").shape == (2,)
        a, b = _rollout(local), _rollout(remote)
    finally:
        local.close()
        remote.close()
    for k in ("a", "b"):
        np.testing.assert_array_equal(a[0][k], b[0][k])
    for (o1, r1, d1, i1, _), (o2, r2, d2, i2, _) in zip(a[1:], b[1:]):
        for k in ("a", "b"):
            np.testing.assert_array_equal(o1[k], o2[k])
            np.testing.assert_array_equal(r1[k], r2[k])
        np.testing.assert_array_equal(d1, d2)
        assert [sorted(i["a"]) for i in i1] == [sorted(i["a"]) for i in i2]
    # world w seeded with seed + w: different worlds
    assert len(set(a[0]["a"][:, 1].tolist())) == 3
    # the 4th step ends every world: reset at once, the episode and the last observation kept
    obs, rewards, dones, infos, resets = a[4]
    assert dones.all() and (obs["a"][:, 0] == 0).all()
    for w in range(3):
        assert infos[w]["a"]["terminal_observation"][0] == 4
        assert infos[w]["b"]["TimeLimit.truncated"] is True
        assert infos[w]["a"]["episode"]["l"] == 4 and resets[w]["b"] == {"start": True}
    returns = sum(step[1]["a"].astype(np.float64) for step in a[1:5])
    np.testing.assert_allclose([i["a"]["episode"]["r"] for i in infos], returns, atol=1e-5)


@pytest.mark.parametrize("n_procs", [0, 1])
def test_agents_that_end_their_episodes_apart_are_an_error(n_procs):
    batch = WorldBatch(functools.partial(_Toy, apart=True), 2, n_procs)
    try:
        with pytest.raises((LockstepError, RuntimeError), match="end their episodes together"):
            _rollout(batch)
    finally:
        batch.close()


@pytest.mark.parametrize("die", [True, False])
def test_a_dead_or_stuck_world_worker_is_an_error_naming_it(die):
    batch = WorldBatch(functools.partial(_Toy, die_at=2 if die else None,
                                         hang_at=None if die else 2), 2, 2)
    try:
        rng = np.random.default_rng(0)
        batch.reset(seed=0)
        batch.step(_toy_actions(rng, 2))
        batch.timeout_s = 1.0    # (a stuck worker never answers: no race with a slow machine)
        with pytest.raises(RuntimeError, match=r"world worker 0 \(pid \d+\) " +
                           ("died .exit code 3." if die else "did not answer within 1 s")):
            batch.step(_toy_actions(rng, 2))
    finally:
        batch.close()
    assert not batch.procs


def _views_job(hub, agent, steps):
    def job():
        view = agent_vec_env(hub, agent)
        view.seed(11)
        view.reset()
        rng = np.random.default_rng(0)
        for _ in range(steps):
            view.step(_toy_actions(rng, hub.n_envs)[agent])
    return job


def test_vector_lockstep_hands_each_agent_its_slots_of_one_batch_step():
    batch = WorldBatch(_Toy, 2)
    hub = VecLockstep(batch)
    got = {}

    def job(agent):
        view = agent_vec_env(hub, agent)
        assert view.num_envs == 2 and view.render_mode is None
        assert view.observation_space == batch.observation_space(agent)
        view.seed(3 if agent == "a" else 99)    # the first agent's seed is the worlds'
        first = view.reset()
        rng = np.random.default_rng(0)
        steps = [view.step(_toy_actions(rng, 2)[agent]) for _ in range(5)]
        got[agent] = (first, steps)

    try:
        run_lockstep(hub, {a: functools.partial(job, a) for a in ("a", "b")})
        ref = WorldBatch(_Toy, 2)
        obs, _ = ref.reset(seed=3)
        rng = np.random.default_rng(0)
        expected = [ref.step(_toy_actions(rng, 2)) for _ in range(5)]
        ref.close()
    finally:
        batch.close()
    assert hub.env_steps == 10 and hub.batch_steps == 5
    for agent in ("a", "b"):
        first, steps = got[agent]
        np.testing.assert_array_equal(first, obs[agent])
        for (o, r, d, infos), (eo, er, ed, _, _) in zip(steps, expected):
            np.testing.assert_array_equal(o, eo[agent])
            np.testing.assert_array_equal(r, er[agent])
            np.testing.assert_array_equal(d, ed)
            assert len(infos) == 2
    assert "episode" in got["b"][1][3][3][0]   # the 4th step ended both worlds


@pytest.mark.parametrize("budgets", [(3, 5), (5, 3)])
def test_vector_learners_with_different_step_budgets_get_a_clear_error(budgets):
    batch = WorldBatch(_Toy, 2)
    hub = VecLockstep(batch)
    try:
        with pytest.raises(LockstepError, match="same number of steps"):
            run_lockstep(hub, {"a": _views_job(hub, "a", budgets[0]),
                               "b": _views_job(hub, "b", budgets[1])})
    finally:
        batch.close()
    assert hub.env_steps == 6
