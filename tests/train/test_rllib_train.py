"""``train --engine rllib`` / ``eval`` of its runs, on a Ray cluster the test starts on loopback
(``ray start --head`` in a subprocess): the shared policy of high five through the command
line with 2 env runners, one policy per agent on a heterogeneous pair, a vision task stepping
in a runner. The Ray tests are skipped where ray's RLlib is not installed (the rllib extra;
``scripts/test_rllib.sh`` runs them in ``.venv-rllib``); the argument checks run everywhere."""

from __future__ import annotations

import csv
import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from mimo_social.cli import main

TINY = {"train_batch_size_per_learner": 200, "minibatch_size": 100, "num_epochs": 1,
        "fcnet_hiddens": [16]}
SHORT = {"max_steps": 50}


# -- argument checks (no ray needed) -------------------------------------------------------------
def _train(tmp_path, *extra):
    return main(["train", "--task", "high_five", "--algo", "ppo", "--steps", "10",
                 "--out", str(tmp_path / "run"), "--no-progress", *extra])


@pytest.mark.parametrize("extra, says", [
    (["--address", "127.0.0.1:6379"], "--address: for --engine rllib"),
    (["--num-env-runners", "2"], "--num-env-runners: for --engine rllib"),
    (["--num-gpus-per-learner", "1"], "--num-gpus-per-learner: for --engine rllib"),
    (["--engine", "sb3", "--algo", "appo"], "--algo appo: for --engine rllib"),
    (["--engine", "rllib", "--n-envs", "2"], "--n-envs: for --engine sb3"),
    (["--engine", "rllib", "--obs-min-std", "0.01"], "--obs-min-std: for --engine sb3"),
])
def test_options_of_the_other_engine_are_refused(tmp_path, capsys, extra, says):
    assert _train(tmp_path, *extra) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("mimo-social train: error: ") and says in err, err
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("bad", ["localhost", "host:0", "host:port", ":6379", "1.2.3.4:70000"])
def test_a_bad_address_is_a_usage_error(tmp_path, capsys, bad):
    with pytest.raises(SystemExit) as e:
        _train(tmp_path, "--engine", "rllib", "--address", bad)
    assert e.value.code == 2
    assert "argument --address" in capsys.readouterr().err


def test_without_ray_one_line_says_how_to_install_it(tmp_path, capsys, monkeypatch):
    import mimo_social.train.rllib as rllib

    monkeypatch.setattr(rllib, "ray_available", lambda: False)
    assert _train(tmp_path, "--engine", "rllib") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and '.[rllib]' in err and "setup_rllib.sh" in err


# -- on a Ray cluster ----------------------------------------------------------------------------
def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _cluster_pids(temp_dir: str) -> list[int]:
    """The processes of the test's cluster: those whose command line names its temp dir."""
    pids = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit() and int(d.name) != os.getpid():
            try:
                if temp_dir.encode() in (d / "cmdline").read_bytes():
                    pids.append(int(d.name))
            except OSError:
                pass
    return pids


def _set_auth(env: dict) -> None:
    """Ray's authentication settings of this process (Ray reads the mode and the token once and
    caches them: reload both)."""
    for k, v in env.items():
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v
    from ray._raylet import AuthenticationTokenLoader, Config
    Config.initialize("")
    AuthenticationTokenLoader.instance().reset_cache()


