"""Memory and reward normalisation in training (issue 29): ``--algo recurrent_ppo`` (sb3-contrib's
RecurrentPPO, an LSTM after the MLP inputs or after the CNN) trains, saves and is evaluated with
its state carried across an episode's steps and fresh at every episode; ``--normalize-reward``
(SB3's VecNormalize on the rewards) saves its statistics next to every model, ``eval`` loads
them, and every number written is the env's own return. Tiny runs: 128 steps, short episodes,
one env."""

import json
import pickle

import numpy as np
import pytest
import torch

from mimo_social import cli
from mimo_social.core.episodes import run_episode, run_episodes
from mimo_social.train import evaluate, read_progress, train
from mimo_social.train.baselines import baselines
from mimo_social.train.envs import make_env
from mimo_social.train.rollouts import (ModelPolicy, PolicyState, is_recurrent, load_vecnormalize,
                                        vecnormalize_path)
from mimo_social.train.tasks import TrainInputError, algo_class

torch.set_num_threads(1)

SHORT = {"max_steps": 30}
#: a small LSTM and one short epoch: the runs test the plumbing, not learning
TINY = {"n_steps": 64, "batch_size": 64, "n_epochs": 1, "policy_kwargs": {"lstm_hidden_size": 16}}
FAST_PPO = {"n_steps": 64, "batch_size": 64, "n_epochs": 1}


@pytest.fixture(scope="module")
def reach_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("runs") / "reach_rppo"
    res = train("reach", "recurrent_ppo", 128, 0, out, eval_every=128, eval_episodes=2,
                checkpoint_every=0, progress=False, env_kwargs=SHORT, algo_kwargs=TINY,
                n_envs=1)
    return out, res


def test_recurrent_ppo_trains_on_reach_with_an_lstm_and_saves(reach_run):
    out, res = reach_run
    config = json.loads((out / "config.json").read_text())
    assert config["algo"] == "recurrent_ppo" and config["policy"] == "MlpLstmPolicy"
    assert config["algo_kwargs"]["policy_kwargs"]["lstm_hidden_size"] == 16
    assert config["algo_kwargs"]["policy_kwargs"]["enable_critic_lstm"] is True   # shipped
    assert config["algo_kwargs_provenance"]["policy_kwargs.n_lstm_layers"] == (
        "shipped:default.toml")
    assert config["normalize_reward"] is False and not (out / "vecnormalize.pkl").exists()
    assert (out / "model.zip").is_file() and (out / "best_model.zip").is_file()
    model = algo_class("recurrent_ppo").load(str(out / "model.zip"), device="cpu")
    assert is_recurrent(model) and model.policy.lstm_actor.hidden_size == 16
    assert res["timesteps"] == 128


def test_evaluate_reloads_it_and_resets_the_state_every_episode(reach_run):
    out, res = reach_run
    a = evaluate(out, episodes=3, seed=5, deterministic=True)
    b = evaluate(out, episodes=3, seed=5, deterministic=True)
    assert a["returns"] == b["returns"] and len(a["returns"]) == 3
    # episode 2 of a run of three is episode 1 of a run that starts at its seed: no state left
    # over from the episode before
    c = evaluate(out, episodes=1, seed=6, deterministic=True)
    assert c["returns"][0] == a["returns"][1]
    # the training's last evaluation (seeds 10000 + seed) is what evaluate() gives on model.zip
    last = read_progress(out / "progress.csv")
    n = int(last["eval_episodes"][-1])
    d = evaluate(out, episodes=n, seed=10_000, deterministic=True)
    assert d["return_mean"] == pytest.approx(float(last["eval_return_mean"][-1]))
    assert a["vecnormalize"] is None


def test_the_state_is_carried_within_an_episode_and_reset_between_episodes(reach_run):
    out, _ = reach_run
    model = algo_class("recurrent_ppo").load(str(out / "model.zip"), device="cpu")
    env = make_env("reach", flat=True, **SHORT)
    try:
        obs, _ = env.reset(seed=3)
        memory = PolicyState(model)
        carried, fresh = [], []
        for _ in range(5):
            carried.append(memory.predict(obs, True))
            fresh.append(model.predict(obs, state=None, episode_start=np.array([True]),
                                       deterministic=True)[0])
            obs, *_ = env.step(carried[-1])
        assert np.allclose(carried[0], fresh[0])          # a fresh state at the start
        assert not all(np.allclose(c, f) for c, f in zip(carried[1:], fresh[1:]))
        memory.reset()
        obs, _ = env.reset(seed=3)
        assert np.allclose(memory.predict(obs, True), carried[0])
        # one ModelPolicy over several episodes (as baselines and paradigms use it): the core
        # loop's reset hook gives each episode a fresh state
        policy = ModelPolicy(model)
        two = run_episodes(env, policy, 2, seed=7)
        alone = run_episode(env, ModelPolicy(model), seed=8)
        assert two[1].returns == alone.returns
    finally:
        env.close()


