"""Issue 29: the evaluation budget, both policies' columns, stopping on a signal, the PPO
rounding note and one learner's envs in spawned workers (short runs on reach)."""

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import torch

from mimo_social import cli
from mimo_social.train import read_progress
from mimo_social.train.progress import progress_agents
from mimo_social.train.runlog import EVAL_FRACTION, Schedule
from mimo_social.train.single import train_single
from mimo_social.train.tasks import algo_class

torch.set_num_threads(1)

SHORT = {"max_steps": 20}
FAST_PPO = {"n_steps": 128, "batch_size": 64, "n_epochs": 1}


def _single(out: Path, steps: int, **kw) -> dict:
    """``train_single`` as :func:`mimo_social.train.runner.train` calls it."""
    out.mkdir(parents=True, exist_ok=True)
    args = dict(eval_every=None, eval_episodes=5, checkpoint_every=0, progress=False,
                env_kwargs=SHORT, algo_kwargs=dict(FAST_PPO), verbose=0,
                config={"task": "reach", "algo": "ppo", "env_kwargs": SHORT})
    args.update(kw)
    return train_single(algo_class("ppo"), "reach", steps, 0, out, **args)


def _eval_steps(p) -> float:
    """Env steps evaluated, from the rows: mean length x episodes, each policy."""
    return float(np.sum(p["eval_episodes"] * (p["eval_length_mean"]
                                              + p["eval_length_mean_stochastic"])))


@pytest.fixture(scope="module")
def budget_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("budget") / "reach"
    return out, _single(out, 512)


def test_default_evaluation_stays_within_its_budget_with_both_policies(budget_run):
    out, res = budget_run
    p = read_progress(out / "progress.csv")
    done = json.loads((out / "config.json").read_text())
    assert done["timesteps_done"] == 512 and done["eval_every"] is None
    assert _eval_steps(p) <= EVAL_FRACTION * 512
    assert p["eval_steps"][-1] == _eval_steps(p) == done["eval_steps_done"]
    assert (p["timesteps"] >= FAST_PPO["n_steps"]).all()   # none before the first update
    for key in ("eval_success_rate", "eval_success_rate_stochastic", "eval_return_mean",
                "eval_return_mean_stochastic"):
        assert np.isfinite(p[key]).all(), key
    assert progress_agents(p) == []      # the stochastic columns are no agent's
    assert (out / "learning_curve.png").read_bytes()[:4] == b"\x89PNG"


def test_the_budgeted_schedule_spreads_evaluations_and_never_overspends():
    s = Schedule(None, 0, 200_000, episodes=5, episode_steps=100, first=2048)
    made = []
    for n in range(1, 200_000, 7):
        k = s.eval_due(n)
        if k:
            made.append(n)
            s.spend(s.cost(k))
            assert s.spent <= EVAL_FRACTION * n
    s.spend(s.cost(s.final_episodes()))
    assert s.spent <= EVAL_FRACTION * 200_000
    assert made[0] >= 2048 and len(made) >= 5
    gaps = np.diff(made)
    assert gaps[-1] > gaps[0]                  # sparse early, wider apart later
    # long episodes (1000 steps, 2 policies: 2000 env steps an episode each): the first
    # evaluation comes as soon as one episode of each fits, at ~10x its cost; later ones longer
    s = Schedule(None, 0, 300_000, episodes=5, episode_steps=1000, first=2048)
    made = {}
    for n in range(2048, 300_000, 64):
        k = s.eval_due(n)
        if k:
            made[n] = k
            s.spend(s.cost(k))
            assert s.spent <= EVAL_FRACTION * n
    first = min(made)
    assert made[first] == 1 and first <= 25_000
    assert max(made.values()) >= 3 and list(made.values()) == sorted(made.values())
    assert s.final_episodes() == 5
    s.spend(s.cost(s.final_episodes()))
    assert s.spent <= EVAL_FRACTION * 300_000
    # an explicit interval keeps its meaning, its episodes too
    s = Schedule(128, 0, 512, episodes=3)
    assert [n for n in range(1, 512) if s.eval_due(n)] == [128, 256, 384]
    assert s.final_episodes() == 3


