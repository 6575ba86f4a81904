"""Per-task hyperparameters as data (``mimo_social.train.hyperparams``, issue 29): the shipped
TOML files parse, carry their provenance and are accepted by SB3; every ``--algo-kwargs`` key is
checked before anything is built."""

import fnmatch
import inspect
import json
import shutil
import tomllib
from pathlib import Path

import gymnasium as gym
import pytest
import torch
from sb3_contrib import RecurrentPPO
from stable_baselines3 import PPO, SAC

from mimo_social.envs.catalog import CATALOG
from mimo_social.train import hyperparams as hp
from mimo_social.train.tasks import ALGOS, MODES, MULTI_TASKS, TASKS, TrainInputError

torch.set_num_threads(1)
ROOT = Path(__file__).resolve().parents[2]
CLASSES = {"ppo": PPO, "sac": SAC, "recurrent_ppo": RecurrentPPO}


def _combos():
    for task in [e.name for e in CATALOG]:
        for algo in ALGOS:
            for mode in (MODES if task in MULTI_TASKS else (None,)):
                yield task, algo, mode


def _build(algo, kwargs):
    env = gym.make("Pendulum-v1")
    return CLASSES[algo](hp.POLICIES[algo], env, seed=0, device="cpu",
                         **hp.to_sb3(algo, kwargs))


def test_every_shipped_file_parses_and_every_value_has_its_provenance():
    names = hp.shipped_files()
    assert "default.toml" in names
    assert set(names) - {"default.toml"} <= {f"{e.name}.toml" for e in CATALOG}
    assert {f"{t}.toml" for t in (*TASKS, *MULTI_TASKS)} <= set(names)  # one file per task
    for name in names:
        data = tomllib.loads((hp.DIRECTORY / name).read_text())
        assert set(data) <= {*ALGOS, "run"}, name
        intro, comments = hp.notes(name)
        assert intro, f"{name}: no opening comment"
        found = set()
        for table, values in data.items():
            for key, value in values.items():
                if isinstance(value, dict) and (key in MODES or key == "policy_kwargs"):
                    found |= {(f"{table}.{key}", k) for k in value}
                else:
                    found.add((table, key))
        assert found == set(comments), f"{name}: not one line each: {found ^ set(comments)}"
        assert all(comments.values()), f"{name}: values without a provenance comment"
        for line in (hp.DIRECTORY / name).read_text().splitlines():
            assert len(line) <= 100, f"{name}: {line}"


def test_values_marked_sb3_default_are_sb3_defaults():
    _, comments = hp.notes("default.toml")
    data = tomllib.loads((hp.DIRECTORY / "default.toml").read_text())
    checked = 0
    for algo in ALGOS:
        params = inspect.signature(CLASSES[algo].__init__).parameters
        for key, value in data[algo].items():
            if key != "policy_kwargs" and comments[(algo, key)].startswith(
                    ("SB3 default", "sb3-contrib default")):
                assert params[key].default == value, (algo, key)
                checked += 1
        policy = inspect.signature(CLASSES[algo].policy_aliases[hp.POLICIES[algo]].__init__)
        for key, value in data[algo].get("policy_kwargs", {}).items():
            if key in ("lstm_hidden_size", "n_lstm_layers", "shared_lstm", "enable_critic_lstm"):
                assert comments[(f"{algo}.policy_kwargs", key)].startswith("sb3-contrib default")
                assert policy.parameters[key].default == value, (algo, key)
                checked += 1
    assert checked >= 30


@pytest.mark.parametrize("algo", ALGOS)
def test_the_shipped_network_is_sb3s_default_network(algo):
    shipped = _build(algo, hp.load("reach", algo)).policy
    bare = CLASSES[algo](hp.POLICIES[algo], gym.make("Pendulum-v1"), seed=0,
                         device="cpu").policy
    assert str(shipped) == str(bare)


def test_every_catalogue_task_resolves_for_every_algo_and_mode_and_sb3_accepts_it():
    built = {}
    for task, algo, mode in _combos():
        kwargs, prov = hp.resolve(task, algo, {}, mode=mode, steps=1000)
        assert set(prov) >= {k for k in kwargs if k != "policy_kwargs"}
        assert all(p.startswith("shipped:") for p in prov.values()), prov
        key = (algo, json.dumps(kwargs, sort_keys=True))
        if key not in built:  # the distinct settings only: SB3 takes each of them
            built[key] = _build(algo, kwargs)
    assert len(built) >= 3  # the defaults of both algorithms, mirror's gamma


