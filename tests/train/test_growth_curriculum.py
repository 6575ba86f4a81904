"""Growth curricula (the infant's age by training step) and the cross-age evaluation (issue 32)."""

from __future__ import annotations

import csv
import json

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

from mimo_social.train import TrainInputError
from mimo_social.train.curriculum import load_curriculum
from mimo_social.train.growth import (Growth, GrowthController, GrowthEnv, age, check_ages,
                                      monitored_growth_env, parse_growth)


# -- the schedule functions ----------------------------------------------------------------------
def test_forward_and_inverse_run_between_their_endpoints_monotonically():
    fwd, inv = parse_growth("forward:1-12"), parse_growth("inverse:1-12")
    steps = np.arange(0, 1001, 10)
    up = [age(fwd, n, total=1000) for n in steps]
    down = [age(inv, n, total=1000) for n in steps]
    assert up[0] == 1 and up[-1] == 12 and down[0] == 12 and down[-1] == 1
    assert np.all(np.diff(up) > 0) and np.all(np.diff(down) < 0)
    assert age(fwd, 500, total=1000) == pytest.approx(6.5)
    assert age(fwd, 5000, total=1000) == 12 and age(fwd, -5, total=1000) == 1   # clamped


def test_a_step_span_ends_the_change_early_and_the_far_age_stays():
    g = parse_growth("forward:3-9:200")
    assert g == Growth("forward", 3.0, 9.0, 200)
    assert age(g, 100) == pytest.approx(6) and age(g, 200) == 9 and age(g, 10_000) == 9
    assert age(g, 100, total=10**6) == pytest.approx(6)     # the span, not the run's total
    with pytest.raises(ValueError, match="total"):
        age(parse_growth("forward:1-12"), 10)


def test_stochastic_draws_within_the_range_reproducibly_under_a_seed():
    g = parse_growth("stochastic:3-9")
    draws = [age(g, 0, np.random.default_rng(s)) for s in range(200)]
    assert min(draws) >= 3 and max(draws) <= 9 and np.std(draws) > 1
    again = [age(g, 123, np.random.default_rng(s)) for s in range(200)]
    assert draws == again
    assert age(parse_growth("stochastic:6-6"), 0, np.random.default_rng(0)) == 6
    with pytest.raises(ValueError, match="rng"):
        age(g, 0)


@pytest.mark.parametrize("spec, words", [
    ("sideways:1-12", "kind 'sideways' not allowed; allowed: forward, inverse, stochastic"),
    ("forward:12-1", "low-high"),
    ("forward:12-1", "inverse:1-12"),
    ("forward:1-40", "40' not allowed; allowed: an age in months from 0 to 33"),
    ("forward:-1-12", "age '' is not a number"),
    ("forward:1", "not A-B"),
    ("forward:a-12", "'a' is not a number"),
    ("forward:1-12:0", "steps 0 not allowed; allowed: an integer >= 1"),
    ("forward:1-12:ten", "steps 'ten' not allowed"),
    ("forward:6-6", "low-high"),
    ("stochastic:1-12:100", "a step span is for forward and inverse"),
    ("forward", "not KIND:A-B[:STEPS]"),
    (12, "allowed: forward:A-B"),
    ({"kind": "forward", "ages": [1]}, "a [low, high] pair"),
    ({"kind": "forward", "ages": [1, 12], "speed": 3}, "unknown key(s) speed"),
])
def test_bad_specs_are_refused_with_what_is_allowed(spec, words):
    with pytest.raises(TrainInputError) as e:
        parse_growth(spec)
    assert words in str(e.value)


def test_specs_and_tables_give_the_same_schedule():
    g = parse_growth(" inverse : 2 - 10.5 : 300 ")
    assert g == parse_growth({"kind": "inverse", "ages": [2, 10.5], "steps": 300})
    assert g.spec == "inverse:2-10.5:300" and parse_growth(g.spec) == g
    assert parse_growth(g.describe()) == g        # config.json's form reads back
    assert parse_growth(None) is None and parse_growth(g) is g