def test_eval_reports_both_policies_by_default(budget_run, capsys):
    out, _ = budget_run
    assert cli.main(["eval", str(out), "--episodes", "2", "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "reach PPO model.zip: 2 episodes, mean action (deterministic): return" in text
    assert "reach PPO model.zip: 2 episodes, sampled actions (stochastic): return" in text
    res = json.loads((out / "eval_results.json").read_text())
    assert len(res["returns"]) == len(res["stochastic"]["returns"]) == 2
    assert cli.main(["eval", str(out), "--episodes", "1", "--stochastic", "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "sampled actions" in text and "mean action" not in text


def test_ppo_rounding_up_to_whole_rollouts_is_said_and_recorded(tmp_path, capsys):
    res = _single(tmp_path / "r", 300)
    err = capsys.readouterr().err
    assert "n_steps x n_envs = 128 x 1 = 128: --steps 300 trains 384 steps" in err
    config = json.loads((tmp_path / "r" / "config.json").read_text())
    assert config["steps"] == 300 and config["steps_planned"] == 384
    assert config["timesteps_done"] == res["timesteps"] == 384


def test_one_learner_trains_on_two_spawned_workers(tmp_path):
    out = tmp_path / "w"
    res = _single(out, 256, algo_kwargs={"n_steps": 64, "batch_size": 64, "n_epochs": 1},
                  n_envs=2, worker_timeout=600)
    config = json.loads((out / "config.json").read_text())
    assert config["n_envs"] == 2 and res["timesteps"] == 256
    with open(out / "episodes.csv", newline="") as f:
        episodes = list(csv.DictReader(f))
    assert len(episodes) >= 2 * (256 // 2 // 20) - 2    # both workers' episodes
    assert algo_class("ppo").load(str(out / "model.zip"), device="cpu").n_envs == 2


def test_ppo_with_several_envs_keeps_a_rollout_of_2048_unless_given():
    from mimo_social.train.single import vector_defaults
    assert vector_defaults({}, set(), 4, "ppo") == {"n_steps": 512}
    assert vector_defaults({"n_steps": 64}, {"n_steps"}, 4, "ppo") == {"n_steps": 64}
    assert vector_defaults({}, set(), 1, "ppo") == {}
    assert vector_defaults({}, set(), 2, "sac") == {"gradient_steps": -1}


class _Stuck:
    """An env factory whose env never answers ``step`` (or dies in it)."""

    def __init__(self, die: bool):
        self.die = die

    def __call__(self):
        import gymnasium as gym

        die = self.die

        class Env(gym.Env):
            observation_space = gym.spaces.Box(-1, 1, (2,))
            action_space = gym.spaces.Box(-1, 1, (1,))

            def reset(self, seed=None, options=None):
                return np.zeros(2, np.float32), {}

            def step(self, action):
                if die:
                    os._exit(3)
                time.sleep(3600)

        return Env()


@pytest.mark.parametrize("die", [False, True])
def test_a_stuck_or_dead_worker_is_an_error_naming_it(die):
    from mimo_social.train.workers import TimedSubprocVecEnv
    venv = TimedSubprocVecEnv([_Stuck(die)] * 2, timeout_s=600)
    try:
        venv.reset()
        venv.timeout_s = 1.0     # (a stuck worker never answers: no race with a slow machine)
        with pytest.raises(RuntimeError, match="died .exit code 3." if die
                           else "did not answer within 1 s"):
            venv.step(np.zeros((2, 1), np.float32))
    finally:
        venv.kill()


def _train_until_checkpoint(out: Path, args: list[str], pattern: str):
    """``mimo-social train`` in a subprocess, until its first checkpoint is on disk."""
    cmd = [sys.executable, "-m", "mimo_social.cli", "train", *args, "--out", str(out),
           "--no-progress", "--checkpoint-every", "64", "--env-kwargs", json.dumps(SHORT),
           "--algo-kwargs", json.dumps(FAST_PPO), "--steps", "1000000"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 600     # a hang guard only
    while not list((out / "checkpoints").glob(pattern)):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "no checkpoint within 600 s"
        time.sleep(0.2)
    return proc


@pytest.mark.parametrize("task,mode,sig", [("reach", None, signal.SIGINT),
                                           ("high_five", "independent", signal.SIGTERM)])
def test_a_signal_during_training_saves_the_run_and_exits_128_plus_its_number(
        tmp_path, task, mode, sig):
    out = tmp_path / "stopped"
    args = ["--task", task, "--algo", "ppo"] + (["--mode", mode] if mode else [])
    proc = _train_until_checkpoint(out, args, "model_*_steps.zip")
    proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=600)
    assert proc.returncode == 128 + sig, stderr
    assert "(interrupted)" in stdout and f"stopped by signal {int(sig)}" in stderr
    config = json.loads((out / "config.json").read_text())
    assert config["interrupted"] is True and config["signal"] == int(sig)
    assert 64 <= config["timesteps_done"] < 1_000_000
    p = read_progress(out / "progress.csv")
    assert len(p["timesteps"]) >= 1 and "eval_success_rate_stochastic" in p
    assert (out / "learning_curve.png").stat().st_size > 0
    assert (out / "episodes.csv").stat().st_size > 0
    models = ["model.zip"] if mode is None else [f"model_{a}.zip" for a in config["agents"]]
    for m in models:
        algo_class("ppo").load(str(out / m), device="cpu")