def test_baselines_run_a_recurrent_run_with_a_fresh_state_each_episode(reach_run):
    out, _ = reach_run
    res = baselines("reach", episodes=2, seed=4, runs=[out], progress=False)
    trained = next(p for p in res["policies"] if p["kind"] == "trained")
    assert trained["returns"] == evaluate(out, episodes=2, seed=4,
                                          deterministic=True)["returns"]


def test_recurrent_ppo_on_mirror_scripted_sees_through_the_cnn_with_normalised_rewards(tmp_path):
    out = tmp_path / "mirror_rppo"
    res = train("mirror", "recurrent_ppo", 128, 0, out, mode="scripted", eval_every=128,
                eval_episodes=1, checkpoint_every=0, progress=False,
                env_kwargs={"max_steps": 20}, algo_kwargs=TINY, n_envs=1,
                normalize_reward=True)
    config = json.loads((out / "config.json").read_text())
    assert config["policy"] == "MultiInputLstmPolicy" and config["mode"] == "scripted"
    assert config["algo_kwargs"]["gamma"] == 0.0                # mirror.toml [recurrent_ppo]
    assert config["vecnormalize"]["gamma"] == 0.0 and config["normalize_reward"] is True
    model = algo_class("recurrent_ppo").load(str(out / "model.zip"), device="cpu")
    assert type(model.policy.features_extractor).__name__ == "EyesExtractor"
    for name in ("vecnormalize.pkl", "best_vecnormalize.pkl"):
        assert (out / name).is_file(), name
    a = evaluate(out, episodes=2, seed=3, deterministic=True)
    b = evaluate(out, episodes=2, seed=3, deterministic=True)
    assert a["returns"] == b["returns"] and a["vecnormalize"].endswith("vecnormalize.pkl")
    assert all(0 <= r <= 20 for r in a["returns"])       # raw: +1 a matching step, 20 steps
    assert res["last_eval"]["eval_return_mean"] == pytest.approx(
        evaluate(out, episodes=1, seed=10_000, deterministic=True)["return_mean"])


def test_normalize_reward_saves_the_statistics_with_every_model_and_eval_loads_them(tmp_path):
    out = tmp_path / "reach_norm"
    train("reach", "ppo", 128, 0, out, eval_every=64, eval_episodes=1, checkpoint_every=64,
          progress=False, env_kwargs=SHORT, algo_kwargs=FAST_PPO, n_envs=1,
          normalize_reward=True)
    config = json.loads((out / "config.json").read_text())
    assert config["normalize_reward"] is True
    assert config["vecnormalize"] == {"file": "vecnormalize.pkl", "norm_obs": False,
                                      "norm_reward": True, "gamma": 0.99, "clip_reward": 10.0,
                                      "epsilon": 1e-08}
    assert sorted(p.name for p in (out / "checkpoints").iterdir()) == [
        "model_128_steps.zip", "model_64_steps.zip", "vecnormalize_128_steps.pkl",
        "vecnormalize_64_steps.pkl"]
    with open(out / "vecnormalize.pkl", "rb") as f:
        stats = pickle.load(f)
    assert stats.norm_reward and not stats.norm_obs and stats.ret_rms.count > 1
    # the rewards were normalised for the learner only: the evaluations are the env's returns
    rows = read_progress(out / "progress.csv")
    res = evaluate(out, episodes=1, seed=10_000, deterministic=True)
    assert res["return_mean"] == pytest.approx(float(rows["eval_return_mean"][-1]))
    assert res["vecnormalize"] == str(out / "vecnormalize.pkl")
    env = make_env("reach", flat=True, **SHORT)
    try:   # the same episode summed by hand from the env's rewards
        model = algo_class("ppo").load(str(out / "model.zip"), device="cpu")
        obs, _ = env.reset(seed=10_000)
        total, done = 0.0, False
        while not done:
            obs, r, term, trunc, _ = env.step(model.predict(obs, deterministic=True)[0])
            total, done = total + float(r), term or trunc
    finally:
        env.close()
    assert res["returns"][0] == pytest.approx(total)
    ckpt = evaluate(out, episodes=1, seed=0, model=str(out / "checkpoints" /
                                                       "model_64_steps.zip"))
    assert ckpt["vecnormalize"].endswith("vecnormalize_64_steps.pkl")


def test_shared_mode_takes_recurrent_ppo_and_normalised_rewards(tmp_path):
    out = tmp_path / "mirror_shared"
    train("mirror", "recurrent_ppo", 64, 0, out, mode="shared", eval_every=64, eval_episodes=1,
          checkpoint_every=0, progress=False, env_kwargs={"max_steps": 16}, algo_kwargs=TINY,
          normalize_reward=True)
    assert json.loads((out / "config.json").read_text())["policy"] == "MlpLstmPolicy"
    res = evaluate(out, episodes=1, seed=0, deterministic=True)
    assert set(res["agents"]) == set(res["models"]) and res["vecnormalize"] is not None