def test_a_task_without_a_file_gets_default_toml():
    assert not (hp.DIRECTORY / "free_play.toml").is_file()
    assert hp.load("free_play", "ppo") == hp.load("reach", "ppo")
    _, prov = hp.resolve("free_play", "sac", {})
    assert set(prov.values()) == {"shipped:default.toml"}


def test_command_line_values_override_shipped_ones_and_provenance_says_so():
    assert hp.load("mirror", "ppo")["gamma"] == 0.0
    kwargs, prov = hp.resolve("mirror", "ppo", {"gamma": 0.9, "n_steps": 512,
                                                "policy_kwargs": {"net_arch": [32, 32]}})
    assert kwargs["gamma"] == 0.9 and kwargs["n_steps"] == 512
    assert prov["gamma"] == prov["n_steps"] == "command line"
    assert kwargs["policy_kwargs"] == {"net_arch": [32, 32], "activation_fn": "tanh"}
    assert prov["policy_kwargs.net_arch"] == "command line"
    assert prov["policy_kwargs.activation_fn"] == "shipped:default.toml"
    assert prov["batch_size"] == "shipped:default.toml"
    _, prov = hp.resolve("mirror", "ppo", {})
    assert prov["gamma"] == "shipped:mirror.toml"


def test_sac_buffer_is_capped_at_steps_unless_given():
    kwargs, prov = hp.resolve("reach", "sac", {}, steps=5000)
    assert kwargs["buffer_size"] == 5000 and "capped at steps" in prov["buffer_size"]
    kwargs, _ = hp.resolve("reach", "sac", {}, steps=5_000_000)
    assert kwargs["buffer_size"] == 1_000_000
    kwargs, prov = hp.resolve("reach", "sac", {"buffer_size": 20_000}, steps=5000)
    assert kwargs["buffer_size"] == 20_000 and prov["buffer_size"] == "command line"


def test_load_returns_a_fresh_copy():
    hp.load("reach", "ppo")["policy_kwargs"]["net_arch"]["pi"].append(7)
    assert hp.load("reach", "ppo")["policy_kwargs"]["net_arch"]["pi"] == [64, 64]


def test_mode_tables_go_on_top_of_the_task_table(tmp_path, monkeypatch):
    shutil.copy(hp.DIRECTORY / "default.toml", tmp_path / "default.toml")
    (tmp_path / "high_five.toml").write_text(
        "# test\n[ppo]\nn_steps = 1024  # test\n[ppo.shared]\nn_steps = 512  # test\n"
        "[ppo.shared.policy_kwargs]\nnet_arch = [32]  # test\n")
    monkeypatch.setattr(hp, "DIRECTORY", tmp_path)
    assert hp.load("high_five", "ppo")["n_steps"] == 1024
    assert hp.load("high_five", "ppo", "independent")["n_steps"] == 1024
    shared, prov = hp.resolve("high_five", "ppo", {}, mode="shared")
    assert shared["n_steps"] == 512 and prov["n_steps"] == "shipped:high_five.toml [ppo.shared]"
    assert shared["policy_kwargs"] == {"net_arch": [32], "activation_fn": "tanh"}


@pytest.mark.parametrize("given, hint", [
    ({"n_step": 512}, "did you mean 'n_steps'?"),
    ({"learning_rat": 1e-3}, "did you mean 'learning_rate'?"),
    ({"buffer_size": 1000}, "'buffer_size' (an argument of SAC, not of PPO)"),
    ({"policy_kwargs": {"net_arc": [64]}}, "did you mean 'net_arch'?"),
])
def test_unknown_key_is_refused_with_a_suggestion_and_the_allowed_keys(given, hint):
    # validate needs no env and builds no model: the error comes before anything exists
    with pytest.raises(TrainInputError) as e:
        hp.resolve("reach", "ppo", given)
    msg = str(e.value)
    assert hint in msg and "--algo-kwargs" in msg and "allowed: " in msg
    assert "n_steps" in msg or "net_arch" in msg
    with pytest.raises(TrainInputError, match="unknown PPO"):
        hp.validate("ppo", hp.load("reach", "ppo") | given)


