"""Categorical heads (issue 30, mimo_social/train/categorical_heads.py): a learner's face sampled
as a categorical choice beside its Gaussian motors: the distribution's probabilities, the
actions it gives the env, cloning, PPO training, saving and loading, and the runs it is refused
for."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch
from gymnasium import spaces
from torch.distributions import Categorical, Normal

from mimo_social.core.action_decoder import LOGIT_HIGH, LOGIT_LOW, ActionDecoder
from mimo_social.train import TrainInputError, train
from mimo_social.train.categorical_heads import (CategoricalHeads, CategoricalHeadsPolicy,
                                                 check_groups, learner_groups)
from mimo_social.train.demonstrations import clone, record_demonstrations
from mimo_social.train.envs import make_env

torch.set_num_threads(1)

FACE = spaces.Dict({"motors": spaces.Box(-1, 1, (8,), np.float32),
                    "expression": spaces.Discrete(7)})


def _heads(groups=((8, 7),), dim=15, latent=6, log_std=-1.0, seed=0):
    torch.manual_seed(seed)
    dist = CategoricalHeads(dim, [list(g) for g in groups])
    net, std = dist.proba_distribution_net(latent, log_std)
    return dist, net, std


def test_the_decoder_names_its_logit_groups():
    assert ActionDecoder(FACE).categorical_groups == ((8, 7),)
    voice = spaces.Dict({"motors": spaces.Box(-1, 1, (3,), np.float32),
                         "expression": spaces.Discrete(7), "voice": spaces.Discrete(4),
                         "loudness": spaces.Box(0, 1, (1,), np.float32)})
    assert ActionDecoder(voice).categorical_groups == ((3, 7), (10, 4))
    assert ActionDecoder(spaces.Box(-1, 1, (5,), np.float32)).categorical_groups == ()
    face_only = spaces.Dict({"motors": spaces.Box(-1, 1, (0,), np.float32),
                             "expression": spaces.Discrete(7)})
    assert ActionDecoder(face_only).categorical_groups == ()


def test_log_prob_is_the_motors_gaussian_plus_the_face_s_categorical():
    dist, net, std = _heads()
    mean = net(torch.randn(32, 6))
    dist.proba_distribution(mean, std)
    acts = dist.sample()
    want = (Normal(mean[:, :8], std.exp()).log_prob(acts[:, :8]).sum(-1)
            + Categorical(logits=mean[:, 8:]).log_prob(acts[:, 8:].argmax(-1)))
    assert torch.allclose(dist.log_prob(acts), want, atol=1e-6)
    ent = (Normal(mean[:, :8], std.exp()).entropy().sum(-1)
           + Categorical(logits=mean[:, 8:]).entropy())
    assert torch.allclose(dist.entropy(), ent, atol=1e-6)
    assert std.shape == (8,)            # one log-std per motor, none for the logits


def test_sampled_faces_follow_the_categorical_probabilities_in_the_decoder_s_encoding():
    dist, net, std = _heads(log_std=-3.0)
    logits = torch.tensor([0.0, 2.0, 0.0, 1.0, -9.0, -9.0, -9.0])
    mean = torch.cat([torch.full((20000, 8), 0.3), logits.expand(20000, 7)], dim=1)
    with torch.no_grad():
        dist.proba_distribution(mean, std)
        acts = dist.sample()
    face = acts[:, 8:]
    assert set(face.unique().tolist()) == {LOGIT_LOW, LOGIT_HIGH}
    assert (face == LOGIT_HIGH).sum(1).tolist() == [1] * 20000
    freq = np.bincount(face.argmax(1).numpy(), minlength=7) / 20000
    assert np.allclose(freq, torch.softmax(logits, 0).numpy(), atol=0.02)
    assert abs(float(acts[:, :8].mean()) - 0.3) < 0.01
    decoder = ActionDecoder(FACE)
    decoded = decoder(acts[0].numpy())
    assert decoded["expression"] == int(face[0].argmax())
    mode = dist.mode()
    assert (mode[:, 8:].argmax(1) == 1).all() and torch.allclose(mode[:, :8], mean[:, :8])


def test_two_groups_and_no_motors():
    dist, net, std = _heads(groups=((0, 3), (4, 2)), dim=6)
    dist.proba_distribution(net(torch.randn(10, 6)), std)
    acts = dist.sample()
    assert (acts[:, :3] == LOGIT_HIGH).sum(1).tolist() == [1] * 10
    assert (acts[:, 4:] == LOGIT_HIGH).sum(1).tolist() == [1] * 10
    assert std.shape == (1,) and dist.log_prob(acts).shape == (10,)
    only, net, std = _heads(groups=((0, 4),), dim=4)
    only.proba_distribution(net(torch.randn(3, 6)), std)
    assert std.shape == (0,) and torch.isfinite(only.log_prob(only.sample())).all()
    assert only.clone_loss(only.mode()).item() > 0


@pytest.mark.parametrize("groups, words", [
    ((), "at least one"),
    (((8, 1),), "n >= 2"),
    (((10, 7),), "within the action's 15"),
    (((2, 4), (5, 3)), "not overlapping"),
    (((8.0, 7),), "two integers"),
])
def test_bad_groups_are_refused(groups, words):
    with pytest.raises(ValueError, match=words):
        check_groups(groups, 15)


def test_a_learner_without_a_logit_group_is_named():
    with pytest.raises(TrainInputError, match="learner 'infant_0'.*a Box of motors"):
        learner_groups(spaces.Box(-1, 1, (4,), np.float32), "infant_0")
    face_only = spaces.Dict({"motors": spaces.Box(-1, 1, (0,), np.float32),
                             "expression": spaces.Discrete(7)})
    with pytest.raises(TrainInputError, match="already one categorical choice"):
        learner_groups(face_only, "infant_0")
    assert learner_groups(FACE, "infant_0") == [[8, 7]]


def test_cloning_trains_the_face_by_cross_entropy_and_ppo_saves_and_loads(tmp_path):
    """High five's learner (8 motors, 7 expression logits): the scripted episodes cloned into
    PPO with categorical heads, the clone's most likely face is the controller's on >= 90 % of
    its states; a short PPO update keeps the policy, which loads back with its groups and
    predicts the same."""
    from stable_baselines3 import PPO
    env = make_env("high_five", flat=True, max_steps=40)
    try:
        demos = record_demonstrations("high_five", env, 2, 20_000)
        model = PPO(CategoricalHeadsPolicy, env, seed=0, device="cpu", n_steps=64,
                    batch_size=32, n_epochs=1,
                    policy_kwargs={"categorical_groups": [[8, 7]]})
        assert model.policy.log_std.shape == (8,)
        res = clone(model, demos, 40, seed=0, log_std=[-2.0] * 8)
        assert res["loss"] == "mse + cross-entropy"
        assert res["loss_after"] < res["loss_before"] / 3
        act = model.predict(demos.obs, deterministic=True)[0]
        assert np.mean(act[:, 8:].argmax(1) == demos.actions[:, 8:].argmax(1)) >= 0.9
        sampled = model.predict(demos.obs, deterministic=False)[0]
        assert ((sampled[:, 8:] == LOGIT_HIGH).sum(1) == 1).all()
        model.learn(64)
        model.save(tmp_path / "m.zip")
        back = PPO.load(tmp_path / "m.zip", device="cpu")
        assert isinstance(back.policy, CategoricalHeadsPolicy)
        assert back.policy.action_dist.groups == ((8, 7),)
        assert np.array_equal(back.predict(demos.obs[:20], deterministic=True)[0],
                              model.predict(demos.obs[:20], deterministic=True)[0])
    finally:
        env.close()


def test_a_run_with_categorical_heads_records_them_and_clones_its_face(tmp_path):
    out = tmp_path / "run"
    train("high_five", "ppo", 128, 0, out, progress=False, mode="scripted", n_envs=1, n_cpus=0,
          env_kwargs={"max_steps": 40}, algo_kwargs={"n_steps": 64, "batch_size": 32},
          eval_episodes=1, bc_episodes=1, bc_epochs=2,
          bc_kwargs={"log_std": [-1.0] * 8, "keep_updates": 2}, categorical_heads=True)
    cfg = json.loads((out / "config.json").read_text())
    assert cfg["categorical_heads"] is True and cfg["categorical_groups"] == [[8, 7]]
    assert cfg["policy"] == "CategoricalHeadsPolicy"
    assert cfg["bc"]["loss"] == "mse + cross-entropy"
    from stable_baselines3 import PPO
    assert PPO.load(out / "model.zip", device="cpu").policy.log_std.tolist() != [0.0] * 8


@pytest.mark.parametrize("kwargs, words", [
    ({"task": "high_five", "algo": "sac", "mode": "scripted"}, "allowed: ppo, a2c"),
    ({"task": "high_five", "algo": "ppo", "mode": "independent"}, "--mode independent"),
    ({"task": "reach", "algo": "ppo", "mode": None}, "'reach' has no logit group"),
    ({"task": "mirror", "algo": "ppo", "mode": "scripted"}, "already one categorical choice"),
])
def test_runs_it_does_not_fit_are_refused(tmp_path, kwargs, words):
    with pytest.raises(TrainInputError, match=words):
        train(kwargs["task"], kwargs["algo"], 128, 0, tmp_path / "run", progress=False,
              mode=kwargs["mode"], n_envs=1, n_cpus=0, categorical_heads=True)
    assert not (tmp_path / "run" / "progress.csv").exists()


def test_categorical_heads_must_be_a_bool(tmp_path):
    with pytest.raises(TrainInputError, match="categorical_heads='yes'; allowed: True or False"):
        train("high_five", "ppo", 128, 0, tmp_path / "run", progress=False, mode="scripted",
              categorical_heads="yes")


def test_the_cli_trains_with_categorical_heads_and_eval_loads_the_run(tmp_path, capsys):
    from mimo_social import cli
    out = tmp_path / "cli"
    assert cli.main(["train", "--task", "high_five", "--mode", "scripted", "--algo", "ppo",
                     "--steps", "64", "--out", str(out), "--eval-episodes", "1",
                     "--checkpoint-every", "0", "--no-progress", "--n-envs", "1",
                     "--categorical-heads", "--env-kwargs", '{"max_steps": 20}',
                     "--algo-kwargs", '{"n_steps": 64, "batch_size": 32}']) == 0
    assert json.loads((out / "config.json").read_text())["policy"] == "CategoricalHeadsPolicy"
    assert cli.main(["eval", str(out), "--episodes", "1", "--no-progress"]) == 0
    assert "high_five PPO" in capsys.readouterr().out
    assert cli.main(["train", "--task", "high_five", "--engine", "rllib", "--algo", "ppo",
                     "--steps", "64", "--out", str(tmp_path / "x"), "--categorical-heads"]) == 2
    assert "--categorical-heads: for --engine sb3" in capsys.readouterr().err


def test_a_shared_policy_gets_categorical_heads_for_every_agent(tmp_path):
    """High five, --mode shared: both infants (8 motors and a face each) share one policy with
    the face as a categorical head."""
    from stable_baselines3 import PPO
    out = tmp_path / "shared"
    train("high_five", "ppo", 128, 0, out, progress=False, mode="shared", n_envs=1, n_cpus=0,
          env_kwargs={"max_steps": 20}, algo_kwargs={"n_steps": 64, "batch_size": 32},
          eval_episodes=1, categorical_heads=True)
    cfg = json.loads((out / "config.json").read_text())
    assert cfg["categorical_groups"] == [[8, 7]] and len(cfg["agents"]) == 2
    model = PPO.load(out / "model.zip", device="cpu")
    assert isinstance(model.policy, CategoricalHeadsPolicy)
    assert model.policy.log_std.shape == (8,)
