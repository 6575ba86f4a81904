"""The auxiliary label while cloning (``bc_kwargs`` ``aux_label``, issue 30,
mimo_social/train/auxiliary.py): each pair keeps the step's info, the head learns to name it
through the policy's features, the saved policy is unchanged, DAgger's pairs keep their labels,
a run records the head's accuracy, bad settings are refused by name."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from mimo_social.core.episodes import run_episode
from mimo_social.train import TrainInputError, train
from mimo_social.train.auxiliary import label_of
from mimo_social.train.bc_settings import check_bc
from mimo_social.train.demonstrations import (Cloner, Demonstrator, clone, demonstrator,
                                              record_demonstrations)
from mimo_social.train.envs import make_env

torch.set_num_threads(1)

#: joint attention without eyes: cheap, and its info "target" (the toy the partner looks at,
#: -1 while none) is a label the flat observation cannot name
JA = {"vision": False, "max_steps": 120}


def _ppo(env, seed=0):
    from stable_baselines3 import PPO
    return PPO("MlpPolicy", env, seed=seed, device="cpu", n_steps=64, batch_size=32)


def test_each_pair_keeps_the_step_s_info_as_its_label():
    env = make_env("joint_attention", **JA)
    try:
        demos = record_demonstrations("joint_attention", env, 2, 20_000, aux_label="target")
        seen = []
        rec = Demonstrator(demonstrator("joint_attention"), env)
        for seed in (20_000, 20_001):
            run_episode(env, rec, seed, on_step=lambda e, o, r, t, tr, infos: seen.append(
                int(next(iter(infos.values()))["target"])))
        plain = record_demonstrations("joint_attention", env, 1, 20_000)
    finally:
        env.close()
    assert demos.labels.shape == (len(demos),) and demos.labels.dtype == np.int64
    assert demos.labels.tolist() == seen            # the same episodes, the info step by step
    assert (demos.labels >= 0).sum() > 50 and (demos.labels == -1).any()
    assert plain.labels is None


def test_label_of_takes_whole_numbers_and_refuses_others():
    assert label_of({"t": 2}, "t") == 2 and label_of({"t": 3.0}, "t") == 3
    assert label_of({"t": -1.0}, "t") == -1 and label_of({"t": -7}, "t") == -1
    assert label_of({}, "t") == -1 and label_of({"t": None}, "t") == -1
    for bad in (0.5, "red", True, float("nan")):
        with pytest.raises(TrainInputError, match="aux_label='t'.*not an integer class"):
            label_of({"t": bad}, "t")


def test_the_head_learns_a_label_the_observation_names_and_not_one_it_does_not():
    """A label made from the observation (which half of its first entry's range) is learnt
    through the policy's features; the task's own target, absent from the eyeless observation,
    is not: the head reads what the features can carry, nothing leaks in."""
    env = make_env("joint_attention", **JA)
    try:
        demos = record_demonstrations("joint_attention", env, 3, 20_000, aux_label="target")
        true_target = demos.labels.copy()
        x = demos.obs[:, 0]
        demos.labels = (x > np.median(x)).astype(np.int64)
        readable = clone(_ppo(env), demos, 30, seed=0)
        demos.labels = true_target
        unreadable = clone(_ppo(env), demos, 30, seed=0)
    finally:
        env.close()
    assert readable["aux_accuracy_after"] >= 0.9
    labelled = true_target[true_target >= 0]
    chance = np.bincount(labelled).max() / len(labelled)
    assert unreadable["aux_accuracy_after"] <= chance + 0.1


def test_the_label_trains_the_features_and_the_saved_policy_is_unchanged():
    env = make_env("joint_attention", **JA)
    try:
        demos = record_demonstrations("joint_attention", env, 2, 20_000, aux_label="target")
        with_aux, without = _ppo(env), _ppo(env)
        keys = set(with_aux.policy.state_dict())
        clone(with_aux, demos, 2, seed=0, aux_weight=5.0)
        demos_plain = record_demonstrations("joint_attention", env, 2, 20_000)
        clone(without, demos_plain, 2, seed=0)
    finally:
        env.close()
    assert set(with_aux.policy.state_dict()) == keys      # no head in what is saved
    a = with_aux.policy.mlp_extractor.policy_net[0].weight
    b = without.policy.mlp_extractor.policy_net[0].weight
    assert not torch.allclose(a, b)                       # the same seed, the label's gradient
    cloner = Cloner(with_aux, demos)
    assert cloner.aux is not None and cloner.aux.n_classes == int(demos.labels.max()) + 1


def test_a_run_records_the_label_and_keeps_it_through_dagger_and_rl(tmp_path):
    out = tmp_path / "run"
    train("joint_attention", algo="ppo", steps=256, seed=0, out=out, progress=False,
          mode="scripted",
          eval_episodes=1, env_kwargs=dict(JA, max_steps=60),
          algo_kwargs={"n_steps": 64, "batch_size": 32},
          bc_episodes=2, bc_epochs=2,
          bc_kwargs={"aux_label": "target", "aux_weight": 0.5, "dagger_rounds": 1,
                     "dagger_episodes": 1, "keep_updates": 4, "keep_until": 1.0})
    bc = json.loads((out / "config.json").read_text())["bc"]
    assert bc["aux_label"] == "target" and bc["aux_weight"] == 0.5
    assert 0.0 <= bc["aux_accuracy_after"] <= 1.0
    assert "aux_accuracy_after" in bc["dagger"][0]
    assert bc["keep_updates_made"] > 0


@pytest.mark.parametrize("kwargs, algo, match", [
    ({"aux_label": 3}, "ppo", r"aux_label=3; allowed: None or the name of an info key"),
    ({"aux_label": ""}, "ppo", r"aux_label=''"),
    ({"aux_label": "target", "aux_weight": 0}, "ppo", r"aux_weight=0; allowed: a number > 0"),
    ({"aux_label": "target", "aux_weight": "1"}, "ppo", r"aux_weight='1'"),
    ({"aux_label": "target"}, "sac", r"aux_label='target' with algo 'sac'; allowed: ppo"),
])
def test_bad_auxiliary_settings_are_refused_by_name(kwargs, algo, match):
    with pytest.raises(TrainInputError, match=match):
        check_bc("joint_attention", algo, None, 2, 1, kwargs)


def test_a_key_that_never_holds_a_label_is_refused(tmp_path):
    with pytest.raises(TrainInputError, match="no recorded step had a label"):
        train("joint_attention", algo="ppo", steps=64, seed=0, out=tmp_path / "r",
              mode="scripted", progress=False, eval_episodes=1, env_kwargs=dict(JA, max_steps=30),
              algo_kwargs={"n_steps": 64, "batch_size": 32}, bc_episodes=1, bc_epochs=1,
              bc_kwargs={"aux_label": "no_such_info"})