def test_ages_are_checked_one_by_one():
    assert check_ages("1, 3,6,9,12") == [1, 3, 6, 9, 12]
    assert check_ages([0, 33]) == [0, 33]
    for bad, words in (("1,40", "'40' not allowed; allowed: ages in months from 0 to 33"),
                       ("1,x", "'x' not allowed"), ("", "one or more ages"),
                       ("3,3", "'3' given twice"), ([True], "True not allowed")):
        with pytest.raises(TrainInputError, match="ages") as e:
            check_ages(bad)
        assert words in str(e.value)


# -- the wrapper and the controller on a stand-in env ---------------------------------------------
class AgedEnv(gym.Env):
    """A stand-in for the core env's Gymnasium adapter: set_age applies at the next reset."""

    observation_space = spaces.Box(-1, 1, (1,), np.float32)
    action_space = spaces.Box(-1, 1, (1,), np.float32)

    def __init__(self, length: int = 3):
        self.length, self.pending, self.age, self.calls, self.t = length, None, None, [], 0

    def set_age(self, age_months=None, motor_age_months=None, agent=None):
        self.calls.append(age_months)
        self.pending = age_months

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.options = options
        if options and "age_months" in options:
            self.pending = options["age_months"]
        self.age, self.t = self.pending, 0
        return np.zeros(1, np.float32), {}

    def step(self, action):
        self.t += 1
        return (np.full(1, self.age or 0, np.float32), 0.0, False, self.t >= self.length,
                {"is_success": False})


def test_the_wrapper_passes_set_age_on_and_it_applies_at_the_next_reset():
    inner = AgedEnv()
    env = GrowthEnv(inner, age_months=1.0)
    _, info = env.reset(seed=0)
    assert inner.age == 1.0 and info["age_months"] == 1.0
    env.set_age(age_months=4.5)
    assert env.step(env.action_space.sample())[-1]["age_months"] == 1.0   # the running episode
    assert inner.calls == [4.5]      # passed on at once, for the next reset
    env.reset()
    assert inner.age == 4.5 and env.step(env.action_space.sample())[-1]["age_months"] == 4.5
    assert inner.options == {"age_months": 4.5}   # and in every reset's options
    inner.pending = None             # an env below made anew (a curriculum's next stage) ...
    env.reset(options={"other": 1})
    assert inner.age == 4.5 and inner.options == {"age_months": 4.5, "other": 1}   # ... takes it


def test_a_stochastic_wrapper_draws_each_episode_from_its_seeded_generator():
    def ages(seed):
        env = GrowthEnv(AgedEnv(), draw=(3.0, 9.0))
        out = [env.reset(seed=seed)[1]["age_months"]]
        out += [env.reset()[1]["age_months"] for _ in range(20)]
        return out
    a = ages(7)
    assert a == ages(7) and a != ages(8)
    assert min(a) >= 3 and max(a) <= 9 and len(set(a)) == len(a)


def test_env_method_reaches_the_wrapper_below_the_episode_statistics():
    from stable_baselines3.common.vec_env import DummyVecEnv
    g = parse_growth("forward:1-12")
    venv = DummyVecEnv([lambda: monitored_growth_env(AgedEnv, g.describe(), 100)] * 2)
    venv.reset()
    assert venv.env_method("set_age", age_months=7.0) == [7.0, 7.0]
    inner = [e.unwrapped for e in venv.envs]
    assert [e.pending for e in inner] == [7.0, 7.0] and [e.age for e in inner] == [1.0, 1.0]
    venv.close()


class _Venv:
    def __init__(self):
        self.calls = []

    def env_method(self, name, **kw):
        self.calls.append((name, kw))


