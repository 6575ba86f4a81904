"""Multi-agent training: ``mimo-social train|eval|compare`` on high five in the three modes, and
the lockstep that runs independent learners in one world."""

import csv
import json
import threading

import numpy as np
import pytest
import torch

import mimo_social.train as train_mod
from mimo_social import cli
from mimo_social.envs import handover_v0, high_five_v0
from mimo_social.core.gym_adapter import SingleAgentEnv
from mimo_social.train import (Lockstep, LockstepAborted, LockstepError, TrainInputError, compare,
                               evaluate, make_parallel_env, make_sb3_single, make_scripted_env,
                               read_progress, run_lockstep, task_module, train)

torch.set_num_threads(1)

FAST = {"n_steps": 64, "batch_size": 32, "n_epochs": 1}
SHORT = {"max_steps": 50}
STEPS = 512
AGENTS = ["infant_0", "infant_1"]
MODES = ("shared", "independent", "scripted")


def _train_in_thread(timeout_s: float = 120, **kwargs) -> dict:
    """``train(**kwargs)`` in a thread that must end within ``timeout_s`` (no hang)."""
    box = {}

    def target():
        try:
            box["res"] = train(**kwargs)
        except BaseException as e:  # noqa: BLE001
            box["err"] = e

    t = threading.Thread(target=target, daemon=True)
    t.start()
    t.join(timeout_s)
    assert not t.is_alive(), f"train(mode={kwargs.get('mode')}) still running after {timeout_s} s"
    if "err" in box:
        raise box["err"]
    return box["res"]


def _run(out, mode, seed=0, steps=STEPS):
    return _train_in_thread(task="high_five", algo="ppo", steps=steps, seed=seed, out=out,
                            mode=mode, eval_every=256, eval_episodes=2, checkpoint_every=256,
                            progress=False, env_kwargs=SHORT, algo_kwargs=FAST)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("multi")
    return {m: (root / m, _run(root / m, m)) for m in MODES}


def _params(path):
    from stable_baselines3 import PPO
    return {k: v.clone() for k, v in PPO.load(str(path), device="cpu").policy.state_dict().items()}


