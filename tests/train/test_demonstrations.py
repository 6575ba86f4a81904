"""Demonstrations and the behaviour-cloning warm start (issue 30,
mimo_social/train/demonstrations.py): the controller's actions in the learner's form, a cloned
policy that beats an untrained one before any RL step, expression actions, SAC, the run's
records, and bad arguments refused before anything is written."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
import torch
from gymnasium import spaces

from mimo_social.core.wrappers import ActionDecoder
from mimo_social.train import TrainInputError, train
from mimo_social.train.demonstrations import clone, record_demonstrations
from mimo_social.train.envs import make_env
from mimo_social.train.rollouts import evaluate_policy

torch.set_num_threads(1)


def test_encode_is_the_decoder_s_inverse():
    box = ActionDecoder(spaces.Box(-1, 1, (3,), np.float32))
    a = np.array([0.5, -0.25, 1.0], np.float32)
    assert np.array_equal(box(box.encode(a)), a)
    both = ActionDecoder(spaces.Dict({"motors": spaces.Box(-1, 1, (2,), np.float32),
                                      "expression": spaces.Discrete(7)}))
    flat = both.encode({"motors": np.array([0.1, -0.9], np.float32), "expression": 4})
    assert flat.shape == both.space.shape and both.space.contains(flat)
    assert flat[2:].tolist() == [-1, -1, -1, -1, 1, -1, -1]
    back = both(flat)
    assert back["expression"] == 4 and np.allclose(back["motors"], [0.1, -0.9])
    face = ActionDecoder(spaces.Dict({"motors": spaces.Box(-1, 1, (0,), np.float32),
                                      "expression": spaces.Discrete(7)}))
    assert face.encode({"motors": np.zeros(0), "expression": 3}) == 3
    assert face(3)["expression"] == 3


def test_a_cloned_policy_beats_an_untrained_one_before_any_rl_step():
    """Reach: 30 controller episodes cloned into PPO's policy; the mean action then succeeds
    and returns clearly more than the untrained policy on 10 seeded episodes."""
    from stable_baselines3 import PPO
    env = make_env("reach", flat=True)
    try:
        demos = record_demonstrations("reach", env, 30, 20_000)
        assert demos.summary()["success_rate"] == 1.0
        assert demos.obs.shape == (len(demos), env.observation_space.shape[0])
        assert demos.actions.shape == (len(demos), 8)
        model = PPO("MlpPolicy", env, seed=0, device="cpu")
        untrained = evaluate_policy(model, env, 10, 10_000, True)
        res = clone(model, demos, 30, seed=0)
        assert res["loss_after"] < res["loss_before"] / 5
        cloned = evaluate_policy(model, env, 10, 10_000, True)
    finally:
        env.close()
    assert untrained["success_rate"] == 0.0
    assert cloned["success_rate"] >= 0.3
    assert cloned["return_mean"] > untrained["return_mean"] + 100


def test_expression_actions_are_cloned_as_logits_and_as_a_choice():
    from stable_baselines3 import PPO
    # high five: a Box of 8 motors and 7 expression logits
    env = make_env("high_five", flat=True, max_steps=40)
    try:
        demos = record_demonstrations("high_five", env, 2, 20_000)
        logits = demos.actions[:, 8:]
        assert demos.actions.shape[1] == 15
        assert set(np.unique(logits)) <= {-1.0, 1.0} and (logits == 1).sum(axis=1).tolist() == \
            [1] * len(demos)
        model = PPO("MlpPolicy", env, seed=0, device="cpu")
        res = clone(model, demos, 40, seed=0)
        assert res["loss"] == "mse" and res["loss_after"] < res["loss_before"] / 3
        act = model.predict(demos.obs, deterministic=True)[0]
        assert np.mean(act[:, 8:].argmax(1) == logits.argmax(1)) >= 0.9
    finally:
        env.close()
    # mirror: a face-only learner, a Discrete expression (cross-entropy)
    env = make_env("mirror", flat=True, max_steps=40)
    try:
        demos = record_demonstrations("mirror", env, 2, 20_000)
        assert demos.actions.dtype.kind == "i" and demos.actions.ndim == 1
        model = PPO("MlpPolicy", env, seed=0, device="cpu")
        res = clone(model, demos, 40, seed=0)
        assert res["loss"] == "cross-entropy" and res["loss_after"] < res["loss_before"] / 3
        act = model.predict(demos.obs, deterministic=True)[0]
        assert np.mean(act == demos.actions) >= 0.9
    finally:
        env.close()


def test_sac_s_actor_and_the_log_std_after_cloning():
    from stable_baselines3 import PPO, SAC
    env = make_env("reach", flat=True)
    try:
        demos = record_demonstrations("reach", env, 5, 20_000)
        sac = SAC("MlpPolicy", env, seed=0, device="cpu", buffer_size=1000)
        res = clone(sac, demos, 20, seed=0)
        assert res["loss_after"] < res["loss_before"] / 3
        ppo = PPO("MlpPolicy", env, seed=0, device="cpu")
        clone(ppo, demos, 1, seed=0, log_std=-1.5)
        assert torch.allclose(ppo.policy.log_std, torch.full_like(ppo.policy.log_std, -1.5))
        per_dim = [-2.0] * (env.action_space.shape[0] - 1) + [0.5]
        clone(ppo, demos, 1, seed=0, log_std=per_dim)
        assert ppo.policy.log_std.tolist() == per_dim
        nll = clone(PPO("MlpPolicy", env, seed=0, device="cpu"), demos, 5, loss="nll")
        assert nll["loss"] == "nll" and nll["loss_after"] < nll["loss_before"]
    finally:
        env.close()


def test_a_per_dimension_log_std_of_the_wrong_size_is_refused_before_any_episode(tmp_path):
    with pytest.raises(TrainInputError) as err:
        train("reach", "ppo", 512, 0, tmp_path / "run", progress=False, n_envs=1, n_cpus=0,
              algo_kwargs={"n_steps": 256}, bc_episodes=2, bc_kwargs={"log_std": [-1.0, -2.0]})
    msg = str(err.value)
    assert "log_std=[-1.0, -2.0] has 2 values" in msg and "one per action dimension" in msg
    assert not (tmp_path / "run" / "progress.csv").exists()


def test_a_run_records_the_warm_start_and_evaluates_it_before_any_rl_step(tmp_path, capfd):
    out = tmp_path / "run"
    train("reach", "ppo", 512, 0, out, progress=False, n_envs=2, n_cpus=0, eval_episodes=2,
          algo_kwargs={"n_steps": 256, "n_epochs": 1, "batch_size": 512},
          env_kwargs={"max_steps": 100}, bc_episodes=6, bc_epochs=3,
          bc_kwargs={"log_std": -1.0, "batch_size": 32})
    bc = json.loads((out / "config.json").read_text())["bc"]
    assert bc["episodes"] == 6 and bc["seeds"] == [20_000, 20_005] and bc["epochs"] == 3
    assert bc["success_rate"] == 1.0 and bc["controller"] == "ReachController"
    assert bc["demonstrator"] == "scripted"
    assert bc["loss_after"] < bc["loss_before"] and bc["log_std"] == -1.0
    assert bc["batch_size"] == 32 and bc["samples"] > 0
    with open(out / "progress.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert rows[0]["timesteps"] == "0" and rows[0]["before_rl"] == "1"
    assert len(rows) >= 2 and all(r["before_rl"] == "0" for r in rows[1:])
    assert "behaviour cloning: 6 episodes of ReachController" in capfd.readouterr().err


@pytest.mark.parametrize("kwargs, words", [
    ({"bc_episodes": -1}, ["bc_episodes=-1", "integer >= 0"]),
    ({"bc_episodes": 2, "bc_epochs": 0}, ["bc_epochs=0", "integer >= 1"]),
    ({"bc_episodes": 2, "bc_kwargs": {"lr": 0}}, ["lr=0", "number > 0"]),
    ({"bc_episodes": 2, "bc_kwargs": {"epoch": 3}},
     ["epoch", "batch_size, lr, loss, log_std, critic_epochs, keep_updates"]),
    ({"bc_episodes": 2, "bc_kwargs": {"loss": "l1"}}, ["loss='l1'", "mse, nll"]),
    ({"bc_episodes": 0, "bc_kwargs": {"lr": 0.1}}, ["without bc_episodes"]),
    ({"bc_episodes": 2, "algo": "sac", "bc_kwargs": {"loss": "nll"}}, ["with sac: mse"]),
    ({"bc_episodes": 2, "algo": "sac", "bc_kwargs": {"log_std": -1}}, ["log_std=-1", "ppo"]),
    ({"bc_episodes": 2, "bc_kwargs": {"log_std": []}}, ["log_std=[]", "one per action"]),
    ({"bc_episodes": 2, "bc_kwargs": {"log_std": [-1, "a"]}}, ["log_std=[-1, 'a']", "finite"]),
    ({"bc_episodes": 2, "bc_kwargs": {"log_std": [-1, float("nan")]}}, ["log_std=", "finite"]),
    ({"bc_episodes": 2, "algo": "sac", "bc_kwargs": {"critic_epochs": 3}},
     ["critic_epochs=3", "with ppo only"]),
    ({"bc_episodes": 2, "bc_kwargs": {"critic_epochs": -1}}, ["critic_epochs=-1", ">= 0"]),
    ({"bc_episodes": 2, "bc_kwargs": {"keep_updates": 1.5}}, ["keep_updates=1.5", ">= 0"]),
    ({"bc_episodes": 2, "bc_kwargs": {"keep_until": 0}}, ["keep_until=0", "(0, 1000]"]),
    ({"bc_episodes": 2, "bc_kwargs": {"keep_until": 1001}}, ["keep_until=1001", "(0, 1000]"]),
    ({"bc_episodes": 2, "bc_kwargs": {"keep_until": True}}, ["keep_until=True", "(0, 1000]"]),
    ({"bc_episodes": 2, "normalize_reward": True, "bc_kwargs": {"critic_epochs": 2}},
     ["critic_epochs with --normalize-reward"]),
    ({"bc_episodes": 2, "algo": "recurrent_ppo", "bc_kwargs": {"critic_epochs": 2}},
     ["critic_epochs=2 with recurrent_ppo", "pair by pair"]),
    ({"bc_episodes": 2, "algo": "recurrent_ppo", "bc_kwargs": {"dagger_rounds": 1}},
     ["dagger_rounds=1 with recurrent_ppo"]),
    ({"bc_episodes": 2, "algo": "recurrent_ppo", "bc_kwargs": {"aux_label": "target"}},
     ["aux_label='target' with recurrent_ppo"]),
    ({"bc_episodes": 2, "bc_kwargs": {"seq_len": 64}},
     ["seq_len=64 with algo 'ppo'", "recurrent_ppo only"]),
    ({"bc_episodes": 2, "algo": "recurrent_ppo", "bc_kwargs": {"seq_len": 1}},
     ["seq_len=1", "integer >= 2"]),
    ({"bc_episodes": 2, "algo": "recurrent_ppo", "bc_kwargs": {"seq_batch": 0.5}},
     ["seq_batch=0.5", "integer >= 1"]),
    ({"bc_episodes": 2, "bc_kwargs": {"controller": {"stiffness": 2}}},
     ["controller={'stiffness': 2}", "stiffness"]),
    ({"bc_episodes": 2, "bc_kwargs": {"controller": {"frequency": -1.0}}},
     ["controller={'frequency': -1.0}", "frequency"]),
    ({"bc_episodes": 2, "bc_kwargs": {"controller": [6.0]}},
     ["controller=[6.0]", "ReachController's keyword arguments"]),
    ({"bc_episodes": 2, "task": "high_five"}, ["--mode shared", "one learner"]),
    ({"bc_episodes": 2, "bc_kwargs": {"demonstrator": "checking"}},
     ["demonstrator='checking'", "allowed for reach", "['scripted']"]),
    ({"bc_episodes": 2, "task": "joint_attention", "mode": "scripted",
      "bc_kwargs": {"demonstrator": 3}},
     ["demonstrator=3", "['scripted', 'checking', 'sensed']"]),
    ({"bc_episodes": 2, "task": "joint_attention", "mode": "scripted",
      "bc_kwargs": {"demonstrator": "checking", "controller": {"read": "head"}}},
     ["controller={'read': 'head'}", "read"]),
    ({"bc_episodes": 2, "bc_kwargs": {"noise": 1.5}}, ["noise=1.5", "[0, 1]"]),
    ({"bc_episodes": 2, "bc_kwargs": {"noise": "some"}}, ["noise='some'", "[0, 1]"]),
])
def test_bad_arguments_are_refused_before_anything_is_written(tmp_path, kwargs, words):
    kwargs = dict(kwargs)
    task, algo = kwargs.pop("task", "reach"), kwargs.pop("algo", "ppo")
    out = tmp_path / "run"
    with pytest.raises(TrainInputError) as info:
        train(task, algo, 100, 0, out, progress=False, **kwargs)
    for w in words:
        assert w in str(info.value), (w, str(info.value))
    assert not out.exists()


def test_the_demonstrator_takes_the_controller_settings_given():
    """bc_kwargs controller: the demonstrations are the controller made with them (a stiffer
    reach: other actions from the same start), and the run records them."""
    from mimo_social.train.demonstrations import check_bc, demonstrator
    env = make_env("reach", flat=True, max_steps=40)
    try:
        soft = record_demonstrations("reach", env, 1, 20_000)
        stiff = record_demonstrations("reach", env, 1, 20_000, {"frequency": 8.0})
        again = record_demonstrations("reach", env, 1, 20_000, {"frequency": 3.0})
    finally:
        env.close()
    assert np.array_equal(soft.obs[0], stiff.obs[0])
    assert not np.allclose(soft.actions[:5], stiff.actions[:5])
    assert np.array_equal(soft.actions, again.actions)      # 3 Hz is the default
    s = check_bc("reach", "ppo", None, 2, 1, {"controller": {"frequency": 8.0}})
    assert demonstrator("reach", s)().frequency == 8.0
    assert check_bc("reach", "ppo", None, 2, 1, {})["controller"] is None


def test_a_named_demonstrator_records_its_own_episodes():
    """bc_kwargs demonstrator: joint attention's checking follower first looks at the partner's
    face (the scripted follower waits, the zero action, until the partner looks at a toy); the
    settings pick it and its keyword arguments."""
    from mimo_social.tasks.joint_attention import CheckingFollowController
    from mimo_social.train.demonstrations import check_bc, demonstrator
    env = make_env("joint_attention", max_steps=30,
                   per_agent=[{"vision": {"width": 8, "height": 8}}, {}])
    try:
        scripted = record_demonstrations("joint_attention", env, 1, 20_000)
        checking = record_demonstrations("joint_attention", env, 1, 20_000,
                                         demonstrator_name="checking")
    finally:
        env.close()
    assert np.array_equal(scripted.obs["vector"][0], checking.obs["vector"][0])
    assert not np.any(scripted.actions[:5])                  # waiting for the partner's look
    assert np.abs(checking.actions[:5]).max() > 0.05         # turning to the partner's face
    s = check_bc("joint_attention", "ppo", "scripted", 2, 1,
                 {"demonstrator": "checking", "controller": {"look_s": 3.0}})
    made = demonstrator("joint_attention", s)()
    assert isinstance(made, CheckingFollowController) and made.look_s == 3.0
    assert check_bc("joint_attention", "ppo", None, 2, 1, {})["demonstrator"] is None


def test_returns_to_go_stop_at_each_episode_end():
    from mimo_social.train.demonstrations import returns_to_go
    r = np.array([1.0, 1.0, 2.0, 5.0, 1.0], np.float32)
    ends = np.array([False, False, True, False, True])
    np.testing.assert_allclose(returns_to_go(r, ends, 0.5), [2.0, 2.0, 2.0, 5.5, 1.0])


def test_the_critic_fitted_to_the_demonstrations_explains_their_returns():
    from stable_baselines3 import PPO
    from mimo_social.train.demonstrations import fit_critic, returns_to_go
    env = make_env("reach", flat=True, max_steps=100)
    try:
        demos = record_demonstrations("reach", env, 4, 20_000)
        assert len(demos.rewards) == len(demos) and demos.ends.sum() == 4
        assert demos.ends[np.cumsum(demos.lengths) - 1].all()
        # the rewards recorded are the episodes' rewards: each episode's sum is its return
        starts = np.concatenate([[0], np.cumsum(demos.lengths)[:-1]])
        np.testing.assert_allclose([demos.rewards[a:a + n].sum() for a, n in
                                    zip(starts, demos.lengths)], demos.returns, rtol=1e-4)
        ppo = PPO("MlpPolicy", env, seed=0, device="cpu")
        actor = [p.detach().clone() for p in ppo.policy.action_net.parameters()]
        res = fit_critic(ppo, demos, 60, seed=0)
        assert res["critic_explained_variance_after"] > 0.8 > res[
            "critic_explained_variance_before"]
        assert res["return_to_go_mean"] == pytest.approx(
            float(np.mean(returns_to_go(demos.rewards, demos.ends, ppo.gamma))))
        for before, after in zip(actor, ppo.policy.action_net.parameters()):
            assert torch.equal(before, after)        # the actor is left as it was
    finally:
        env.close()


def test_keep_cloning_pulls_the_policy_back_to_the_demonstrations_and_fades():
    from stable_baselines3 import PPO
    from mimo_social.train.demonstrations import Cloner, keep_cloning
    env = make_env("reach", flat=True, max_steps=100)
    try:
        demos = record_demonstrations("reach", env, 4, 20_000)
        ppo = PPO("MlpPolicy", env, seed=0, device="cpu")
        settings = {"keep_updates": 40, "keep_until": 0.5, "lr": 1e-3, "loss": "mse",
                    "batch_size": 64}
        assert keep_cloning(ppo, demos, {**settings, "keep_updates": 0}, 1000, 0) is None
        cb = keep_cloning(ppo, demos, settings, 1000, 0)
        cb.init_callback(ppo)
        loss = Cloner(ppo, demos).mean_loss
        before = loss()
        for t in (0, 100, 250, 500, 900):      # SB3 timesteps at each rollout's start
            ppo.num_timesteps = t
            cb.on_rollout_start()
        # none before the first update; then 40 x (1 - t / 500): 32, 20, then none
        assert cb.updates == 32 + 20 and loss() < before / 2
        late = keep_cloning(ppo, demos, {**settings, "keep_until": 2.0}, 1000, 0)
        late.init_callback(ppo)
        for t in (0, 500, 1000):
            ppo.num_timesteps = t
            late.on_rollout_start()
        # beyond 1: 40 x (1 - t / 2000), still on at the run's end: 30, then 20
        assert late.updates == 30 + 20
    finally:
        env.close()


def test_a_run_goes_on_cloning_during_rl_when_asked(tmp_path):
    out = tmp_path / "run"
    train("reach", "ppo", 1024, 0, out, progress=False, n_envs=1, eval_episodes=1,
          algo_kwargs={"n_steps": 256, "n_epochs": 1, "batch_size": 256},
          env_kwargs={"max_steps": 100}, bc_episodes=3, bc_epochs=2,
          bc_kwargs={"keep_updates": 10, "keep_until": 0.5, "critic_epochs": 2})
    bc = json.loads((out / "config.json").read_text())["bc"]
    # rollouts start at 0, 256, 512, 768 steps: 10 x (1 - 256 / 512) = 5 after the first
    # update, none from 512 on
    assert bc["keep_updates"] == 10 and bc["keep_updates_made"] == 5
    assert bc["critic_epochs"] == 2 and bc["critic_explained_variance_after"] > bc[
        "critic_explained_variance_before"]


def entry_controller(task):
    from mimo_social.envs.catalog import entry
    return entry(task).controller


def test_dagger_labels_the_cloned_policy_s_states_with_the_controller_s_actions():
    from stable_baselines3 import PPO
    from mimo_social.train.dagger import DAGGER_SEED, dagger
    env = make_env("reach", flat=True, max_steps=60)
    try:
        demos = record_demonstrations("reach", env, 3, 20_000)
        ppo = PPO("MlpPolicy", env, seed=0, device="cpu")
        clone(ppo, demos, 5, seed=0)
        settings = {"dagger_rounds": 2, "dagger_episodes": 2, "epochs": 5, "batch_size": 64,
                    "lr": 1e-3, "loss": "mse", "log_std": None}
        heard = []
        joined, rounds = dagger(ppo, "reach", env, demos, settings, 7, report=heard.append)
        # two rounds, then the last policy's play (labelled, not cloned)
        assert [r["round"] for r in rounds] == [1, 2, 3]
        # each play reported as it ends, with its numbers
        assert [h.split(":")[0] for h in heard] == [f"DAgger play {k} of 3" for k in (1, 2, 3)]
        assert all(f"{r['pairs']} pairs" in h for h, r in zip(heard, rounds))
        assert "loss_after" in rounds[1] and "loss_after" not in rounds[2]
        assert rounds[0]["seeds"] == [DAGGER_SEED + 7, DAGGER_SEED + 8]
        assert rounds[1]["seeds"] == [DAGGER_SEED + 1007, DAGGER_SEED + 1008]
        added = sum(r["pairs_added"] for r in rounds)
        assert len(joined) == len(demos) + added == rounds[-1]["pairs"]
        assert joined.ends.sum() == 3 + 6 and len(joined.rewards) == len(joined)
        # the policy kept is the best play's: playing it again on that play's seeds gives
        # that play's numbers
        kept = [r for r in rounds if r["kept"]]
        assert len(kept) == 1 and kept[0]["success_rate"] == max(r["success_rate"]
                                                                 for r in rounds)
        from mimo_social.train.dagger import Labeller
        from mimo_social.train.demonstrations import play
        again = play(Labeller(entry_controller("reach"), env, ppo), env, kept[0]["seeds"][0], 2)
        assert again.summary()["return_mean"] == pytest.approx(kept[0]["return_mean"], rel=1e-5)
        # the labels are the controller's actions (in the action box), not the policy's own
        new = slice(len(demos), len(joined))
        assert np.all(np.abs(joined.actions) <= 1)
        played = ppo.predict(joined.take(np.arange(len(joined))[new]), deterministic=True)[0]
        assert not np.allclose(played, joined.actions[new], atol=1e-3)
    finally:
        env.close()


def played_with_noise(task: str, max_steps: int, noise: float):
    """One demonstration episode (seed 20000) with ``noise``: the recorded pairs, and the
    actions the demonstrator executed."""
    from mimo_social.train.demonstrations import Demonstrator, demonstrator, play
    executed = []

    class Executed(Demonstrator):
        def act(self, env, agent, obs):
            out = super().act(env, agent, obs)
            executed.append(out)
            return out

    env = make_env(task, flat=True, max_steps=max_steps)
    try:
        return play(Executed(demonstrator(task), env, noise=noise), env, 20_000, 1), executed
    finally:
        env.close()


def test_noisy_demonstrations_record_the_controller_s_own_actions_off_its_path():
    """bc_kwargs noise (DART): the executed actions are perturbed, so the states leave the clean
    episode's path, and each recorded action is the controller's own for the state it was in
    (a controller that acts on its state: the reach's PD); the same seed gives the same noisy
    episode; noise 0 is the clean one."""
    env = make_env("reach", flat=True, max_steps=40)
    try:
        clean = record_demonstrations("reach", env, 1, 20_000)
        noisy = record_demonstrations("reach", env, 1, 20_000, noise=0.3)
        again = record_demonstrations("reach", env, 1, 20_000, noise=0.3)
        zero = record_demonstrations("reach", env, 1, 20_000, noise=0.0)
    finally:
        env.close()
    assert np.array_equal(clean.obs[0], noisy.obs[0])           # the same start
    assert np.abs(clean.obs[1:] - noisy.obs[1:]).max() > 1e-3   # then off the path
    assert np.array_equal(noisy.obs, again.obs) and np.array_equal(noisy.actions, again.actions)
    assert np.array_equal(clean.actions, zero.actions)
    assert np.abs(noisy.actions).max() <= 1.0
    # the recorded actions are not the executed (noisy) ones: they are the controller's, which
    # differ from the clean episode's only because the states do
    assert not np.allclose(clean.actions[5:], noisy.actions[5:])
    # the executed actions are the recorded ones plus the noise (sd 0.3, clipped to the Box)
    demos, executed = played_with_noise("reach", 40, 0.3)
    assert np.array_equal(demos.actions, noisy.actions)
    gap = np.stack(executed) - demos.actions
    assert 0.2 < gap.std() < 0.35 and abs(gap.mean()) < 0.05, (gap.std(), gap.mean())


def test_noisy_demonstrations_of_a_discrete_choice_replace_it_at_random():
    """noise on a ``Discrete`` action (mirror's face): that share of the executed choices is
    drawn at random, the recorded ones are the controller's."""
    demos, executed = played_with_noise("mirror", 200, 0.5)
    changed = np.mean(np.array(executed, int) != demos.actions)
    n = make_env("mirror", flat=True, max_steps=10).action_space.n
    assert 0.5 * (1 - 1 / n) - 0.12 < changed < 0.5 * (1 - 1 / n) + 0.12, changed