@pytest.fixture(scope="module")
def cluster():
    ray = pytest.importorskip("ray")
    pytest.importorskip("ray.rllib")
    if ray.is_initialized():
        ray.shutdown()
    saved = {k: os.environ.get(k) for k in ("RAY_AUTH_MODE", "RAY_AUTH_TOKEN")}
    token = secrets.token_hex(16)
    temp_dir = tempfile.mkdtemp(prefix="rt", dir="/tmp")
    port = _free_port()
    env = {**os.environ, "RAY_AUTH_MODE": "token", "RAY_AUTH_TOKEN": token}
    ray_bin = str(Path(sys.executable).with_name("ray"))
    start = subprocess.run(
        [ray_bin, "start", "--head", "--node-ip-address", "127.0.0.1", "--port", str(port),
         "--num-cpus", "2", "--temp-dir", temp_dir, "--include-dashboard=false",
         "--disable-usage-stats"], env=env, capture_output=True, text=True, timeout=120)
    try:
        assert start.returncode == 0, start.stderr[-2000:]
        _set_auth({"RAY_AUTH_MODE": "token", "RAY_AUTH_TOKEN": token})  # the test's own token
        yield f"127.0.0.1:{port}"
    finally:
        if ray.is_initialized():
            ray.shutdown()
        for sig in (signal.SIGTERM, signal.SIGKILL):
            for pid in _cluster_pids(temp_dir):
                try:
                    os.kill(pid, sig)
                except ProcessLookupError:
                    pass
            deadline = time.time() + 3
            while _cluster_pids(temp_dir) and time.time() < deadline:
                time.sleep(0.2)
        _set_auth(saved)
        shutil.rmtree(temp_dir, ignore_errors=True)


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_shared_policy_on_the_cluster_writes_curves_and_a_checkpoint_eval_reloads(
        cluster, tmp_path, capsys, monkeypatch):
    import ray

    out = tmp_path / "hf"
    rc = main(["train", "--engine", "rllib", "--address", cluster, "--task", "high_five",
               "--mode", "shared", "--algo", "ppo", "--steps", "400", "--num-env-runners", "2",
               "--env-kwargs", json.dumps(SHORT), "--algo-kwargs", json.dumps(TINY),
               "--eval-every", "200", "--eval-episodes", "1", "--out", str(out),
               "--no-progress"])
    printed = capsys.readouterr().out
    assert rc == 0, printed
    assert "trained PPO with RLlib on high_five (shared) for 400 steps" in printed
    assert not ray.is_initialized()        # it joined the cluster and left it
    config = json.loads((out / "config.json").read_text())
    assert (config["engine"], config["address"], config["num_env_runners"]) == \
        ("rllib", cluster, 2)
    assert config["modules"] == {"infant_0": "shared", "infant_1": "shared"}
    rows = _rows(out / "progress.csv")
    assert [int(r["timesteps"]) for r in rows] == [200, 400]   # 2 iterations of 200 steps
    for a in ("infant_0", "infant_1"):
        assert all(np.isfinite(float(r[f"eval_return_mean_{a}"])) for r in rows)
    # 400 steps of 50-step episodes: 8 episodes, each a row per agent
    episodes = _rows(out / "episodes.csv")
    assert sorted(e["agent"] for e in episodes) == ["infant_0"] * 8 + ["infant_1"] * 8
    assert all(int(e["length"]) == 50 for e in episodes)
    assert (out / "learning_curve.png").stat().st_size > 5000
    for ckpt in ("checkpoint", "checkpoints/step_400", "best_checkpoint"):
        assert (out / ckpt / "learner_group/learner/rl_module/shared").is_dir(), ckpt

    rrd = tmp_path / "eval.rrd"
    assert main(["eval", str(out), "--episodes", "2", "--record", str(rrd)]) == 0
    printed = capsys.readouterr().out
    res = json.loads((out / "eval_results.json").read_text())
    assert (res["engine"], res["episodes"], res["deterministic"]) == ("rllib", 2, True)
    assert set(res["agents"]) == {"infant_0", "infant_1"}
    assert all(n == 50 for a in res["agents"].values() for n in a["lengths"])
    assert rrd.stat().st_size > 10_000 and "wrote " + str(rrd) in printed
    # deterministic: the same episodes again give the same returns
    again = main(["eval", str(out), "--episodes", "2"])
    assert again == 0
    assert json.loads((out / "eval_results.json").read_text())["returns"] == res["returns"]
    # the run folder as typed in a shell, relative (RLlib reads checkpoints by URI)
    monkeypatch.chdir(tmp_path)
    assert main(["eval", "hf", "--episodes", "1"]) == 0


HETERO = {"max_steps": 50, "per_agent": [{"hands": "mitten"}, {"touch": True}]}


def test_shared_mode_refuses_a_heterogeneous_pair(tmp_path, capsys):
    pytest.importorskip("ray.rllib")
    rc = main(["train", "--engine", "rllib", "--task", "high_five", "--mode", "shared",
               "--algo", "ppo", "--steps", "10", "--env-kwargs", json.dumps(HETERO),
               "--out", str(tmp_path / "x"), "--no-progress"])
    assert rc == 2
    assert "--mode independent" in capsys.readouterr().err


