"""One test per clause of the success definitions of high five and mirror (the task tables'
`success` and `termination` rows, issue 30). Each clause below names the test that fails when
the clause is removed from the task's code (checked by mutating a scratch copy of the task, one
clause at a time, when the tests were written); clauses guarded elsewhere name that test.

high five (`HighFive.rewards`, `HighFive.palms_meet`, `HighFive.terminations`)
  H1 the two right hands are in contact: test_crossed_arms_are_no_high_five_under_either_rule
     (with `success="touch"`; under the palm rule `palms_meet` needs a hand-to-hand contact too)
  H2 both right-hand skins feel the other agent: see the note below
  H3 `success="palms"`: a contact whose normal lies within 60 deg of the learner's palm normal:
     test_issue30_high_five_social_touch.py::test_the_back_of_the_learners_hand_is_no_high_five
  H4 ... and of the partner's palm normal: test_issue30_high_five_social_touch.py::
     test_the_back_of_the_partners_hand_is_no_high_five
  H5 ... held `hold_time` (0.1 s): test_issue30_high_five_social_touch.py::
     test_palms_held_for_hold_time_make_the_high_five_and_not_before
  H6 ... without a break: test_issue30_high_five_social_touch.py::
     test_an_interrupted_palm_contact_starts_the_count_again
  H7 `success="touch"`: any felt touch of the right hands, one step: test_high_five_touch.py::
     test_hands_together_are_felt_by_both_skins_and_give_the_bonus
  H8 both agents' episodes end on success if `end_on_touch`: test_high_five_touch.py::
     test_without_end_on_touch_the_bonus_comes_every_touching_step and
     test_hands_together_are_felt_by_both_skins_and_give_the_bonus

  Note on H2: the skin feels a contact that presses (a positive normal force), and a contact
  between two skinned hands is felt by both; `require_skin` makes both right hands skinned. So a
  hand-to-hand contact one hand feels and the other does not needs a zero-force contact between
  the hands while the partner's arm presses on one hand; no test builds that state (searched
  for, in seeded random postures, and not found), and removing one skin's clause changes
  nothing any test sees.

mirror (`Mirror.rewards`, `Mirror.terminations`)
  M1 a step matches when the two faces are the same: test_mirror.py::
     test_match_reward_both_learners_with_free_roles
  M2 the matched steps are counted over the episode (not in a row):
     test_mirror_matched_steps_add_up_over_breaks
  M3 success: at least `success_fraction` of the episode's steps (`max_steps`), rounded up:
     test_mirror_success_needs_success_fraction_of_the_steps_rounded_up
  M4 no termination on success: test_mirror_success_does_not_end_the_episode
"""

import numpy as np
import pytest

from mimo_social.envs import high_five_v0, mirror_v0
from test_high_five_touch import _place_palm, _zero   # this folder is on the path

NO_MOTORS = np.zeros(0, np.float32)


# -- high five -----------------------------------------------------------------------------------
@pytest.mark.parametrize("success", ["touch", "palms"])
def test_crossed_arms_are_no_high_five_under_either_rule(success):
    """H1: each right hand on the other's forearm: both skins feel the partner, the hands do not
    touch each other: no success, with the first versions' rule either."""
    env = high_five_v0.parallel_env(expressions=False, task_options={
        "distance": 0.3, "start_spread": 0.0, "success": success})
    env.reset(seed=0)
    w = env.world
    _place_palm(env, 1, [0.1, 0.0, 0.55])
    _place_palm(env, 0, w.data.xipos[w.model.body("infant_1/right_lower_arm").id].copy())
    _, r, term, _, info = env.step(_zero(env))
    for a in env.possible_agents:
        assert info[a]["hand_feels_partner"] and not info[a]["is_success"] and not term[a]
        assert r[a] == pytest.approx(-info[a]["hand_distance"])
    env.close()


# -- mirror ----------------------------------------------------------------------------------------
def _faces(e0, e1):
    return {"infant_0": {"motors": NO_MOTORS, "expression": np.int64(e0)},
            "infant_1": {"motors": NO_MOTORS, "expression": np.int64(e1)}}


def _mirror(max_steps, **options):
    env = mirror_v0.parallel_env(vision=False, max_steps=max_steps,
                                 task_options={"roles": "free", **options})
    env.reset(seed=0)
    return env


def _run(env, matches):
    """One step per entry of ``matches`` (True: both faces happy; False: happy and sad); each
    step's infant_0 info and termination."""
    out = []
    for same in matches:
        _, _, term, _, info = env.step(_faces(1, 1 if same else 2))
        assert info["infant_0"]["is_success"] == info["infant_1"]["is_success"]
        out.append((info["infant_0"], term["infant_0"]))
    return out


def test_mirror_matched_steps_add_up_over_breaks():
    """M2: 5 of 10 steps must match (success_fraction 0.5); they come one at a time, a
    mismatch after each: the 5th matched step is the success."""
    env = _mirror(10, success_fraction=0.5)
    steps = _run(env, [True, False] * 5)
    assert [i["matched_steps"] for i, _ in steps] == [1, 1, 2, 2, 3, 3, 4, 4, 5, 5]
    assert [i["is_success"] for i, _ in steps] == [False] * 8 + [True] * 2
    env.close()


@pytest.mark.parametrize("fraction, need", [(0.45, 5), (0.5, 5), (0.8, 8), (0.01, 1)])
def test_mirror_success_needs_success_fraction_of_the_steps_rounded_up(fraction, need):
    """M3: of a 10-step episode, success needs ceil(success_fraction x 10) matched steps: not
    one fewer."""
    env = _mirror(10, success_fraction=fraction)
    steps = _run(env, [True] * 10)
    assert [i["is_success"] for i, _ in steps] == [False] * (need - 1) + [True] * (11 - need)
    env.close()
    default = _mirror(20)                      # 0.8 of 20 steps: 16
    steps = _run(default, [False] * 4 + [True] * 16)
    assert not any(i["is_success"] for i, _ in steps[:-1]) and steps[-1][0]["is_success"]
    default.close()


def test_mirror_success_does_not_end_the_episode():
    """M4: success secured, the episode runs on to max_steps (every matched step still pays)."""
    env = _mirror(10, success_fraction=0.2)
    steps = _run(env, [True] * 9)
    assert steps[1][0]["is_success"] and not any(t for _, t in steps)
    assert env.agents == ["infant_0", "infant_1"]
    *_, trunc, _ = env.step(_faces(1, 1))
    assert trunc["infant_0"] and env.agents == []
    env.close()
