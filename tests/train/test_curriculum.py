"""Curricula (issue 30): stages as data, checked before training; the envs in the worker
processes switch at their next reset; stages advance by steps and by success; config.json,
progress.csv and stderr record it (mimo_social/train/curriculum.py)."""

from __future__ import annotations

import csv
import functools
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from mimo_social.train import TrainInputError, train
from mimo_social.train.curriculum import (DIRECTORY, CurriculumController, CurriculumEnv,
                                          check_curriculum, load_curriculum,
                                          monitored_curriculum_env, shipped_curricula)
from mimo_social.train.workers import TimedSubprocVecEnv

FLAT = {"flat": True, "frame_stack": 1}
ROOT = Path(__file__).resolve().parents[2]


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# -- the data and its checks ---------------------------------------------------------------------
def test_the_shipped_selfbody_curriculum_goes_from_a_few_targets_to_all():
    assert "selfbody" in shipped_curricula()
    cur = load_curriculum("selfbody", "selfbody")
    check_curriculum(cur, "selfbody", FLAT, {})
    first, last = cur.stages[0], cur.stages[-1]
    assert len(first.draw["target"]) == 4 and first.until_success is not None
    assert last.draw == {} and last.env_kwargs == {} and last.until_steps is None
    assert cur.evaluate == "final"
    # package data: the curricula ship with the package as the hyperparameters do
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())
    shipped = data["tool"]["setuptools"]["package-data"]["mimo_social.train"]
    assert "curricula/*.toml" in shipped
    assert (DIRECTORY / "selfbody.toml").is_file()


STAGE_OK = {"name": "a", "until": {"steps": 100}}


@pytest.mark.parametrize("spec, words", [
    ({"stages": []}, ["stages=[]", "non-empty list"]),
    ({"stages": [{"nme": "x", "until": {"steps": 5}}, {}]}, ["stage 0", "nme", "allowed"]),
    ({"stages": [{"name": "a"}, {}]}, ["stage 0 (a)", "until=None", "steps"]),
    ({"stages": [STAGE_OK, {"name": "b", "until": {"steps": 5}}]},
     ["stage 1 (b)", "last stage", "until"]),
    ({"stages": [{"name": "a", "until": {"steps": 0}}, {}]}, ["until.steps=0", "integer >= 1"]),
    ({"stages": [{"name": "a", "until": {"success": 0.8}}, {}]}, ["until.window=None"]),
    ({"stages": [{"name": "a", "until": {"success": 1.5, "window": 5}}, {}]},
     ["until.success=1.5", "(0, 1]"]),
    ({"stages": [{"name": "a", "until": {"episodes": 5}}, {}]}, ["episodes", "steps, success"]),
    ({"stages": [{"name": "a", "draw": {"target": []}, "until": {"steps": 5}}, {}]},
     ["draw.target=[]", "non-empty list"]),
    ({"task": "reach", "stages": [{}]}, ["task='reach'", "selfbody"]),
    ({"evaluate": "best", "stages": [{}]}, ["evaluate='best'", "final, current"]),
    ({"stages": [{}], "extra": 1}, ["extra", "allowed"]),
    ("no_such_curriculum", ["no_such_curriculum", "selfbody"]),
])
def test_bad_structures_are_refused_naming_the_field(spec, words):
    with pytest.raises(TrainInputError) as info:
        load_curriculum(spec, "selfbody")
    for w in words:
        assert w in str(info.value), (w, str(info.value))


@pytest.mark.parametrize("stage, words", [
    ({"options": {"targt": "head"}}, ["stage 0 (a)", "targt", "allowed", "target"]),
    ({"draw": {"target": ["head", "nose"]}}, ["stage 0 (a)", "draw.target='nose'", "head"]),
    # four targets make a four-long one-hot: another observation space
    ({"options": {"targets": ["head", "hip", "chest_lower", "shoulders"]}},
     ["stage 0 (a)", "observation", "keep the spaces"]),
    ({"env_kwargs": {"bogus": 1}}, ["stage 0 (a)", "env_kwargs", "bogus"]),
])
def test_options_the_task_does_not_take_are_refused_before_training(tmp_path, stage, words):
    spec = {"stages": [{"name": "a", **stage, "until": {"steps": 10}}, {"name": "b"}]}
    if "targets" in stage.get("options", {}):   # the first stage sets the spaces: swap them
        spec["stages"] = [{"name": "b", "until": {"steps": 10}}, {"name": "a", **stage}]
        words = ["stage 1 (a)" if w == "stage 0 (a)" else w for w in words]
    out = tmp_path / "run"
    with pytest.raises(TrainInputError) as info:
        train("selfbody", "ppo", 100, 0, out, curriculum=spec, progress=False, flat_obs=True)
    for w in words:
        assert w in str(info.value), (w, str(info.value))
    assert not out.exists()   # refused before anything was written