def test_one_policy_per_agent_of_a_heterogeneous_pair(cluster, tmp_path):
    from ray.rllib.core.rl_module.rl_module import RLModule

    from mimo_social.train.rllib import evaluate_rllib, train_rllib

    out = tmp_path / "hetero"
    res = train_rllib("high_five", "ppo", 200, 1, out, mode="independent", address=cluster,
                      num_env_runners=1, env_kwargs=HETERO, algo_kwargs=TINY,
                      eval_episodes=1, progress=False)
    assert res["agents"] == ["infant_0", "infant_1"] and res["timesteps"] == 200
    config = json.loads((out / "config.json").read_text())
    assert config["modules"] == {"infant_0": "infant_0", "infant_1": "infant_1"}
    base = out / "checkpoint/learner_group/learner/rl_module"
    modules = {a: RLModule.from_checkpoint(base / a) for a in ("infant_0", "infant_1")}
    obs_dims = {a: m.observation_space.shape[0] for a, m in modules.items()}
    assert obs_dims["infant_1"] > obs_dims["infant_0"]      # infant_1 has touch
    assert "eval_return_mean_infant_1" in _rows(out / "progress.csv")[0]
    ev = evaluate_rllib(out, 1)
    assert set(ev["agents"]) == {"infant_0", "infant_1"}


def test_vision_task_steps_in_an_env_runner(cluster, tmp_path):
    """mirror with the learner's eyes on (16x16), on the flat path (``flat_obs``: the image
    path is tests/train/test_rllib_eyes.py): the env and its GL context are made in the env
    runner's process, whose eye images are not blank; --normalize-obs keeps its filter."""
    import ray

    from mimo_social.train.rllib import build_config
    from mimo_social.train.rllib.runner import filter_state, init_ray

    eyes = {"max_steps": 50, "per_agent": [{"vision": {"width": 16, "height": 16}}, {}]}
    assert init_ray(cluster)
    try:
        algo = build_config("mirror", "scripted", "ppo", 0, num_env_runners=1, env_kwargs=eyes,
                            algo_kwargs=TINY, normalize_obs=True, flat_obs=True).build_algo()
        try:
            result = algo.train()
            assert result["env_runners"]["num_env_steps_sampled_lifetime"] >= 200

            def probe(runner):
                env = runner.env.unwrapped.envs[0]
                obs, _ = env.reset(seed=3)
                obs, *_ = env.step({"infant_0": 1})
                return os.getpid(), float(np.max(obs["infant_0"])), obs["infant_0"].shape

            (pid, brightest, shape), = algo.env_runner_group.foreach_env_runner(
                probe, remote_worker_ids=[1], local_env_runner=False)
            assert pid != os.getpid()
            assert shape == (2 * 16 * 16 * 3,) and 0 < brightest <= 1   # scaled to [0, 1]
            stats = filter_state(algo)
            assert set(stats) == {"infant_0"}
        finally:
            algo.stop()
    finally:
        ray.shutdown()


def test_one_agent_task_with_sac_sampling_in_the_driver(cluster, tmp_path, capsys):
    """reach (one agent) with SAC, no env runner process (--num-env-runners 0): the summary
    columns only, as the SB3 path writes them for a one-agent task; eval --model best."""
    out = tmp_path / "reach"
    sac = {"train_batch_size_per_learner": 32, "num_steps_sampled_before_learning_starts": 50,
           "fcnet_hiddens": [16]}
    rc = main(["train", "--engine", "rllib", "--address", cluster, "--task", "reach", "--algo",
               "sac", "--steps", "100", "--num-env-runners", "0", "--env-kwargs",
               json.dumps(SHORT), "--algo-kwargs", json.dumps(sac), "--eval-episodes", "1",
               "--out", str(out), "--no-progress"])
    assert rc == 0, capsys.readouterr().err
    rows = _rows(out / "progress.csv")
    assert int(rows[-1]["timesteps"]) >= 100
    assert not any(k.startswith("eval_return_mean_infant") for k in rows[0])   # no agent columns
    assert "eval_return_mean_stochastic" in rows[0]
    assert json.loads((out / "config.json").read_text())["modules"] == {"infant_0": "infant_0"}
    assert main(["eval", str(out), "--episodes", "1", "--model", "best"]) == 0
    assert "reach SAC best_checkpoint: 1 episodes" in capsys.readouterr().out