def test_the_controller_sets_ages_by_resolution_and_notes_whole_months_only():
    written, notes, venv = [], [], _Venv()
    eval_env = GrowthEnv(AgedEnv(), age_months=1.0)
    config = {}
    ctl = GrowthController(parse_growth("forward:1-4"), venv, eval_env, 300, config,
                           lambda: written.append(1), notes.append)
    for n in range(0, 301):
        ctl.on_step(n, [])
    ages = [kw["age_months"] for _, kw in venv.calls]
    assert ages[-1] == 4 and len(ages) == 30 and np.all(np.diff(ages) > 0)
    assert {name for name, _ in venv.calls} == {"set_age"}
    assert eval_env.pending == 4
    assert len(notes) == 3 and "4 months old from step 300" in notes[-1]
    hist = config["growth"]["history"]
    assert [h["age_months"] for h in hist] == [1, 2, 3, 4] and len(written) == 3
    assert config["growth"]["spec"] == "forward:1-4" and config["growth"]["span"] == 300
    assert ctl.columns() == {"age_months": 4, "eval_age_months": 4}


def test_a_stochastic_controller_reports_the_mean_age_of_the_episodes_that_ended():
    venv, config = _Venv(), {}
    eval_env = GrowthEnv(AgedEnv(), draw=(2.0, 4.0))
    ctl = GrowthController(parse_growth("stochastic:2-4"), venv, eval_env, 100, config,
                           lambda: None, print)
    ctl.on_step(5, [{"episode": {}, "age_months": 2.5}, {"age_months": 9.0}])
    ctl.on_step(9, [{"episode": {}, "age_months": 3.5}])
    eval_env.reset(seed=1)
    eval_env.reset(seed=2)
    row = ctl.columns()
    assert row["age_months"] == 3.0 and 2 <= row["eval_age_months"] <= 4
    assert venv.calls == [] and config["growth"]["history"] == []
    assert np.isnan(ctl.columns()["age_months"])


