"""Slow (kept out of CI: ``pytest -m slow tests/train/test_recipes_slow.py``): each measured
recipe's first stage reaches a stated success within a small budget, one seed, judged by
``check_recipe`` on 10 seeded episodes (mean action). The bars are below what was measured
(docs/baselines.md, "Recipes"), so a recipe, a task or a training change that breaks learning
fails here.

* reach: the recipe at 150k steps, judged by its sampled actions, which learn first (Fig. 8's
  five PPO seeds at 150k: 20-100 % sampled, 0-50 % mean action; this test's seed 0, run in
  issue 30: 50 % mean action, sampled >= 80 %; the full recipe, 600k: 100 % both);
* mirror: the whole recipe (100k steps, its best evaluated model: 100 % in both seeds, issue
  30); at 20k steps with its learning rate decaying over those 20k it stayed at 0 % (issue 30:
  training is unstable, docs/baselines.md "Recipes");
* selfbody (the shipped recipe): at 10k steps (its warm start: 200 scripted episodes cloned into
  the 256x256 policy, 7 DAgger rounds of 50, the best play's policy kept, then five PPO updates
  with the cloning kept), its final model by its mean action: before any RL step the clones
  touched in 4/5 and 3/5 evaluation episodes (seeds 0 and 1, issue 30, third session), their
  best DAgger plays 90 % and 92 % of 50; the bar is 50 %;
* selfbody (the curriculum, not shipped): its first stage as a task of its own (the `targets`
  option cut to the stage's 4 primitives), 80k steps: 80 % in 60k steps in one run of issue 30,
  40 % at 80k in this test's run (return 76; random 3 %): the bar is 30 %;
* turn_taking: the recipe at 10k steps (its warm start, cloned from 20 scripted episodes, then
  five PPO updates with the cloning kept), judged by its sampled actions: the clone alone
  succeeded in 3/3 sampled episodes in issue 33's pilots (the most likely sound is silence: 0 %
  with the mean action); the bar is 70 %.
* contingency: the recipe at 2,048 steps (its warm start: 10 scripted episodes cloned into the
  CNN policy, then one PPO update with the cloning kept), judged by its sampled actions: the
  clones succeeded in 2/2 sampled evaluation episodes of both seeds before any RL step (issue
  30, fourth session; the full recipe, 60k: 100 % sampled in both seeds on 30 episodes); the bar
  is 70 %;
* still_face: the recipe at 2,048 steps (its warm start: 10 episodes of the scripted infant
  renewing its smile every 0.125 s cloned into the CNN policy, then one PPO update with the
  cloning kept), judged by its sampled actions: the clones succeeded in 2/2 sampled evaluation
  episodes of both seeds before any RL step (issue 30, fifth session; the full recipe, 60k: 93 %
  and 100 % sampled on 30 episodes); the bar is 60 %;
* imitation: the recipe at 2,048 steps (its warm start: 20 episodes of the preparing scripted
  imitator, DART noise 0.1, cloned at lr 3e-4 into the CNN policy with the normaliser's scale
  floored at 0.01, then one PPO update with the cloning kept), judged by its mean action: the
  clones imitated in 2/2 evaluation episodes of both seeds before any RL step, mean and sampled
  (issue 30, sixth session); the bar is 70 %;
* catch: the recipe at 10k steps (its warm start: 100 scripted episodes cloned, 2 DAgger
  rounds, then five PPO updates with the cloning kept), judged by its mean action: the clone
  caught in 5/5 evaluation episodes of both seeds before any RL step (issue 30; the full recipe,
  200k steps: 93 % and 87 % on 30 episodes); the bar is 70 %;
* rollover: the recipe at 10k steps (its warm start: 50 scripted rolls cloned, 3 DAgger rounds,
  then five PPO updates with the cloning kept), its best evaluated model by its mean action: the
  clone rolled over in 5/5 evaluation episodes of both seeds before any RL step (issue 30); the
  bar is 70 %.
"""

import tomllib

import pytest

from mimo_social.train.curriculum import DIRECTORY as CURRICULA
from mimo_social.train.recipes import check_recipe

pytestmark = pytest.mark.slow


def test_reach_s_recipe_learns_within_150k_steps(tmp_path):
    res = check_recipe("reach", [0], tmp_path, episodes=10, steps=150_000, progress=False)
    assert res["seeds"][0]["success_sampled"] >= 0.7, res["seeds"]


def test_mirror_s_recipe_passes_with_its_best_model(tmp_path):
    res = check_recipe("mirror", [0], tmp_path, episodes=10, progress=False)
    assert res["model"] == "best" and res["seeds"][0]["success"] >= 0.8, res["seeds"]


def test_the_selfbody_curriculums_first_stage_is_learnt_within_80k_steps(tmp_path):
    stage = tomllib.loads((CURRICULA / "selfbody.toml").read_text())["stages"][0]
    targets = stage["draw"]["target"]
    recipe = tmp_path / "selfbody_first_stage.toml"
    recipe.write_text('task = "selfbody"\nalgo = "ppo"\nsteps = 80000\n[train]\nn_envs = 1\n'
                      f'env_kwargs = {{ task_options = {{ targets = {targets!r} }} }}\n'
                      .replace("'", '"'))
    res = check_recipe(str(recipe), [0], tmp_path / "out", episodes=10, progress=False)
    assert res["seeds"][0]["success"] >= 0.3, res["seeds"]


def test_the_selfbody_recipes_warm_start_touches(tmp_path):
    res = check_recipe("selfbody", [0], tmp_path, episodes=10, steps=10_240, progress=False)
    assert res["model"] == "final" and res["seeds"][0]["success"] >= 0.5, res["seeds"]


def test_the_turn_taking_recipes_warm_start_takes_turns(tmp_path):
    res = check_recipe("turn_taking", [0], tmp_path, episodes=10, steps=10_240, progress=False)
    assert res["seeds"][0]["success_sampled"] >= 0.7, res["seeds"]


def test_the_contingency_recipes_warm_start_returns_smiles(tmp_path):
    res = check_recipe("contingency", [0], tmp_path, episodes=10, steps=2_048, progress=False)
    assert res["seeds"][0]["success_sampled"] >= 0.7, res["seeds"]


def test_the_still_face_recipes_warm_start_sobers_at_the_still_face(tmp_path):
    res = check_recipe("still_face", [0], tmp_path, episodes=10, steps=2_048, progress=False)
    assert res["seeds"][0]["success_sampled"] >= 0.6, res["seeds"]


def test_the_imitation_recipes_warm_start_imitates(tmp_path):
    res = check_recipe("imitation", [0], tmp_path, episodes=10, steps=2_048, progress=False)
    assert res["seeds"][0]["success"] >= 0.7, res["seeds"]


def test_the_catch_recipes_warm_start_catches(tmp_path):
    res = check_recipe("catch", [0], tmp_path, episodes=10, steps=10_240, progress=False)
    assert res["seeds"][0]["success"] >= 0.7, res["seeds"]


def test_the_rollover_recipes_warm_start_rolls_over(tmp_path):
    res = check_recipe("rollover", [0], tmp_path, episodes=10, steps=10_240, progress=False)
    assert res["seeds"][0]["success"] >= 0.7, res["seeds"]