def test_a_curriculum_file_and_the_modes_it_is_refused_in(tmp_path):
    path = tmp_path / "c.json"
    path.write_text(json.dumps({"stages": [{"name": "near", "options": {"min_distance": 0.1},
                                            "until": {"steps": 5}}, {"name": "task"}]}))
    cur = load_curriculum(str(path), "reach")
    assert cur.source == str(path)
    assert cur.stages[0].env_kwargs == {"task_options": {"min_distance": 0.1}}
    bad = tmp_path / "bad.toml"
    bad.write_text("[[stages]\nname = 1")
    with pytest.raises(TrainInputError, match="not valid TOML"):
        load_curriculum(str(bad), "reach")
    with pytest.raises(TrainInputError, match="--mode shared; allowed: one learner"):
        train("high_five", "ppo", 100, 0, tmp_path / "r", curriculum=str(path), progress=False)
    with pytest.raises(TrainInputError, match="no_such"):
        train("reach", "ppo", 100, 0, tmp_path / "r", curriculum="no_such", progress=False)
    assert not (tmp_path / "r").exists()


# -- the envs in the worker processes ------------------------------------------------------------
def _finish_episodes(venv, rng, want: int, stage: int | None = None, limit: int = 400):
    """Step random actions until every env has finished ``want`` episodes (those of ``stage``
    when given); returns each finished episode's (env index, length, stage, info)."""
    done_by = [0] * venv.num_envs
    out = []
    for _ in range(limit):
        actions = np.stack([venv.action_space.sample() for _ in range(venv.num_envs)])
        _, _, dones, infos = venv.step(actions)
        for i, (d, info) in enumerate(zip(dones, infos)):
            if d:
                out.append((i, int(info["episode"]["l"]), info["curriculum_stage"], info))
                if stage is None or info["curriculum_stage"] == stage:
                    done_by[i] += 1
        if min(done_by) >= want:
            return out
    raise AssertionError(f"episodes not finished in {limit} steps: {done_by}")


def test_envs_in_worker_processes_switch_stage_at_their_next_reset():
    plan = load_curriculum({"stages": [
        {"name": "short", "env_kwargs": {"max_steps": 7}, "until": {"steps": 1}},
        {"name": "longer", "env_kwargs": {"max_steps": 11}}]}, "reach").plan({})
    fn = functools.partial(monitored_curriculum_env, "reach", FLAT, plan)
    venv = TimedSubprocVecEnv([fn, fn, fn], n_workers=2)
    try:
        venv.action_space.seed(0)
        venv.seed(0)
        venv.reset()
        assert venv.get_attr("curriculum_stage") == [0, 0, 0]
        first = _finish_episodes(venv, venv.action_space, 1)
        assert {length for _, length, _, _ in first} == {7}
        venv.env_method("set_curriculum_stage", 1)
        # the running episodes finish under stage 0 (length 7), the next ones are stage 1's
        after = _finish_episodes(venv, venv.action_space, 1, stage=1)
        assert all(length == (7 if st == 0 else 11) for _, length, st, _ in after)
        assert {st for _, _, st, _ in after} == {0, 1}
        assert venv.get_attr("curriculum_stage") == [1, 1, 1]
    finally:
        venv.close()


def test_a_drawn_option_reaches_every_episode_and_the_spaces_stay():
    targets = ["head", "left_upper_leg"]
    plan = load_curriculum({"stages": [
        {"name": "two", "env_kwargs": {"max_steps": 3}, "draw": {"target": targets},
         "until": {"steps": 1}},
        {"name": "all", "env_kwargs": {"max_steps": 3}}]}, "selfbody").plan({})
    env = CurriculumEnv("selfbody", FLAT, plan)
    try:
        seen = []
        for seed in range(12):
            _, info = env.reset(seed=seed)
            assert info["curriculum_stage"] == 0
            seen.append(env.unwrapped.parallel.unwrapped.task.target)
        assert set(seen) == set(targets)
        again = []
        for seed in range(12):   # the same seeds draw the same targets
            env.reset(seed=seed)
            again.append(env.unwrapped.parallel.unwrapped.task.target)
        assert again == seen
        assert env.observation_space.shape[0] > 28   # the one-hot over all 28 targets stays
        env.set_curriculum_stage(1)
        drawn = set()
        for seed in range(40):
            env.reset(seed=seed)
            drawn.add(env.unwrapped.parallel.unwrapped.task.target)
        assert len(drawn) > 2 and env.curriculum_stage == 1
        with pytest.raises(ValueError, match="stage 2 not allowed; allowed: 0 to 1"):
            env.set_curriculum_stage(2)
    finally:
        env.close()