@pytest.mark.parametrize("key", sorted(hp.RUNNER_KEYS))
def test_keys_the_runner_sets_are_refused(key):
    with pytest.raises(TrainInputError, match=f"'{key}' is set by train itself"):
        hp.resolve("reach", "sac", {key: 1})


@pytest.mark.parametrize("algo, given, words", [
    ("ppo", {"learning_rate": -1}, ["learning_rate=-1", "positive number", "lin_"]),
    ("ppo", {"learning_rate": "fast"}, ["learning_rate='fast'"]),
    ("ppo", {"learning_rate": "lin_-3"}, ["learning_rate='lin_-3'"]),
    ("ppo", {"n_steps": 0}, ["n_steps=0", "a positive integer"]),
    ("ppo", {"n_steps": 2048.5}, ["n_steps=2048.5"]),
    ("ppo", {"n_steps": True}, ["n_steps=True"]),
    ("ppo", {"batch_size": -64}, ["batch_size=-64", "a positive integer"]),
    ("ppo", {"gamma": 1.5}, ["gamma=1.5", "[0, 1]"]),
    ("ppo", {"gae_lambda": "high"}, ["gae_lambda='high'"]),
    ("ppo", {"ent_coef": -0.1}, ["ent_coef=-0.1", ">= 0"]),
    ("ppo", {"policy_kwargs": [64, 64]}, ["policy_kwargs=[64, 64]", "object"]),
    ("ppo", {"policy_kwargs": {"activation_fn": "swish"}},
     ["activation_fn='swish'", "'tanh'", "'relu'"]),
    ("ppo", {"policy_kwargs": {"net_arch": "big"}}, ["net_arch='big'", "layer sizes"]),
    ("ppo", {"policy_kwargs": {"net_arch": {"pi": [64], "qf": [64]}}}, ["pi and vf"]),
    ("sac", {"policy_kwargs": {"net_arch": [64, -1]}}, ["net_arch=[64, -1]"]),
    ("sac", {"ent_coef": "autox"}, ["ent_coef='autox'", '"auto"']),
    ("sac", {"train_freq": [1, "minute"]}, ["train_freq=[1, 'minute']", "episode"]),
    ("sac", {"tau": 0}, ["tau=0", "(0, 1]"]),
    ("sac", {"buffer_size": 1e6}, ["buffer_size=1000000.0", "a positive integer"]),
    ("sac", {"gradient_steps": 0}, ["gradient_steps=0", "-1"]),
    ("recurrent_ppo", {"policy_kwargs": {"lstm_hidden_size": 0}},
     ["lstm_hidden_size=0", "a positive integer", "RecurrentPPO"]),
    ("recurrent_ppo", {"policy_kwargs": {"n_lstm_layers": 1.5}}, ["n_lstm_layers=1.5"]),
    ("recurrent_ppo", {"policy_kwargs": {"enable_critic_lstm": "yes"}},
     ["enable_critic_lstm='yes'", "true or false"]),
    ("recurrent_ppo", {"policy_kwargs": {"shared_lstm": True}},
     ["shared_lstm=True", "enable_critic_lstm=True", "enable_critic_lstm=false"]),
    ("recurrent_ppo", {"policy_kwargs": {"lstm_hiden_size": 64}},
     ["did you mean 'lstm_hidden_size'?"]),
    ("recurrent_ppo", {"rollout_buffer_class": None},
     ["'rollout_buffer_class' (an argument of PPO, not of RecurrentPPO)"]),
    ("ppo", {"policy_kwargs": {"lstm_hidden_size": 64}},
     ["'lstm_hidden_size' (a policy_kwargs key of RecurrentPPO, not of PPO)"]),
    ("recurrent_ppo", {"n_steps": 0}, ["n_steps=0", "a positive integer"]),
])
def test_bad_values_are_refused_with_the_key_the_value_and_what_is_allowed(algo, given, words):
    with pytest.raises(TrainInputError) as e:
        hp.resolve("reach", algo, given)
    msg = str(e.value)
    assert msg.startswith("--algo-kwargs: ") and "allowed: " in msg
    for w in words:
        assert w in msg, msg