def _modes():
    from mimo_social.train import MULTI_TASKS, TASKS
    return ([(t, None) for t in TASKS]
            + [(t, m) for t in MULTI_TASKS for m in ("shared", "scripted")])


@pytest.mark.parametrize("task, mode", _modes())
def test_the_env_creator_makes_every_task_of_the_catalogue(task, mode):
    pytest.importorskip("ray.rllib")
    from mimo_social.train.rllib import env_name, make_rllib_env, register_rllib_envs
    from mimo_social.train.rllib.env import EPISODE_KEY, CatalogEnv

    assert env_name(task) in register_rllib_envs()
    env = CatalogEnv({"task": task, "mode": mode, "env_kwargs": {"max_steps": 3}})
    try:
        obs, infos = env.reset(seed=0)
        assert set(obs) == set(env.agents) == set(env.possible_agents)
        for a in env.agents:
            env.action_spaces[a].seed(0)
        for step in range(3):
            actions = {a: env.action_spaces[a].sample() for a in env.agents}
            obs, rewards, terms, truncs, infos = env.step(actions)
            for a, o in obs.items():
                assert env.observation_spaces[a].contains(o), (a, step)
        assert truncs["__all__"] or terms["__all__"]
        assert all(EPISODE_KEY in infos[a] for a in env.possible_agents)
        assert not env.agents
    finally:
        env.close()
    made = make_rllib_env({"task": task, "mode": mode})   # the registered creator: the same env
    try:
        assert made.observation_spaces.keys() == env.observation_spaces.keys()
    finally:
        made.close()


def _first_module(task, mode):
    """The RLModule PPO starts with (built from build_config's spec, as RLlib builds it) and
    observations of a few zero-action steps of the task."""
    from mimo_social.train.rllib import build_config
    from mimo_social.train.rllib.config import flat_spaces
    from mimo_social.train.rllib.env import flat_env

    spaces = flat_spaces(task, mode)
    config = build_config(task, mode, "ppo", seed=0, spaces=spaces)
    mid, spec = sorted(config.rl_module_spec.rl_module_specs.items())[0]
    agent = next(a for a in spaces[0] if mid in ("shared", a))
    env = flat_env(task, mode)
    try:
        obs, _ = env.reset(seed=0)
        seen = []
        for _ in range(20):
            seen.append(obs[agent])
            obs, *_ = env.step({a: np.zeros_like(env.action_space(a).sample())
                                for a in env.agents})
            if not env.agents:
                obs, _ = env.reset()
    finally:
        env.close()
    return spec.build(), np.asarray(seen, dtype=np.float32), spaces[1][agent][1]


def test_ppo_starts_as_sb3_mean_actions_near_zero_and_unit_std():
    pytest.importorskip("ray.rllib")
    import torch

    module, obs, act_space = _first_module("high_five", "shared")
    with torch.no_grad():
        out = module.forward_inference({"obs": torch.from_numpy(obs)})["action_dist_inputs"]
    n = act_space.shape[0]
    assert out.shape == (len(obs), 2 * n)        # means, then log stds
    assert float(out[:, :n].abs().max()) < 0.05  # SB3's gain 0.01: RLlib's own init gives ~0.35
    assert torch.equal(out[:, n:], torch.zeros(len(obs), n))   # std 1, the same in every state
    assert isinstance(module.pi.log_std, torch.nn.Parameter)
    assert hasattr(module.encoder, "critic_encoder")   # the value net shares no layer
    with torch.no_grad():
        values = module.compute_values({"obs": torch.from_numpy(obs)})
    assert values.shape == (len(obs),) and float(values.abs().max()) < 10


def test_ppo_with_discrete_actions_starts_near_uniform():
    pytest.importorskip("ray.rllib")
    import torch

    module, obs, act_space = _first_module("mirror", "independent")
    with torch.no_grad():
        logits = module.forward_inference({"obs": torch.from_numpy(obs)})["action_dist_inputs"]
    assert logits.shape == (len(obs), act_space.n)
    assert float(logits.abs().max()) < 0.05
