"""Slow (kept out of CI: ``pytest -m slow tests/train/test_recipes_slow.py``): each measured
recipe's first stage reaches a stated success within a small budget, one seed, judged by
``check_recipe`` on 10 seeded episodes (mean action). The bars are below what was measured
(docs/baselines.md, "Recipes"), so a recipe, a task or a training change that breaks learning
fails here.

* reach: the recipe at 150k steps (its seeds were at 100 % from 100-180k; the full recipe 600k);
* mirror: the recipe at 20k steps (100 % from 5k steps on, issue 15; the recipe 50k);
* selfbody: the curriculum's first stage as a task of its own (the `targets` option cut to the
  stage's 4 primitives; 80 % in 60k steps measured in issue 30), 80k steps.
"""

import tomllib

import pytest

from mimo_social.train.curriculum import DIRECTORY as CURRICULA
from mimo_social.train.recipes import check_recipe

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("task, steps, bar", [("reach", 150_000, 0.7), ("mirror", 20_000, 0.8)])
def test_a_recipe_learns_within_a_small_budget(tmp_path, task, steps, bar):
    res = check_recipe(task, [0], tmp_path, episodes=10, steps=steps, progress=False)
    assert res["seeds"][0]["success"] >= bar, res["seeds"]


def test_the_selfbody_curriculums_first_stage_is_learnt_within_80k_steps(tmp_path):
    stage = tomllib.loads((CURRICULA / "selfbody.toml").read_text())["stages"][0]
    targets = stage["draw"]["target"]
    recipe = tmp_path / "selfbody_first_stage.toml"
    recipe.write_text('task = "selfbody"\nalgo = "ppo"\nsteps = 80000\n[train]\nn_envs = 1\n'
                      f'env_kwargs = {{ task_options = {{ targets = {targets!r} }} }}\n'
                      .replace("'", '"'))
    res = check_recipe(str(recipe), [0], tmp_path / "out", episodes=10, progress=False)
    assert res["seeds"][0]["success"] >= 0.5, res["seeds"]
