"""Training recipes (issue 30): every task ships one, each is checked before anything runs, and
``check_recipe`` trains, reuses finished runs and judges each seed against the scripted
controller."""

import json
import os
from pathlib import Path

import pytest

from mimo_social.cli import main
from mimo_social.envs.catalog import CATALOG
from mimo_social.train.recipes import (PASS_SHARE, check_recipe, load_recipe, recipe_markdown,
                                       shipped_recipes, validate_recipe)
from mimo_social.train.tasks import TrainInputError


def test_every_task_of_the_catalogue_but_free_play_ships_a_valid_recipe():
    tasks = {e.name for e in CATALOG} - {"free_play"}
    assert set(shipped_recipes()) == tasks
    for name in shipped_recipes():
        r = load_recipe(name)
        validate_recipe(r)
        assert r.task == name and r.steps <= 2_000_000, name   # the budget
        assert r.description and r.status, name
        kw = r.train_kwargs(3, "/tmp/x")
        assert kw["seed"] == 3 and kw["recipe"] == name and kw["task"] == name


def test_every_recipe_file_the_docs_cite_is_valid():
    """The recipes under docs/training (measured pilots and runs, each README gives the command
    that runs it) load and pass the checks made before training, so a cited command still runs."""
    files = sorted((Path(__file__).parents[2] / "docs" / "training").rglob("recipe.toml"))
    assert len(files) >= 10
    for path in files:
        r = load_recipe(path)
        validate_recipe(r)
        assert r.train_kwargs(0, "/tmp/x")["task"] == r.task, path