# -- advancing -------------------------------------------------------------------------------------
class _Venv:
    def __init__(self):
        self.calls = []

    def env_method(self, name, *args, **kwargs):
        self.calls.append((name, args))
        return [None]


def test_the_controller_advances_by_success_counting_only_its_stage_s_episodes():
    cur = load_curriculum({"stages": [
        {"name": "a", "until": {"success": 0.6, "window": 5}},
        {"name": "b", "until": {"steps": 100}},
        {"name": "c"}]}, "reach")
    venv, notes, writes, config = _Venv(), [], [], {}
    ctl = CurriculumController(cur, venv, None, config, lambda: writes.append(1), notes.append)
    ep = lambda ok, st=0: {"episode": {"r": 0.0, "l": 5}, "is_success": ok,  # noqa: E731
                           "curriculum_stage": st}
    ctl.on_step(10, [ep(True), ep(True), {"is_success": True}])   # no episode end: not counted
    ctl.on_step(20, [ep(False), ep(True)])
    assert ctl.stage == 0            # 3 of 4 episodes: the window of 5 is not full
    ctl.on_step(30, [ep(False)])     # 3 / 5 = 0.6
    assert ctl.stage == 1 and venv.calls == [("set_curriculum_stage", (1,))]
    assert ctl.columns() == {"curriculum_stage": 1, "eval_curriculum_stage": 2}
    ctl.on_step(90, [ep(True, 0)] * 10)   # stage 0's late episodes do not count for stage 1
    assert ctl.stage == 1
    ctl.on_step(131, [])
    assert ctl.stage == 2 and venv.calls[-1] == ("set_curriculum_stage", (2,))
    ctl.on_step(10_000, [])
    assert ctl.stage == 2 and len(venv.calls) == 2
    hist = config["curriculum"]["history"]
    assert [(h["stage"], h["step"]) for h in hist] == [(0, 0), (1, 30), (2, 131)]
    assert "success 60% over the last 5 episodes" in hist[1]["why"]
    assert "101 steps in stage 1" in hist[2]["why"]
    assert len(notes) == 2 and "stage 1 (b) from step 30" in notes[0] and len(writes) == 2


def test_a_run_advances_by_steps_and_records_every_stage(tmp_path, capfd):
    spec = {"stages": [
        {"name": "short", "env_kwargs": {"max_steps": 30}, "until": {"steps": 512}},
        {"name": "longer", "env_kwargs": {"max_steps": 45}, "until": {"steps": 512}},
        {"name": "task"}]}   # the run's env kwargs: episodes of at most 60 steps
    out = tmp_path / "run"
    train("reach", "ppo", 1536, 0, out, curriculum=spec, progress=False, n_envs=2, n_cpus=1,
          eval_every=512, eval_episodes=1,
          algo_kwargs={"n_steps": 128, "n_epochs": 1, "batch_size": 256},
          env_kwargs={"max_steps": 60})
    config = json.loads((out / "config.json").read_text())
    hist = config["curriculum"]["history"]
    assert [h["stage"] for h in hist] == [0, 1, 2]
    assert hist[1]["step"] >= 512 and hist[2]["step"] - hist[1]["step"] >= 512
    assert config["curriculum"]["stages"][0]["env_kwargs"] == {"max_steps": 30}
    assert config["curriculum"]["evaluate"] == "final"
    # the envs in the worker really ran each stage: episode lengths within its max_steps
    episodes = _rows(out / "episodes.csv")
    early = [int(e["length"]) for e in episodes if int(e["timesteps"]) <= hist[1]["step"]]
    assert early and max(early) == 30
    mid = [int(e["length"]) for e in episodes
           if hist[1]["step"] + 2 * 45 < int(e["timesteps"]) <= hist[2]["step"]]
    assert mid and max(mid) == 45
    rows = _rows(out / "progress.csv")
    stages = [int(r["curriculum_stage"]) for r in rows]
    assert stages == sorted(stages) and stages[-1] == 2 and stages[0] < 2
    assert {r["eval_curriculum_stage"] for r in rows} == {"2"}   # the final task, always
    err = capfd.readouterr().err
    assert "curriculum: stage 1 (longer) from step" in err and "stage 2 (task)" in err


