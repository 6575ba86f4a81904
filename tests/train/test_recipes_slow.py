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
* social_touch: the recipe at 10k steps (its warm start: 300 episodes of the blind toucher
  cloned into the learner's positional arm, 3 DAgger rounds of 50, then five PPO updates with
  the cloning kept; about an hour here), judged by its mean action: at 10k steps its
  evaluations (5 episodes) touched in 5/5 in both seeds (issue 30, ninth session; before any
  RL step 2/5 and 3/5; the full recipe, 1.2M: 83 % in both seeds on 30 episodes); the bar is
  50 %.
* joint_attention: the recipe at 2,048 steps (its warm start: 300 episodes of the sensed follower
  cloned by sequences into the LSTM policy, about 12 minutes here, then RecurrentPPO's first
  updates with the cloning kept), judged by its mean action: before any RL step the clones
  followed in 5/5 and 3/5 evaluation episodes (seeds 0 and 1, issue 30, fifteenth session; the
  full recipe, 50k: 90 % and 87 % on 30 episodes, 3/5 on seeds 1000-1004, the hardest; random
  and zero 0 %); the bar is 40 %.
"""

import tomllib

import pytest

from mimo_social.train.curriculum import DIRECTORY as CURRICULA
from mimo_social.train.recipes import check_recipe

pytestmark = pytest.mark.slow

# (recipe, budget in steps or None for the recipe's own, which success is judged, the bar, the
# model check_recipe must have judged or None): one row per bullet of the docstring above.
FIRST_STAGES = [
    ("reach", 150_000, "success_sampled", 0.7, None),
    ("mirror", None, "success", 0.8, "best"),
    ("selfbody", 10_240, "success", 0.5, "final"),
    ("turn_taking", 10_240, "success_sampled", 0.7, None),
    ("contingency", 2_048, "success_sampled", 0.7, None),
    ("still_face", 2_048, "success_sampled", 0.6, None),
    ("imitation", 2_048, "success", 0.7, None),
    ("catch", 10_240, "success", 0.7, None),
    ("rollover", 10_240, "success", 0.7, None),
    ("social_touch", 10_240, "success", 0.5, None),
    ("joint_attention", 2_048, "success", 0.4, None),
]


@pytest.mark.parametrize("recipe, steps, judged, bar, model", FIRST_STAGES,
                         ids=[row[0] for row in FIRST_STAGES])
def test_a_recipes_first_stage_reaches_its_bar(tmp_path, recipe, steps, judged, bar, model):
    res = check_recipe(recipe, [0], tmp_path, episodes=10, steps=steps, progress=False)
    assert model is None or res["model"] == model, res["model"]
    assert res["seeds"][0][judged] >= bar, res["seeds"]


def test_the_selfbody_curriculums_first_stage_is_learnt_within_80k_steps(tmp_path):
    stage = tomllib.loads((CURRICULA / "selfbody.toml").read_text())["stages"][0]
    targets = stage["draw"]["target"]
    recipe = tmp_path / "selfbody_first_stage.toml"
    recipe.write_text('task = "selfbody"\nalgo = "ppo"\nsteps = 80000\n[train]\nn_envs = 1\n'
                      f'env_kwargs = {{ task_options = {{ targets = {targets!r} }} }}\n'
                      .replace("'", '"'))
    res = check_recipe(str(recipe), [0], tmp_path / "out", episodes=10, progress=False)
    assert res["seeds"][0]["success"] >= 0.3, res["seeds"]