# -- training outputs ---------------------------------------------------------------------------
@pytest.mark.parametrize("mode", MODES)
def test_each_mode_writes_models_progress_with_agent_columns_and_curve(runs, mode):
    out, res = runs[mode]
    learners = AGENTS if mode != "scripted" else ["infant_0"]
    models = ([f"model_{a}.zip" for a in AGENTS] + [f"best_model_{a}.zip" for a in AGENTS]
              if mode == "independent" else ["model.zip", "best_model.zip"])
    for name in (*models, "config.json", "progress.csv", "episodes.csv", "learning_curve.png"):
        assert (out / name).stat().st_size > 0, name
    assert (out / "learning_curve.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    config = json.loads((out / "config.json").read_text())
    assert config["mode"] == mode and config["agents"] == learners
    assert config["timesteps_done"] == STEPS and res["timesteps"] == STEPS
    p = read_progress(out / "progress.csv")
    assert list(p["timesteps"]) == [256, 512]          # environment steps in every mode
    for a in learners:
        assert np.isfinite(p[f"eval_return_mean_{a}"]).all()
        assert set(np.unique(p[f"eval_success_rate_{a}"])) <= {0.0, 0.5, 1.0}
    assert not any(k.endswith("infant_1") for k in p) or mode != "scripted"
    # the summary columns are the across-agent means
    np.testing.assert_allclose(p["eval_return_mean"],
                               np.mean([p[f"eval_return_mean_{a}"] for a in learners], axis=0),
                               rtol=1e-5)
    # -distance per step over 50 steps, no touch yet
    assert all(-200 < r < 0 for r in p["eval_return_mean"])
    with open(out / "episodes.csv", newline="") as f:
        episodes = list(csv.DictReader(f))
    assert {e["agent"] for e in episodes} == set(learners)
    envs = config["n_envs"]   # env steps spread over the envs (worlds): each ends its episodes
    for a in learners:   # every agent's episodes: at most 50 steps, STEPS / 50 of them in all
        mine = [e for e in episodes if e["agent"] == a]
        assert all(1 <= int(e["length"]) <= 50 for e in mine)
        assert envs * (STEPS // envs // 50) <= len(mine) <= STEPS // 50
    ckpts = sorted(q.name for q in (out / "checkpoints").iterdir())
    if mode == "independent":
        assert ckpts == sorted(f"model_{a}_{n}_steps.zip" for a in AGENTS for n in (256, 512))
    else:
        assert ckpts == ["model_256_steps.zip", "model_512_steps.zip"]


def test_independent_agents_learn_separate_models_deterministically(runs, tmp_path):
    out, _ = runs["independent"]
    p0, p1 = _params(out / "model_infant_0.zip"), _params(out / "model_infant_1.zip")
    assert any(not torch.equal(p0[k], p1[k]) for k in p0)   # two different policies
    # the same seed again: the same models and the same learning curve
    again = tmp_path / "again"
    _run(again, "independent")
    for a in AGENTS:
        before, after = _params(out / f"model_{a}.zip"), _params(again / f"model_{a}.zip")
        assert all(torch.equal(before[k], after[k]) for k in before), a
    pa, pb = read_progress(out / "progress.csv"), read_progress(again / "progress.csv")
    for k in pa:
        if k != "wall_time_s":
            np.testing.assert_array_equal(pa[k], pb[k], err_msg=k)


# -- eval ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("mode", MODES)
def test_eval_reloads_each_kind_and_reports_per_agent(runs, mode, capsys):
    out, _ = runs[mode]
    learners = AGENTS if mode != "scripted" else ["infant_0"]
    a = evaluate(out, episodes=2, seed=3)
    b = evaluate(out, episodes=2, seed=3)
    assert sorted(a["agents"]) == learners and a["mode"] == mode
    for agent in learners:
        r = a["agents"][agent]
        assert len(r["returns"]) == 2 and all(n <= 50 for n in r["lengths"])
        assert r["returns"] == b["agents"][agent]["returns"]   # deterministic, seeded
        assert r["success_rate"] in (0.0, 0.5, 1.0)
    if mode == "independent":
        assert a["models"] == {ag: str(out / f"model_{ag}.zip") for ag in AGENTS}
    saved = json.loads((out / "eval_results.json").read_text())
    assert saved["episodes"] == 2 and sorted(saved["agents"]) == learners
    # the final evaluation of training used the same policies on the same kind of env
    last = read_progress(out / "progress.csv")
    again = evaluate(out, episodes=2, seed=10_000)     # the seeds of training's evaluations
    for agent in learners:
        assert again["agents"][agent]["return_mean"] == pytest.approx(
            last[f"eval_return_mean_{agent}"][-1], rel=1e-4)
    assert cli.main(["eval", str(out), "--episodes", "1", "--model", "best"]) == 0
    printed = capsys.readouterr().out
    assert all(f"  {agent} (" in printed for agent in learners)


def test_eval_writes_frames_of_a_multi_agent_run(runs, tmp_path):
    out, _ = runs["shared"]
    frames = tmp_path / "frames"
    assert cli.main(["eval", str(out), "--episodes", "1", "--frames", str(frames),
                     "--frame-every", "25"]) == 0
    pngs = sorted(frames.glob("*.png"))
    assert [q.name for q in pngs] == ["ep000_00000.png", "ep000_00025.png", "ep000_00050.png"]
    assert pngs[0].read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("mode", ["independent", "scripted"])
def test_eval_records_a_multi_agent_run(runs, mode, tmp_path):
    out, _ = runs[mode]
    rrd = tmp_path / "ep.rrd"
    assert cli.main(["eval", str(out), "--episodes", "2", "--record", str(rrd)]) == 0
    assert rrd.stat().st_size > 10_000
    assert json.loads((out / "eval_results.json").read_text())["record"] == str(rrd)


def test_eval_of_independent_run_rejects_a_single_model_path(runs):
    out, _ = runs["independent"]
    with pytest.raises(FileNotFoundError, match="one model per agent"):
        evaluate(out, episodes=1, model=str(out / "model_infant_0.zip"))


def test_cli_trains_shared_mode_on_two_worlds(tmp_path, capsys):
    out = tmp_path / "two"
    assert cli.main(["train", "--task", "high_five", "--algo", "ppo", "--steps", "128",
                     "--out", str(out), "--n-envs", "2", "--eval-every", "64",
                     "--eval-episodes", "1", "--checkpoint-every", "0", "--no-progress",
                     "--env-kwargs", '{"max_steps": 30}',
                     "--algo-kwargs", '{"n_steps": 32, "batch_size": 64, "n_epochs": 1}']) == 0
    printed = capsys.readouterr().out
    assert "trained PPO on high_five (shared) for 128 steps" in printed
    assert "  infant_0: return" in printed and "  infant_1: return" in printed
    config = json.loads((out / "config.json").read_text())
    assert config["mode"] == "shared" and config["n_envs"] == 2
    # 2 worlds x 2 agents x 32 steps = one rollout of 64 environment steps
    assert list(read_progress(out / "progress.csv")["timesteps"]) == [64, 128]
    with open(out / "episodes.csv", newline="") as f:
        episodes = list(csv.DictReader(f))
    assert sum(e["agent"] == "infant_0" for e in episodes) >= 3   # 2 worlds, 30-step episodes


def test_shared_sac_replay_buffer_holds_every_agents_transitions(tmp_path):
    res = train("high_five", "sac", 64, 0, tmp_path / "sac", eval_every=64, eval_episodes=1,
                checkpoint_every=0, progress=False, env_kwargs={"max_steps": 20},
                algo_kwargs={"learning_starts": 32, "batch_size": 16})
    config = json.loads((tmp_path / "sac" / "config.json").read_text())
    assert config["algo_kwargs"]["buffer_size"] == 128           # 64 env steps x 2 agents
    assert res["timesteps"] == 64 and (tmp_path / "sac" / "model.zip").exists()


# -- compare ------------------------------------------------------------------------------------
def test_compare_multi_agent_averages_agents_and_keeps_their_columns(tmp_path):
    png = compare("high_five", ["ppo"], seeds=2, steps=128, out=tmp_path, mode="independent",
                  eval_every=64, eval_episodes=1, checkpoint_every=0, progress=False,
                  env_kwargs={"max_steps": 30}, algo_kwargs={"n_steps": 32, "batch_size": 32,
                                                             "n_epochs": 1})
    assert png.stat().st_size > 0
    with open(tmp_path / "compare.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert {(r["algo"], r["seed"]) for r in rows} == {("ppo", "0"), ("ppo", "1")}
    for r in rows:
        per_agent = [float(r[f"eval_return_mean_{a}"]) for a in AGENTS]
        assert float(r["eval_return_mean"]) == pytest.approx(np.mean(per_agent), rel=1e-4)
    assert json.loads((tmp_path / "ppo_seed1" / "config.json").read_text())["mode"] == "independent"


# -- the lockstep of independent learners ---------------------------------------------------------
def _hub_env():
    return make_parallel_env("high_five", max_steps=20)


def _zero(env, agent):
    return np.zeros(env.action_space(agent).shape, np.float32)


@pytest.mark.timeout(60)
def test_lockstep_steps_the_world_once_per_round_and_hands_each_agent_its_result():
    env = _hub_env()
    hub = Lockstep(env)
    got = {a: [] for a in AGENTS}
    rng = np.random.default_rng(0)
    actions = [{a: rng.uniform(-1, 1, env.action_space(a).shape).astype(np.float32)
                for a in AGENTS} for _ in range(25)]

    def job(agent):
        view = hub.view(agent)
        view.reset(seed=7)
        for k in range(25):   # 20 steps, a reset (truncation), 5 more
            obs, r, term, trunc, info = view.step(actions[k][agent])
            got[agent].append((obs, r, term or trunc))
            if term or trunc:
                view.reset()

    run_lockstep(hub, {a: (lambda a=a: job(a)) for a in AGENTS})
    assert hub.env_steps == 25
    ref = _hub_env()        # the same actions, stepped directly
    ref.reset(seed=7)
    for k in range(25):
        obs, rew, term, trunc, _ = ref.step(actions[k])
        for a in AGENTS:
            np.testing.assert_array_equal(got[a][k][0], obs[a])
            assert got[a][k][1] == rew[a] and got[a][k][2] == (term[a] or trunc[a])
        if not ref.agents:
            ref.reset()


@pytest.mark.timeout(60)
def test_lockstep_renders_eyes_in_the_thread_that_made_the_env():
    """Vision renders through a GL context bound to one thread: the learners' threads must never
    step the env themselves (EGL_BAD_ACCESS otherwise)."""
    env = make_parallel_env("high_five", max_steps=5, vision={"width": 16, "height": 16})
    stepped_in = set()
    hub = Lockstep(env, on_step=lambda *a: stepped_in.add(threading.current_thread().name),
                   on_reset=lambda *a: stepped_in.add(threading.current_thread().name))
    frames = []

    def job(agent):
        v = hub.view(agent)
        v.reset(seed=0)
        for _ in range(7):
            obs, _, term, trunc, _ = v.step(_zero(env, agent))
            frames.append(obs)
            if term or trunc:
                v.reset()

    run_lockstep(hub, {a: (lambda a=a: job(a)) for a in AGENTS})
    assert stepped_in == {threading.current_thread().name}
    assert hub.env_steps == 7 and len(frames) == 14
    assert np.ptp(np.stack(frames), axis=0).max() > 0      # the observations (eyes) change


@pytest.mark.timeout(60)
def test_lockstep_error_in_one_learner_aborts_the_other_without_hanging():
    env = _hub_env()
    hub = Lockstep(env, poll_s=0.05)
    seen = {}

    def failing():
        v = hub.view("infant_0")
        v.reset(seed=0)
        for _ in range(3):
            v.step(_zero(env, "infant_0"))
        raise RuntimeError("boom in infant_0's learner")

    def endless():
        v = hub.view("infant_1")
        v.reset(seed=0)
        try:
            while True:
                _, _, term, trunc, _ = v.step(_zero(env, "infant_1"))
                if term or trunc:
                    v.reset()
        except LockstepAborted as e:
            seen["aborted"] = str(e)
            raise

    with pytest.raises(RuntimeError, match="boom in infant_0"):
        run_lockstep(hub, {"infant_0": failing, "infant_1": endless})
    assert "boom" in seen["aborted"]
    assert hub.env_steps == 3


@pytest.mark.timeout(60)
@pytest.mark.parametrize("budgets", [(5, 10), (10, 5)])
def test_lockstep_learners_with_different_step_budgets_get_a_clear_error(budgets):
    env = make_parallel_env("high_five", max_steps=100)
    hub = Lockstep(env)

    def steps(agent, n):
        def job():
            v = hub.view(agent)
            v.reset(seed=0)
            for _ in range(n):
                v.step(_zero(env, agent))
        return job

    with pytest.raises(LockstepError, match="same number of steps"):
        run_lockstep(hub, {"infant_0": steps("infant_0", budgets[0]),
                           "infant_1": steps("infant_1", budgets[1])})
    assert hub.env_steps == 5


@pytest.mark.timeout(90)
def test_independent_training_with_a_failing_evaluation_raises_instead_of_hanging(
        tmp_path, monkeypatch):
    from mimo_social.train import independent

    def broken(*args, **kwargs):
        raise RuntimeError("evaluation broke")

    monkeypatch.setattr(independent, "evaluate_agents", broken)
    with pytest.raises(RuntimeError, match="evaluation broke"):
        _train_in_thread(timeout_s=60, task="high_five", algo="ppo", steps=256, seed=0,
                         out=tmp_path / "broken", mode="independent", n_envs=1, n_cpus=0,
                         eval_every=64, eval_episodes=1, checkpoint_every=0, progress=False,
                         env_kwargs={"max_steps": 30}, algo_kwargs=FAST)
    assert not [t for t in threading.enumerate() if t.name.startswith("learn-")]  # all ended
    with open(tmp_path / "broken" / "episodes.csv", newline="") as f:   # stopped at step 64
        assert [e["timesteps"] for e in csv.DictReader(f)] == ["30", "30", "60", "60"]


def test_scripted_mode_trains_and_evaluates_on_the_same_observations():
    kw = dict(max_steps=10)
    gym_env = make_sb3_single(SingleAgentEnv(high_five_v0.scripted_env(**kw)))
    flat = make_scripted_env("high_five", **kw)
    assert flat.possible_agents == ["infant_0"]
    a, _ = gym_env.reset(seed=4)
    b, _ = flat.reset(seed=4)
    np.testing.assert_array_equal(a, b["infant_0"])
    act = np.linspace(-1, 1, gym_env.action_space.shape[0]).astype(np.float32)
    a = gym_env.step(act)
    b = flat.step({"infant_0": act})
    np.testing.assert_array_equal(a[0], b[0]["infant_0"])
    assert a[1] == b[1]["infant_0"]


def test_a_face_only_learner_sees_through_the_cnn_by_default(tmp_path):
    """Mirror with its scripted partner, default observations: the learner's eyes go through
    the convolutional encoder, in training and when its run is evaluated again."""
    out = tmp_path / "mirror_cnn"
    train_mod.train("mirror", "ppo", 128, 0, out, mode="scripted", eval_every=128,
                    eval_episodes=1, checkpoint_every=0, progress=False, n_envs=1,
                    env_kwargs={"max_steps": 16},
                    algo_kwargs={"n_steps": 64, "batch_size": 32, "n_epochs": 1})
    config = json.loads((out / "config.json").read_text())
    assert config["policy"] == "MultiInputPolicy"
    assert config["observation"] == {"flat": False, "frame_stack": 1}
    from stable_baselines3 import PPO
    from torch import nn
    from mimo_social.train.encoders import EyesExtractor
    extractor = PPO.load(str(out / "model.zip"), device="cpu").policy.features_extractor
    assert isinstance(extractor, EyesExtractor)
    assert any(isinstance(m, nn.Conv2d) for m in extractor.modules())
    res = train_mod.evaluate(out, episodes=1, both=True)
    assert res["episodes"] == 1 and "stochastic" in res


def test_a_face_only_learner_trains_and_evaluates_with_a_discrete_expression(tmp_path):
    """Mirror with its scripted partner, flat observations: the learner's only action is its
    face, a Discrete(7) in training and in evaluation alike."""
    out = tmp_path / "mirror"
    train_mod.train("mirror", "ppo", 128, 0, out, mode="scripted", eval_every=128,
                    eval_episodes=1, checkpoint_every=0, progress=False, flat_obs=True,
                    env_kwargs={"max_steps": 16}, normalize_obs=True, n_envs=1,
                    algo_kwargs={"n_steps": 64, "batch_size": 32, "n_epochs": 1})
    res = train_mod.evaluate(out, episodes=1)
    assert res["episodes"] == 1
    # the running input statistics were learnt from the training batches and saved in the model
    from stable_baselines3 import PPO
    from mimo_social.train.obs_norm import RunningNorm
    norm = PPO.load(str(out / "model.zip"), device="cpu").policy.features_extractor
    assert isinstance(norm, RunningNorm) and float(norm.count) >= 128
    assert float(norm.var.max()) > 0 and float(norm.mean.abs().max()) > 0.1
    assert norm.min_std == 0.0
    flat = make_scripted_env("mirror", max_steps=16, flat=True)
    assert flat.action_space("infant_0").n == 7


# -- bad input ----------------------------------------------------------------------------------
def test_bad_mode_task_and_options_say_what_is_allowed(tmp_path, monkeypatch, capsys):
    with pytest.raises(TrainInputError, match="one agent"):
        train("reach", "ppo", 64, 0, tmp_path / "a", mode="independent")
    with pytest.raises(TrainInputError, match="allowed: shared, independent, scripted"):
        train("high_five", "ppo", 64, 0, tmp_path / "b", mode="together")
    with pytest.raises(TrainInputError, match="n_cpus=3"):   # more workers than worlds
        train("high_five", "ppo", 64, 0, tmp_path / "c", mode="independent", n_envs=2, n_cpus=3)
    with pytest.raises(TrainInputError, match="allowed: reach.*high_five"):
        train("juggle", "ppo", 64, 0, tmp_path / "d")
    # a catalogued social task whose module lacks scripted_env: named, with what it needs
    monkeypatch.delattr(handover_v0, "scripted_env")
    with pytest.raises(TrainInputError, match=r"handover_v0 lacks scripted_env.*"
                                              r"needs parallel_env and scripted_env"):
        task_module("handover")
    with pytest.raises(TrainInputError, match="lacks scripted_env"):
        train("handover", "ppo", 64, 0, tmp_path / "e")
    assert not (tmp_path / "e").exists()       # nothing written before the error
    # shared mode needs one space for all agents
    with pytest.raises(TrainInputError, match="same observation and action space"):
        train("high_five", "ppo", 64, 0, tmp_path / "f", progress=False,
              env_kwargs={"per_agent": [{"hands": "five_fingers"}, {}]})
    # the command line: exit code 2 and the message
    assert cli.main(["train", "--task", "reach", "--algo", "ppo", "--steps", "64", "--out",
                     str(tmp_path / "g"), "--mode", "scripted"]) == 2
    assert "one agent" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        cli.main(["train", "--task", "high_five", "--algo", "ppo", "--steps", "64", "--out",
                  str(tmp_path / "h"), "--mode", "bogus"])


def test_shared_mode_space_check_takes_discrete_actions():
    """Mirror's face-only agents act with Discrete(7): one shared policy is allowed (it crashed
    on ``Discrete.low``); two different Discrete spaces are still refused."""
    from gymnasium import spaces
    from mimo_social.core.wrappers import FlattenParallel
    from mimo_social.envs import mirror_v0
    from mimo_social.train.multi import check_shared_spaces
    env = FlattenParallel(mirror_v0.parallel_env())
    check_shared_spaces(env, "mirror")

    class Uneven:
        possible_agents = ["a", "b"]

        def observation_space(self, agent):
            return spaces.Box(0, 1, (3,))

        def action_space(self, agent):
            return spaces.Discrete(7 if agent == "a" else 5)
    with pytest.raises(TrainInputError, match="flat action spaces of a and b differ"):
        check_shared_spaces(Uneven(), "toy")