# -- the TOML keys ------------------------------------------------------------------------------
def test_a_curriculum_file_and_a_recipe_take_a_growth_key(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text('growth = "forward:1-12:5000"\n[[stages]]\nname = "all"\n')
    cur = load_curriculum(str(path), "reach")
    assert cur.growth == Growth("forward", 1.0, 12.0, 5000)
    assert cur.describe()["growth"] == "forward:1-12:5000"
    path.write_text('growth = { kind = "stochastic", ages = [3, 40] }\n[[stages]]\nname = "a"\n')
    with pytest.raises(TrainInputError, match=r"c.toml: growth .*40.* not allowed"):
        load_curriculum(str(path), "reach")
    from mimo_social.train.recipes import load_recipe, validate_recipe
    recipe = tmp_path / "r.toml"
    recipe.write_text('task = "reach"\nalgo = "ppo"\nsteps = 1000\n[train]\n'
                      'growth = "inverse:1-12"\n')
    r = load_recipe(str(recipe))
    assert r.train_kwargs(0, tmp_path / "o")["growth"] == "inverse:1-12"
    validate_recipe(r)
    recipe.write_text('task = "reach"\nalgo = "ppo"\nsteps = 1000\n[train]\ngrowth = "up:1-2"\n')
    with pytest.raises(TrainInputError, match="kind 'up' not allowed"):
        validate_recipe(load_recipe(str(recipe)))


def test_the_command_line_parses_growth_and_refuses_bad_specs(capsys):
    from mimo_social.cli import main
    base = ["train", "--task", "reach", "--algo", "ppo", "--steps", "10", "--out", "unused"]
    with pytest.raises(SystemExit):
        main(base + ["--growth", "forward:12-1"])
    err = capsys.readouterr().err
    assert "--growth" in err and "low-high" in err
    assert main(base + ["--growth", "forward:1-12", "--engine", "rllib"]) == 2
    assert "--growth" in capsys.readouterr().err


def test_growth_is_refused_where_it_cannot_apply(tmp_path):
    from mimo_social.train import train
    with pytest.raises(TrainInputError, match="--mode scripted; allowed: a one-agent task"):
        train("high_five", "ppo", 10, 0, tmp_path / "a", mode="scripted",
              growth="forward:1-12", progress=False)
    with pytest.raises(TrainInputError, match="age_months=6.*one of the two"):
        train("reach", "ppo", 10, 0, tmp_path / "b", growth="forward:1-12",
              env_kwargs={"age_months": 6}, progress=False)
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# -- the real env: its set_age, in this process, in worker processes, in a run -------------------
#: reach with short episodes, its ball placed at least 0.2 m from the shoulder (a 1-month-old's
#: reach allows it; the task's 0.25 m does not below 6 months)
REACH = {"max_steps": 5, "task_options": {"min_distance": 0.2}}


def _reach():
    from mimo_social.train.envs import make_env
    return make_env("reach", flat=True, **REACH)


def test_the_body_takes_the_age_at_the_next_reset_in_this_process():
    from stable_baselines3.common.vec_env import DummyVecEnv
    venv = DummyVecEnv([lambda: monitored_growth_env(_reach, "forward:1-12", 100)])
    config = venv.envs[0].unwrapped.parallel.agent_configs
    try:
        venv.seed(0)
        venv.reset()
        assert config[0].age_months == 1.0
        venv.env_method("set_age", age_months=9.5)
        for k in range(REACH["max_steps"]):
            assert config[0].age_months == 1.0            # the running episode keeps its age
            *_, dones, infos = venv.step(np.zeros((1, *venv.action_space.shape)))
        assert dones[0] and infos[0]["age_months"] == 1.0
        assert config[0].age_months == 9.5                # the next one: auto-reset at 9.5
    finally:
        venv.close()


def test_envs_in_worker_processes_take_the_age_at_their_next_reset():
    from mimo_social.train.workers import TimedSubprocVecEnv
    import functools
    fn = functools.partial(monitored_growth_env, _reach, "forward:1-12", 100)
    venv = TimedSubprocVecEnv([fn, fn], n_workers=1)
    try:
        venv.seed(0)
        venv.reset()
        assert venv.get_attr("age_months") == [1.0, 1.0]
        venv.env_method("set_age", age_months=6.0)
        zero = np.zeros((2, *venv.action_space.shape))
        for _ in range(REACH["max_steps"]):
            *_, dones, infos = venv.step(zero)
        assert all(dones) and [i["age_months"] for i in infos] == [1.0, 1.0]
        assert venv.get_attr("age_months") == [6.0, 6.0]
        assert [i["age_months"] for i in venv.step(zero)[-1]] == [6.0, 6.0]
    finally:
        venv.close()


TINY = ["--algo", "ppo", "--no-progress", "--n-envs", "2", "--eval-episodes", "1",
        "--env-kwargs", json.dumps({**REACH, "max_steps": 15}),
        "--algo-kwargs", '{"n_steps": 64, "n_epochs": 1, "batch_size": 128}']


def test_a_forward_run_grows_the_infant_and_records_it(tmp_path, capfd):
    from mimo_social.cli import main
    out = tmp_path / "run"
    assert main(["train", "--task", "reach", "--steps", "384", "--out", str(out), "--n-cpus",
                 "1", "--eval-every", "128", "--growth", "forward:1-12", *TINY]) == 0
    config = json.loads((out / "config.json").read_text())
    g = config["growth"]
    assert g["spec"] == "forward:1-12" and g["kind"] == "forward" and g["span"] == 384
    months = [h["age_months"] for h in g["history"]]
    assert months[0] == 1 and months == sorted(months) and months[-1] >= 11
    assert all(m == int(m) for m in months)               # whole months only
    rows = _rows(out / "progress.csv")
    ages = [float(r["age_months"]) for r in rows]
    assert ages[-1] == 12 and ages == sorted(ages) and len(set(ages)) >= 3
    for r, a in zip(rows, ages):       # the schedule at the row's step, on the 0.1-month grid
        assert a == pytest.approx(np.floor((1 + 11 * int(r["timesteps"]) / 384) * 10 + 1e-6)
                                  / 10)
    assert [r["eval_age_months"] for r in rows] == [r["age_months"] for r in rows]
    err = capfd.readouterr().err
    notes = [line for line in err.splitlines() if "growth: the infant is" in line]
    assert len(notes) == len(months) - 1 and "12 months old" in notes[-1]
    # eval runs it as its last evaluation did: at the age the schedule ends at
    assert main(["eval", str(out), "--episodes", "1", "--no-progress"]) == 0
    assert json.loads((out / "eval_results.json").read_text())["age_months"] == 12


def test_a_stochastic_run_draws_every_episode_s_age_in_its_range(tmp_path, capfd):
    from mimo_social.train import train
    out = tmp_path / "run"
    train("reach", "ppo", 256, 0, out, progress=False, n_envs=2, n_cpus=0, eval_every=128,
          eval_episodes=2, growth="stochastic:3-9", env_kwargs={**REACH, "max_steps": 15},
          algo_kwargs={"n_steps": 64, "n_epochs": 1, "batch_size": 128})
    config = json.loads((out / "config.json").read_text())
    assert config["growth"]["spec"] == "stochastic:3-9" and config["growth"]["history"] == []
    rows = _rows(out / "progress.csv")
    trained = [float(r["age_months"]) for r in rows if int(r["train_episodes"])]
    assert trained and all(3 <= a <= 9 for a in trained) and len(set(trained)) > 1
    evals = {r["eval_age_months"] for r in rows}
    assert len(evals) == 1 and 3 <= float(evals.pop()) <= 9      # the same seeded draws
    assert "growth:" not in capfd.readouterr().err                 # no line per episode
    from mimo_social.train import evaluate
    assert evaluate(out, 1)["age_months"] == "stochastic:3-9"
    assert evaluate(out, 1, env_kwargs={"age_months": 4})["age_months"] == 4


def test_a_curriculum_s_growth_key_grows_the_infant_across_its_stages(tmp_path):
    from mimo_social.train import train
    spec = {"growth": "forward:6-12", "stages": [
        {"name": "short", "env_kwargs": {"max_steps": 10}, "until": {"steps": 128}},
        {"name": "task"}]}
    kw = dict(progress=False, n_envs=2, n_cpus=0, eval_every=128, eval_episodes=1,
              env_kwargs={**REACH, "max_steps": 15},
              algo_kwargs={"n_steps": 64, "n_epochs": 1, "batch_size": 128})
    out = tmp_path / "run"
    train("reach", "ppo", 256, 0, out, curriculum=spec, **kw)
    config = json.loads((out / "config.json").read_text())
    assert config["curriculum"]["growth"] == "forward:6-12"
    assert config["growth"]["spec"] == "forward:6-12"
    assert [h["stage"] for h in config["curriculum"]["history"]] == [0, 1]
    rows = _rows(out / "progress.csv")
    assert float(rows[-1]["age_months"]) == 12 and rows[-1]["curriculum_stage"] == "1"
    with pytest.raises(TrainInputError, match="the curriculum's growth forward:6-12: allowed: "
                                              "one of the two"):
        train("reach", "ppo", 256, 0, tmp_path / "again", curriculum=spec,
              growth="inverse:1-3", **kw)


def test_an_inverse_controller_goes_down_and_notes_each_whole_month_reached():
    notes, venv, config = [], _Venv(), {}
    ctl = GrowthController(parse_growth("inverse:1-4"), venv, None, 300, config, lambda: None,
                           notes.append)
    for n in range(0, 301):
        ctl.on_step(n, [])
    ages = [kw["age_months"] for _, kw in venv.calls]
    assert ages[0] == 3.9 and ages[-1] == 1 and np.all(np.diff(ages) < 0) and len(ages) == 30
    assert [h["age_months"] for h in config["growth"]["history"]] == [4, 3, 2, 1]
    assert [h["step"] for h in config["growth"]["history"]] == [0, 100, 200, 300]
    assert "1 month old from step 300 (inverse:1-4)" in notes[-1] and len(notes) == 3