def test_a_run_advances_by_success(tmp_path):
    """A warm-started reach learner (behaviour cloning, small log-std) succeeds often enough
    from its first rollout: stage 0 ends by success, not by its step limit."""
    spec = {"evaluate": "current", "stages": [
        {"name": "first", "until": {"success": 0.2, "window": 5, "steps": 100_000}},
        {"name": "task"}]}
    out = tmp_path / "run"
    train("reach", "ppo", 1024, 0, out, curriculum=spec, progress=False, n_envs=2, n_cpus=1,
          eval_episodes=1, algo_kwargs={"n_steps": 256, "n_epochs": 1, "batch_size": 512},
          bc_episodes=30, bc_epochs=30,
          bc_kwargs={"log_std": -2.0})
    config = json.loads((out / "config.json").read_text())
    hist = config["curriculum"]["history"]
    assert [h["stage"] for h in hist] == [0, 1]
    assert "success" in hist[1]["why"] and hist[1]["step"] < 100_000
    rows = _rows(out / "progress.csv")
    assert rows[0]["eval_curriculum_stage"] == "0"   # evaluate = "current"
    assert rows[-1]["eval_curriculum_stage"] == "1"


def test_the_command_line_takes_a_curriculum_file_and_a_warm_start(tmp_path, capsys):
    from mimo_social.cli import main
    path = tmp_path / "c.toml"
    path.write_text('[[stages]]\nname = "short"\nenv_kwargs = { max_steps = 20 }\n'
                    'until = { steps = 128 }\n[[stages]]\nname = "task"\n')
    out = tmp_path / "run"
    base = ["train", "--task", "reach", "--algo", "ppo", "--steps", "256", "--out", str(out),
            "--no-progress", "--n-envs", "2", "--n-cpus", "0", "--eval-episodes", "1",
            "--env-kwargs", '{"max_steps": 50}',
            "--algo-kwargs", '{"n_steps": 64, "n_epochs": 1, "batch_size": 128}']
    assert main(base + ["--curriculum", str(path), "--bc-episodes", "2", "--bc-epochs", "1",
                        "--bc-kwargs", '{"batch_size": 16}']) == 0
    config = json.loads((out / "config.json").read_text())
    assert config["curriculum"]["source"] == str(path)
    assert [h["stage"] for h in config["curriculum"]["history"]] == [0, 1]
    assert config["bc"]["episodes"] == 2 and config["bc"]["batch_size"] == 16
    assert main(base[:8] + [str(tmp_path / "r2"), "--curriculum", "no_such"]) == 2
    assert "no_such" in capsys.readouterr().err and not (tmp_path / "r2").exists()
    assert main(base[:8] + [str(tmp_path / "r3"), "--engine", "rllib", "--bc-episodes", "2"]) == 2
    assert "--bc-episodes" in capsys.readouterr().err


def test_mode_scripted_takes_a_curriculum_and_a_warm_start(tmp_path):
    spec = {"stages": [
        {"name": "short", "env_kwargs": {"max_steps": 20}, "until": {"steps": 256}},
        {"name": "task"}]}
    out = tmp_path / "run"
    train("high_five", "ppo", 512, 0, out, mode="scripted", curriculum=spec, progress=False,
          n_envs=2, n_cpus=0, eval_episodes=1, env_kwargs={"max_steps": 40}, bc_episodes=1,
          bc_epochs=1, algo_kwargs={"n_steps": 64, "n_epochs": 1, "batch_size": 128},
          bc_kwargs={"keep_updates": 4})
    config = json.loads((out / "config.json").read_text())
    hist = config["curriculum"]["history"]
    assert [h["stage"] for h in hist] == [0, 1] and hist[1]["step"] >= 256
    assert config["bc"]["episodes"] == 1
    # rollouts of 128 steps start at 0, 128, 256, 384: the cloning goes on after the first
    # update only (4 x (1 - 128 / 256) = 2; none from half the run on)
    assert config["bc"]["keep_updates_made"] == 2
    episodes = _rows(out / "episodes.csv")
    assert max(int(e["length"]) for e in episodes if int(e["timesteps"]) <= hist[1]["step"]) == 20
    assert max(int(e["length"]) for e in episodes) == 40
    rows = _rows(out / "progress.csv")
    assert rows[0]["before_rl"] == "1" and rows[0]["timesteps"] == "0"
    assert rows[-1]["curriculum_stage"] == "1" and rows[-1]["eval_curriculum_stage"] == "1"
    assert float(rows[-1]["eval_length_mean"]) > 20   # evaluated on the last stage (40 steps)