def _write(tmp_path, text, name="r.toml"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("text, words", [
    ('algo = "ppo"\nsteps = 10\ntask = "reach"\nstep = 3\n', ["'step'", "did you mean 'steps'"]),
    ('algo = "ppo"\nsteps = 10\ntask = "reach"\n[train]\nn_env = 2\n',
     ["[train]", "'n_env'", "did you mean 'n_envs'"]),
    ('algo = "ppo"\nsteps = 0\ntask = "reach"\n', ["steps=0", "positive integer"]),
    ('algo = "ddpg"\nsteps = 10\ntask = "reach"\n', ["ddpg"]),
    ('algo = "ppo"\ntask = "reach"\n', ["no 'steps'"]),
    ('algo = "ppo"\nsteps = 10\ntask = "reach"\nmode = "scripted"\n', ["mode"]),
    ('algo = "ppo"\nsteps = 10\ntask = "juggle"\n', ["juggle"]),
    ('algo = "ppo"\nsteps = 10\ntask = "reach"\n[train]\nmode = "x"\n', ["'mode'"]),
    ('algo = "ppo"\nsteps = 10\ntask = "reach"\nmodel = "last"\n', ["model='last'", "best"]),
])
def test_a_bad_recipe_is_refused_naming_the_key_and_what_is_allowed(tmp_path, text, words):
    with pytest.raises(TrainInputError) as e:
        load_recipe(_write(tmp_path, text))
    for w in words:
        assert w in str(e.value)


def test_a_recipe_whose_train_options_do_not_fit_the_task_is_refused_before_training(tmp_path):
    r = load_recipe(_write(tmp_path, 'task = "reach"\nalgo = "ppo"\nsteps = 64\n[train]\n'
                           'bc_episodes = 2\nbc_kwargs = { lr = -1, nope = 1 }\n'))
    with pytest.raises(TrainInputError, match="nope"):
        validate_recipe(r)
    r = load_recipe(_write(tmp_path, 'task = "reach"\nalgo = "ppo"\nsteps = 64\n[train]\n'
                           'algo_kwargs = { n_step = 8 }\n'))
    with pytest.raises(TrainInputError, match="n_steps"):
        validate_recipe(r)
    with pytest.raises(TrainInputError, match="no such shipped recipe"):
        load_recipe("juggling")


TINY = ('task = "reach"\nalgo = "ppo"\nsteps = 128\ndescription = "tiny"\n[train]\n'
        'n_envs = 1\nn_cpus = 0\neval_episodes = 1\nenv_kwargs = { max_steps = 150 }\n'
        'algo_kwargs = { n_steps = 64, batch_size = 32, n_epochs = 1 }\n')


def test_check_recipe_trains_each_seed_judges_it_and_reuses_finished_runs(tmp_path):
    spec = _write(tmp_path, TINY)
    out = tmp_path / "out"
    res = check_recipe(spec, [0, 1], out, episodes=3, eval_seed=1000, progress=False)
    for s in (0, 1):
        config = json.loads((out / f"seed{s}" / "config.json").read_text())
        assert config["recipe"] == spec and config["seed"] == s and config["steps"] == 128
        assert config["env_kwargs"] == {"max_steps": 150}
    assert [r["seed"] for r in res["seeds"]] == [0, 1]
    assert res["scripted_success"] == 1.0      # the reach controller touches within 150 steps
    assert res["target"] == pytest.approx(PASS_SHARE)
    for r in res["seeds"]:
        assert r["passes"] == (r["success"] >= res["target"])
        assert r["passes_sampled"] == (r["success_sampled"] >= res["target"])
        assert r["steps"] == 128 and r["wall_time_s"] > 0
    assert res["passes"] == all(r["passes"] for r in res["seeds"])
    saved = json.loads((out / "recipe.json").read_text())
    assert saved["seeds"] == json.loads(json.dumps(res["seeds"]))
    assert (out / "recipe.md").read_text().startswith(recipe_markdown(res))
    # a second check trains nothing: the finished runs are reused
    stamp = os.stat(out / "seed0" / "model.zip").st_mtime_ns
    again = check_recipe(spec, [0], out, episodes=3, eval_seed=1000, progress=False)
    assert os.stat(out / "seed0" / "model.zip").st_mtime_ns == stamp
    assert again["seeds"][0]["success"] == res["seeds"][0]["success"]
    best = check_recipe(spec, [0], out, episodes=3, eval_seed=1000, model="best", progress=False)
    assert best["model"] == "best" and "best model" in (out / "recipe.md").read_text()
    assert best["baselines"]["policies"][-1]["model"].endswith("best_model.zip")
    # another budget in the same folder is another run: refused, not overwritten
    with pytest.raises(TrainInputError, match="another --out"):
        check_recipe(spec, [0], out, steps=192, episodes=1, progress=False)


def test_the_command_lists_the_recipes_and_refuses_bad_seeds(capsys):
    assert main(["recipe", "--list"]) == 0
    text = capsys.readouterr().out
    for name in shipped_recipes():
        assert f"| {name} |" in text
    assert main(["recipe", "reach", "--seeds", "x", "--out", "/tmp/r"]) == 2
    assert "'x' is not a seed" in capsys.readouterr().err


def test_an_interrupted_run_stops_the_runs_after_it(monkeypatch, capsys):
    """Ctrl-C / SIGTERM during one run of a sequential ``train_all`` (compare, fig8, recipe):
    that run saves itself (``train`` returns ``interrupted``) and no later run starts."""
    from mimo_social.train import comparison
    started = []

    def fake_train(**kw):
        started.append(kw["out"])
        return {"interrupted": kw["out"] == "b"}

    monkeypatch.setattr(comparison, "train", fake_train)
    comparison.train_all([{"out": o} for o in "abc"], jobs=1, desc="fig8")
    assert started == ["a", "b"]
    assert "fig8: interrupted in b" in capsys.readouterr().err


def test_a_recipe_s_warm_start_steps_count_in_its_budget(tmp_path):
    from mimo_social.train.recipes import warm_start_steps
    spec = _write(tmp_path, TINY + 'bc_episodes = 2\nbc_kwargs = { dagger_rounds = 1, '
                  'dagger_episodes = 1 }\n')
    out = tmp_path / "out"
    res = check_recipe(spec, [0], out, episodes=1, eval_seed=1000, progress=False)
    bc = json.loads((out / "seed0" / "config.json").read_text())["bc"]
    # the controller's 2 episodes and DAgger's 2 plays (a round, then the last policy's)
    assert len(bc["dagger"]) == 2
    ws = bc["samples"] + sum(d["pairs_added"] for d in bc["dagger"])
    assert res["seeds"][0]["warm_start_steps"] == warm_start_steps(out / "seed0") == ws > 0
    assert f"| 0 | 128 + {ws:,} |" in (out / "recipe.md").read_text()