def test_a_bad_shipped_value_names_its_file(tmp_path, monkeypatch):
    shutil.copy(hp.DIRECTORY / "default.toml", tmp_path / "default.toml")
    (tmp_path / "reach.toml").write_text("# test\n[ppo]\ngamma = 2.0  # wrong\n")
    monkeypatch.setattr(hp, "DIRECTORY", tmp_path)
    with pytest.raises(TrainInputError, match=r"hyperparams/reach.toml: gamma=2.0"):
        hp.resolve("reach", "ppo", {})
    (tmp_path / "reach.toml").write_text("# test\n[pop]\n")
    with pytest.raises(TrainInputError, match="unknown table"):
        hp.load("reach", "ppo")


def test_bad_task_algo_mode_and_non_object_kwargs():
    for call in (lambda: hp.load("reachh", "ppo"), lambda: hp.load("reach", "td3"),
                 lambda: hp.load("high_five", "ppo", "solo"),
                 lambda: hp.resolve("reach", "ppo", [("n_steps", 1)])):
        with pytest.raises(TrainInputError):
            call()


def test_good_values_pass():
    for algo, given in [("ppo", {"learning_rate": "lin_3e-4", "clip_range": "lin_0.2",
                                 "target_kl": 0.02, "gamma": 0.0,
                                 "policy_kwargs": {"activation_fn": "relu", "net_arch": [32],
                                                   "optimizer_class": "adamw"}}),
                        ("sac", {"ent_coef": "auto_0.1", "train_freq": [1, "episode"],
                                 "gradient_steps": -1, "learning_starts": 0,
                                 "policy_kwargs": {"net_arch": {"pi": [32], "qf": [64]},
                                                   "activation_fn": torch.nn.ELU}}),
                        ("recurrent_ppo", {"learning_rate": "lin_3e-4", "n_steps": 64,
                                           "policy_kwargs": {"lstm_hidden_size": 32,
                                                             "n_lstm_layers": 2,
                                                             "shared_lstm": True,
                                                             "enable_critic_lstm": False}})]:
        kwargs, _ = hp.resolve("reach", algo, given, steps=2000)
        _build(algo, kwargs)


def test_to_sb3_and_to_json_round_trip_and_the_model_saves(tmp_path):
    kwargs, _ = hp.resolve("reach", "ppo", {"learning_rate": "lin_1e-3", "n_steps": 64,
                                            "batch_size": 32})
    sb3 = hp.to_sb3("ppo", kwargs)
    assert sb3["learning_rate"] == hp.LinearSchedule(1e-3)
    assert sb3["learning_rate"](0.5) == pytest.approx(5e-4)
    assert sb3["policy_kwargs"]["activation_fn"] is torch.nn.Tanh
    assert kwargs["policy_kwargs"]["activation_fn"] == "tanh"  # the input is left alone
    back = hp.to_json(sb3)
    assert json.loads(json.dumps(back)) == back
    assert back["learning_rate"] == "lin_0.001" and back["policy_kwargs"]["activation_fn"] == "tanh"
    assert hp.to_json(hp.to_sb3("ppo", back)) == back
    model = _build("ppo", back)
    model.learn(128)
    model.save(tmp_path / "m.zip")
    assert PPO.load(tmp_path / "m.zip", device="cpu").learning_rate(0.5) == pytest.approx(5e-4)
    assert hp.to_sb3("sac", {"train_freq": [4, "step"]})["train_freq"] == (4, "step")
    assert hp.to_json({"c": torch.optim.AdamW, "d": gym.Env})["c"] == "adamw"
    assert hp.to_json({"d": gym.Env})["d"] == "gymnasium.core.Env"


def test_run_options():
    assert hp.run_options("mirror") == {"normalize_obs": True}
    assert hp.run_options("reach") == {}
    assert hp.run_options("still_face", "scripted") == {"normalize_obs": True}


def test_the_doc_lists_the_shipped_values():
    doc = (ROOT / "docs" / "hyperparameters.md").read_text()
    assert hp.markdown_table() in doc, "regenerate the tables: see docs/hyperparameters.md"


def test_the_files_ship_in_the_wheel():
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())
    patterns = pyproject["tool"]["setuptools"]["package-data"]["mimo_social.train"]
    for name in hp.shipped_files():
        assert any(fnmatch.fnmatch(f"hyperparams/{name}", p) for p in patterns), name