def test_vecnormalize_files_sit_next_to_their_models(tmp_path):
    assert vecnormalize_path(tmp_path / "model.zip") == tmp_path / "vecnormalize.pkl"
    assert vecnormalize_path(tmp_path / "best_model.zip") == tmp_path / "best_vecnormalize.pkl"
    assert vecnormalize_path(tmp_path / "c" / "model_64_steps.zip") == (
        tmp_path / "c" / "vecnormalize_64_steps.pkl")
    assert vecnormalize_path("model_a0.zip").name == "vecnormalize_a0.pkl"
    assert load_vecnormalize(tmp_path / "none.pkl") is None


def test_observation_statistics_are_applied_when_a_file_has_them(tmp_path):
    # train's --normalize-reward leaves the observations alone (norm_obs=False: nothing to
    # apply); a file that normalised them is applied before predict
    import gymnasium as gym
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize
    vec = VecNormalize(DummyVecEnv([lambda: gym.make("Pendulum-v1")]), norm_obs=True)
    vec.reset()
    for _ in range(20):
        vec.step(np.zeros((1, 1), np.float32))
    vec.save(str(tmp_path / "vecnormalize.pkl"))
    loaded = load_vecnormalize(tmp_path / "vecnormalize.pkl")
    assert loaded is not None and not loaded.training and not loaded.norm_reward

    class Seen:
        def __init__(self):
            self.obs = []

        def predict(self, obs, deterministic=True):
            self.obs.append(obs)
            return np.zeros(1), None
    seen = Seen()
    obs = np.array([1.0, 0.0, 0.5], np.float32)
    PolicyState(seen, loaded).predict(obs)
    assert np.allclose(seen.obs[0], vec.normalize_obs(obs))
    vec.close()


def test_bad_recurrent_kwargs_are_refused_before_anything_runs(tmp_path):
    for given, words in (({"policy_kwargs": {"shared_lstm": True}}, "enable_critic_lstm"),
                         ({"policy_kwargs": {"lstm_hidden_size": 0}}, "lstm_hidden_size=0"),
                         ({"policy_kwargs": {"lstm_layers": 2}}, "n_lstm_layers"),
                         ({"rollout_buffer_class": None}, "not of RecurrentPPO")):
        out = tmp_path / "bad"
        with pytest.raises(TrainInputError, match=words):
            train("reach", "recurrent_ppo", 64, 0, out, algo_kwargs=given, progress=False,
                  n_envs=1)
        assert not out.exists()
    with pytest.raises(TrainInputError, match="--mode independent"):
        train("mirror", "ppo", 64, 0, tmp_path / "ind", mode="independent",
              normalize_reward=True, progress=False)
    assert not (tmp_path / "ind").exists()


def test_the_cli_takes_recurrent_ppo_and_normalize_reward(tmp_path, capsys):
    out = tmp_path / "cli"
    assert cli.main(["train", "--task", "reach", "--algo", "recurrent_ppo", "--steps", "64",
                     "--out", str(out), "--eval-every", "64", "--eval-episodes", "1",
                     "--checkpoint-every", "0", "--no-progress", "--n-envs", "1",
                     "--normalize-reward", "--env-kwargs", '{"max_steps": 20}',
                     "--algo-kwargs", json.dumps(TINY)]) == 0
    assert "trained RECURRENT_PPO on reach" in capsys.readouterr().out
    config = json.loads((out / "config.json").read_text())
    assert config["normalize_reward"] and config["policy"] == "MlpLstmPolicy"
    assert (out / "vecnormalize.pkl").is_file()
    assert cli.main(["eval", str(out), "--episodes", "1", "--no-progress"]) == 0
    assert "reach RECURRENT_PPO model.zip" in capsys.readouterr().out
    assert json.loads((out / "eval_results.json").read_text())["vecnormalize"].endswith(
        "vecnormalize.pkl")
    for argv, words in ((["--engine", "rllib", "--algo", "recurrent_ppo"], "--algo recurrent_ppo"),
                        (["--engine", "rllib", "--algo", "ppo", "--normalize-reward"],
                         "--normalize-reward")):
        assert cli.main(["train", "--task", "reach", "--steps", "64", "--out",
                         str(tmp_path / "x"), *argv]) == 2
        assert words in capsys.readouterr().err
    assert cli.main(["train", "--task", "mirror", "--mode", "independent", "--algo", "ppo",
                     "--steps", "64", "--out", str(tmp_path / "y"), "--normalize-reward"]) == 2
    assert "--mode independent" in capsys.readouterr().err
