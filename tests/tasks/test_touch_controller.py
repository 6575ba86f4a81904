"""The scripted toucher of social touch (and the hack policies it must beat)."""

import numpy as np
import pytest

from mimo_social.envs import social_touch_v0
from mimo_social.tasks.social_touch import controller as touch
from mimo_social.tasks.social_touch.controller import (
    ArmSweep,
    NearestPartToucher,
    SocialTouchController,
)
from mimo_social.tasks.social_touch import task as social_touch
from learner_episodes import learner_episode  # this folder is on the path (rootdir-less)

pytestmark = pytest.mark.text_infos   # these tests read the text infos (info_text=True)


def _episode(policy, seed, **kwargs):
    """One episode of the scripted env (``Still`` partner) with ``policy`` acting for infant_0
    through its action space; returns (last info, return, actions seen)."""
    env = social_touch_v0.scripted_env(**kwargs)
    base = env.unwrapped
    obs, _ = env.reset(seed=seed)
    policy.reset(base, "infant_0", np.random.default_rng(seed))
    space = env.action_space("infant_0")
    total, actions = 0.0, []
    while True:
        a = policy.act(base, "infant_0", obs["infant_0"])
        assert space.contains(a)
        actions.append(a)
        obs, r, term, trunc, info = env.step({"infant_0": a})
        total += r["infant_0"]
        if term["infant_0"] or trunc["infant_0"]:
            return info["infant_0"], total, actions


@pytest.mark.parametrize("seed", [1000, 1001])
def test_the_scripted_toucher_touches_the_target_first(seed):
    info, ret, actions = _episode(SocialTouchController(), seed)
    assert info["is_success"] and not info["wrong_touch"], info
    assert info["target_part"] in info["first_touch"] or info["target_part"] == "left_hand"
    assert info["step"] < 250 and ret > 50.0
    # the same seed, the same actions (it plans on scratch copies only)
    _, again, actions2 = _episode(SocialTouchController(), seed)
    assert again == ret and all(np.array_equal(a, b) for a, b in zip(actions, actions2))


@pytest.mark.slow
def test_the_scripted_toucher_succeeds_in_at_least_80_percent_of_20_episodes():
    results = [_episode(SocialTouchController(), seed)[:2] for seed in range(1000, 1020)]
    wins = sum(info["is_success"] for info, _ in results)
    assert wins >= 16, wins


@pytest.mark.slow
@pytest.mark.parametrize("distance", [0.35, 0.40])
@pytest.mark.parametrize("target", social_touch.REACHABLE)
def test_the_scripted_toucher_reaches_each_allowed_target_over_the_distance_range(target,
                                                                                  distance):
    info, _, _ = _episode(SocialTouchController(), 0,
                          task_options={"targets": social_touch.REACHABLE, "target": target,
                                        "distance": distance, "distance_spread": 0.0})
    assert info["is_success"], info


def test_hacks_score_less_than_the_scripted_toucher():
    """Touching the nearest part whatever the instruction, or sweeping the arm across the
    partner, loses to a deliberate touch of the named part (return and success)."""
    seeds = (1000, 1002, 1003)
    scripted = [_episode(SocialTouchController(), s)[:2] for s in seeds]
    for hack in (NearestPartToucher(), ArmSweep()):
        runs = [_episode(hack, s)[:2] for s in seeds]
        assert np.mean([r for _, r in runs]) < np.mean([r for _, r in scripted]) - 50.0, hack
        assert sum(i["is_success"] for i, _ in runs) < sum(i["is_success"] for i, _ in scripted)


@pytest.mark.slow
def test_hacks_score_less_over_20_episodes():
    seeds = range(1000, 1020)
    scripted = np.mean([_episode(SocialTouchController(), s)[1] for s in seeds])
    for hack in (NearestPartToucher(), ArmSweep()):
        assert np.mean([_episode(hack, s)[1] for s in seeds]) < scripted - 50.0, hack


FIXED_START = {"start_spread": 0.0, "partner_spread": 0.0, "distance_spread": 0.0}


def test_a_given_target_overrides_the_task_s():
    info, _, _ = _episode(SocialTouchController(target="left_hand"), 1000,
                          task_options={"target": "upper_body", **FIXED_START})
    assert set(info["first_touch"]) & {"left_hand", "left_fingers"}
    assert info["wrong_touch"] and not info["is_success"]


def test_the_back_of_hand_rule_is_the_task_s():
    assert touch.BACK_COS == social_touch.BACK_COS


def test_bad_arguments_and_envs_say_what_is_wrong():
    with pytest.raises(ValueError, match=r"target=''; allowed: None or a body part name"):
        SocialTouchController(target="")
    with pytest.raises(ValueError, match=r"standoff=0.5 not allowed"):
        SocialTouchController(standoff=0.5)
    env = social_touch_v0.parallel_env()
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"target 'tail' is no body part of infant_1"):
        SocialTouchController(target="tail").reset(env, "infant_0", np.random.default_rng(0))
    muscles = social_touch_v0.parallel_env(per_agent=[{"actuation": "muscle"}, {}])
    muscles.reset(seed=0)
    with pytest.raises(ValueError, match=r"infant_0 has actuation='muscle'; allowed: "
                                         r"'spring_damper' \(the task's\) or 'positional'"):
        SocialTouchController().reset(muscles, "infant_0", np.random.default_rng(0))
    three = social_touch_v0.parallel_env()
    three.reset(seed=0)
    three.possible_agents = ["infant_0", "infant_1", "infant_2"]   # not a dyad
    with pytest.raises(ValueError, match=r"needs a dyad"):
        SocialTouchController().reset(three, "infant_0", np.random.default_rng(0))


def test_a_positional_toucher_targets_the_waypoints_and_succeeds():
    """With positional actuation the toucher's action is each waypoint (plus the gravity torque
    over the servo's stiffness) as target angles: it succeeds from the random starts (seeds
    1000-1007; measured 10 / 10 on 1000-1009, the touch after about 0.25 s), and while it holds
    a waypoint its action decodes to that waypoint within the gravity offset."""
    env = social_touch_v0.scripted_env(per_agent=[{"actuation": "positional"}, {}])
    wins = 0
    for seed in range(1000, 1008):
        ok, _, steps = learner_episode(env, SocialTouchController(), seed)
        wins += ok
        assert steps < 100, (seed, steps)
    assert wins >= 7, wins
    env.reset(seed=1000)
    inner = env.unwrapped
    c = SocialTouchController()
    c.reset(inner, "infant_0", np.random.default_rng(1000))
    act = inner.actuation[0]
    u = c.act(inner, "infant_0", None)
    u = u["motors"] if isinstance(u, dict) else u
    names = list(inner.world.agents[0].actuated_names)
    arm = [names.index(n) for n in ("right_shoulder_horizontal", "right_shoulder_abduction",
                                    "right_elbow")]
    np.testing.assert_allclose(act.targets(u)[arm], c.target_angles[arm], atol=0.05)
