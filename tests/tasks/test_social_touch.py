"""Social touch: the toucher's FIRST touch of its partner must be its hand on the named part."""

import mujoco
import numpy as np
import pytest

from mimo_social.envs import social_touch_v0
from mimo_social.partners import Still
from mimo_social.tasks.social_touch.controller import hand_posture, reach_posture
from mimo_social.tasks.social_touch import task as social_touch

pytestmark = pytest.mark.text_infos   # these tests read the text infos (info_text=True)

#: the first versions' start: no random arm postures, the distance as given (tests that build
#: a touch by IK from the start posture)
FIXED_START = {"start_spread": 0.0, "partner_spread": 0.0, "distance_spread": 0.0}
MITTEN_TARGETS = ("upper_body", "lower_body", "left_upper_arm", "left_lower_arm", "left_hand",
                  "left_lower_leg")
REACHABLE = MITTEN_TARGETS + ("left_upper_leg",)


def _zero(env):
    return {a: np.zeros(env.action_space(a).shape, np.float32) for a in env.agents}


def _place(env, q):
    """Set the toucher's actuated joints (no physics) and bring the poses up to date."""
    w = env.world
    a = w.agents[0]
    w.data.qpos[a.qpos_adr[a.actuated_joint_idx]] = q
    w.data.qvel[:] = 0.0
    mujoco.mj_forward(w.model, w.data)


def _hand_into(env, part, depth=0.005):
    q, dist, worst = reach_posture(env.world, 0, 1, part, depth=depth)
    assert dist < 0.0 and worst < 1e-3, (part, dist, worst)
    _place(env, q)


def test_spaces_and_skins():
    env = social_touch_v0.parallel_env()
    obs, infos = env.reset(seed=0)
    assert env.task.targets == MITTEN_TARGETS == social_touch.DEFAULT_TARGETS
    assert set(social_touch.REACHABLE) == set(REACHABLE)
    s0, s1 = env.observation_space("infant_0"), env.observation_space("infant_1")
    assert set(s0) == {"proprioception", "touch", "target"} and s0["target"].shape == (6,)
    assert set(s1) == {"proprioception", "touch"}
    assert env.action_space("infant_0").shape == (8,)              # the right arm
    assert env.action_space("infant_1").shape == (16,)             # both arms
    touch = env.system("touch")
    assert set(touch.layout("infant_0")) == {"right_upper_arm", "right_lower_arm", "right_hand",
                                             "right_fingers"}
    assert set(MITTEN_TARGETS) < set(touch.layout("infant_1"))    # the whole body
    for a in env.possible_agents:
        assert env.observation_space(a).contains(obs[a])
        assert not any(e["agents"] for e in infos[a]["touch"].values())
    assert infos["infant_0"]["touch"] == {}                          # the arm starts free
    # sitting infants 0.37 m apart: the heads stay clear
    w = env.world
    m, d = w.model, w.data
    heads = [np.flatnonzero(m.geom_bodyid == m.body(f"infant_{i}/head").id) for i in (0, 1)]
    gap = min(mujoco.mj_geomDistance(m, d, int(g0), int(g1), 1.0, np.zeros(6))
              for g0 in heads[0] for g1 in heads[1])
    assert gap > 0.05
    # 0.37 m by default, drawn within 0.02 m of it each episode (distance_spread)
    apart = d.xpos[w.agents[1].body_ids[0]][0] - d.xpos[w.agents[0].body_ids[0]][0]
    assert apart == pytest.approx(env.task.distance) and abs(apart - 0.37) <= 0.02


def test_one_hot_target_matches_the_info_and_varies_with_the_seed():
    env = social_touch_v0.parallel_env()
    seen = set()
    for seed in range(12):
        obs, _ = env.reset(seed=seed)
        onehot = obs["infant_0"]["target"]
        assert onehot.sum() == 1.0
        _, r, _, _, info = env.step(_zero(env))
        target = info["infant_0"]["target_part"]
        assert info["infant_1"]["target_part"] == target == env.task.target
        assert MITTEN_TARGETS[int(onehot.argmax())] == target
        distance = info["infant_0"]["fingertip_distance"]
        assert r["infant_0"] == r["infant_1"] == pytest.approx(-distance)
        assert info["infant_0"]["first_touch"] is None and not info["infant_0"]["wrong_touch"]
        seen.add(target)
    assert len(seen) >= 4


@pytest.mark.parametrize("distance", [0.37, pytest.param(0.35, marks=pytest.mark.slow),
                                      pytest.param(0.40, marks=pytest.mark.slow)])
def test_every_allowed_target_is_within_reach(distance):
    """For each default (and each allowed) target a posture of the toucher's right arm (IK) puts
    the hand into it, touching nothing else of the partner; the partner's far side is out of
    reach."""
    env = social_touch_v0.parallel_env(task_options={"distance": distance, **FIXED_START})
    env.reset(seed=0)
    for part in REACHABLE:
        _, dist, worst = reach_posture(env.world, 0, 1, part)
        assert dist < -0.002 and worst < 1e-3, (part, dist, worst)
    assert reach_posture(env.world, 0, 1, "right_hand")[1] > 0.05


@pytest.mark.parametrize("target", ["upper_body", "left_hand", "left_lower_leg"])
def test_a_first_touch_on_the_target_rewards_both_and_the_partner_feels_it(target):
    env = social_touch_v0.parallel_env(task_options={"target": target})
    env.reset(seed=0)
    _hand_into(env, target)
    obs, r, term, trunc, info = env.step(_zero(env))
    for a in ("infant_0", "infant_1"):
        assert info[a]["is_success"] and term[a] and not trunc[a] and not info[a]["wrong_touch"]
        assert target in info[a]["first_touch"] and info[a]["target_felt"]
        assert r[a] == pytest.approx(100.0 - info[a]["fingertip_distance"])
    assert "infant_0" in info["infant_1"]["touch"][target]["agents"]
    lo, hi = env.system("touch").layout("infant_1")[target]
    assert obs["infant_1"]["touch"][lo:hi].sum() > 0.0
    assert {"right_hand", "right_fingers"} & set(info["infant_0"]["touch"])
    assert env.agents == []


def test_a_wrong_first_touch_ends_the_attempt_and_charges_the_rest_of_the_shaping():
    env = social_touch_v0.parallel_env(task_options={"target": "left_lower_leg"})
    env.reset(seed=0)
    _hand_into(env, "upper_body")
    _, r, term, _, info = env.step(_zero(env))
    i = info["infant_0"]
    assert i["first_touch"] == ["upper_body"] and i["wrong_touch"] and not i["is_success"]
    assert term["infant_0"] and term["infant_1"] and env.agents == []
    left = env.max_steps - 1
    assert r["infant_0"] == pytest.approx(-i["fingertip_distance"] * (1 + left))


def test_a_sweep_over_a_wrong_part_then_onto_the_target_is_no_success():
    """The hand is driven through another part first, then onto the target: no bonus, ever."""
    env = social_touch_v0.parallel_env(task_options={"target": "left_hand",
                                                     "end_on_touch": False})
    env.reset(seed=0)
    _hand_into(env, "left_upper_leg")
    _, r, term, _, info = env.step(_zero(env))
    assert info["infant_0"]["wrong_touch"] and not term["infant_0"]
    assert r["infant_0"] == pytest.approx(-info["infant_0"]["fingertip_distance"])
    _hand_into(env, "left_hand")
    for k in range(3):
        _, r, term, _, info = env.step(_zero(env))
        if k == 0:
            assert "left_hand" in info["infant_0"]["touched_parts"]   # the hand is on it
        assert not info["infant_0"]["is_success"] and r["infant_0"] < 0.0
        assert info["infant_0"]["first_touch"] == ["left_upper_leg"]
    # the same touch of the target, first: a success
    fresh = social_touch_v0.parallel_env(task_options={"target": "left_hand",
                                                       "end_on_touch": False})
    fresh.reset(seed=0)
    _hand_into(fresh, "left_hand")
    _, r, _, _, info = fresh.step(_zero(fresh))
    assert info["infant_0"]["is_success"] and r["infant_0"] > 90.0
    _, r, term, _, info = fresh.step(_zero(fresh))     # the bonus once; success stays
    assert info["infant_0"]["is_success"] and r["infant_0"] < 0.0 and not term["infant_0"]


def test_the_back_of_the_hand_does_not_count():
    env = social_touch_v0.parallel_env(task_options={"target": "lower_body", **FIXED_START})
    env.reset(seed=0)
    # the hand's touching direction turned to its back (the palm's normal turned 180 deg)
    q, _, _, u = hand_posture(env.world, 0, 1, "lower_body", 0.04, tilt_deg=180.0)
    q, dist, _, _ = hand_posture(env.world, 0, 1, "lower_body", -0.005, start=q,
                                 direction=u, tilt_deg=180.0, clearance=0.0)
    assert dist < 0.0
    _place(env, q)
    _, r, term, _, info = env.step(_zero(env))
    assert info["infant_0"]["first_touch"] == ["lower_body"]
    assert info["infant_0"]["wrong_touch"] and not info["infant_0"]["is_success"]
    assert term["infant_0"] and r["infant_0"] < 0.0
    # the same part touched with the finger pads: a success
    env.reset(seed=0)
    _hand_into(env, "lower_body")
    _, r, _, _, info = env.step(_zero(env))
    assert info["infant_0"]["is_success"] and r["infant_0"] > 90.0


def test_the_hand_includes_its_fingers():
    env = social_touch_v0.parallel_env(task_options={"target": "left_hand"})
    env.reset(seed=0)
    q, _, _ = reach_posture(env.world, 0, 1, "left_hand")
    _place(env, q)
    _, _, _, _, info = env.step(_zero(env))
    assert info["infant_0"]["is_success"]
    assert set(info["infant_0"]["first_touch"]) & {"left_hand", "left_fingers"}


def _toucher_run(target, assisted, steps=5):
    env = social_touch_v0.parallel_env(task_options={"target": target,
                                                     "assisted_gaze": assisted})
    obs, _ = env.reset(seed=7)
    out = [obs["infant_0"]]
    for _ in range(steps):
        obs, _, _, _, info = env.step(_zero(env))
        assert not info["infant_0"]["touched_parts"]            # before any contact
        out.append(obs["infant_0"])
    return out


def test_without_assisted_gaze_only_the_one_hot_depends_on_the_target():
    a, b = _toucher_run("left_hand", False), _toucher_run("upper_body", False)
    for oa, ob in zip(a, b):
        assert set(oa) == {"proprioception", "touch", "target"}
        np.testing.assert_array_equal(oa["proprioception"], ob["proprioception"])
        np.testing.assert_array_equal(oa["touch"], ob["touch"])
        assert not np.array_equal(oa["target"], ob["target"])
    # the privileged option puts the target's place into the eye angles
    a, b = _toucher_run("left_hand", True, 0), _toucher_run("upper_body", True, 0)
    assert not np.array_equal(a[0]["proprioception"], b[0]["proprioception"])


def _look_error_deg(env, agent, point):
    d = env.world.data
    mujoco.mj_camlight(env.world.model, d)
    cam = env.world.agents[agent].eye_cameras[0]
    look = -d.cam_xmat[cam].reshape(3, 3)[:, 2]
    v = point - d.cam_xpos[cam]
    return np.degrees(np.arccos(np.clip(look @ v / np.linalg.norm(v), -1.0, 1.0)))


def test_gaze_by_default_at_the_face_with_assisted_gaze_at_the_target():
    env = social_touch_v0.parallel_env(task_options={"target": "upper_body"})
    env.reset(seed=0)
    d = env.world.data
    for i in (0, 1):
        face = d.site_xpos[env.world.agents[1 - i].head_site].copy()
        assert _look_error_deg(env, i, face) < 2.0
    env = social_touch_v0.parallel_env(task_options={"target": "upper_body",
                                                     "assisted_gaze": True})
    env.reset(seed=0)
    part = env.world.data.xpos[env.world.model.body("infant_1/upper_body").id].copy()
    assert _look_error_deg(env, 0, part) < 2.0


def test_shaping_off_leaves_only_the_bonus():
    env = social_touch_v0.parallel_env(task_options={"target": "upper_body", "shaping": False})
    env.reset(seed=0)
    _, r, _, _, _ = env.step(_zero(env))
    assert r["infant_0"] == 0.0
    _hand_into(env, "upper_body")
    _, r, _, _, info = env.step(_zero(env))
    assert info["infant_0"]["is_success"] and r["infant_0"] == 100.0


def test_zero_and_random_actions_fail():
    env = social_touch_v0.scripted_env()
    space = env.action_space("infant_0")
    for seed in range(4):
        for policy in ("zero", "random"):
            env.reset(seed=seed)
            space.seed(seed)
            while True:
                a = space.sample() if policy == "random" else np.zeros(space.shape, np.float32)
                _, _, term, trunc, info = env.step({"infant_0": a})
                if term["infant_0"] or trunc["infant_0"]:
                    break
            assert not info["infant_0"]["is_success"], (policy, seed)


@pytest.mark.slow
def test_random_and_zero_success_at_most_15_percent_over_20_episodes():
    env = social_touch_v0.scripted_env()
    space = env.action_space("infant_0")
    for policy in ("zero", "random"):
        wins = 0
        for seed in range(20):
            env.reset(seed=seed)
            space.seed(seed)
            while True:
                a = space.sample() if policy == "random" else np.zeros(space.shape, np.float32)
                _, _, term, trunc, info = env.step({"infant_0": a})
                if term["infant_0"] or trunc["infant_0"]:
                    break
            wins += info["infant_0"]["is_success"]
        assert wins <= 3, (policy, wins)


def test_scripted_env_has_a_still_partner():
    env = social_touch_v0.scripted_env(max_steps=20)
    assert env.possible_agents == ["infant_0"] and isinstance(env.partners["infant_1"], Still)
    obs, _ = env.reset(seed=1)
    assert set(obs["infant_0"]) == {"proprioception", "touch", "target"}
    rng = np.random.default_rng(0)
    for _ in range(20):
        obs, r, term, trunc, info = env.step({"infant_0": rng.uniform(-1, 1, 8).astype(np.float32)})
        assert "is_success" in info["infant_0"]
        assert info["infant_0"]["partner_rewards"]["infant_1"] == r["infant_0"]   # shared reward
        if term["infant_0"] or trunc["infant_0"]:
            break
    assert trunc["infant_0"] or term["infant_0"]


def test_five_fingered_partner_gets_its_own_targets():
    env = social_touch_v0.parallel_env(per_agent=[{}, {"hands": "five_fingers"}], max_steps=3)
    env.reset(seed=0)
    assert env.task.targets == MITTEN_TARGETS
    env.step(_zero(env))


@pytest.mark.parametrize("kwargs, pattern", [
    ({"n_agents": 3}, r"n_agents=3 not allowed.*dyad"),
    ({"task_options": {"targets": ["upper_body", "tail"]}}, r"targets \['tail'\] are not body parts"),
    ({"task_options": {"targets": ["upper_body", "head", "right_foot"]}},
     (r"targets \['head', 'right_foot'\] are out of the toucher's reach at 0.35-0.4 m; "
      r"allowed: \['upper_body'")),
    ({"task_options": {"targets": "upper_body"}}, r"targets='upper_body' not allowed"),
    ({"task_options": {"target": "right_toes"}}, r"target='right_toes' not allowed; one of"),
    ({"task_options": {"targets": ["left_hand"], "target": "upper_body"}},
     r"target='upper_body' not allowed; one of \['left_hand'\]"),
    ({"task_options": {"distance": 0.28}}, r"distance=0.28 not allowed; allowed: a number from 0.35 to 0.4"),
    ({"task_options": {"distance": 0.41}}, r"distance=0.41 not allowed"),
    ({"task_options": {"success_reward": "lots"}}, r"success_reward='lots' not allowed"),
    ({"task_options": {"end_on_touch": 1}}, r"end_on_touch=1.*True or False"),
    ({"task_options": {"assisted_gaze": "yes"}}, r"assisted_gaze='yes'.*True or False"),
    ({"task_options": {"shaping": None}}, r"shaping=None.*True or False"),
    ({"task_options": {"colour": "red"}}, r"unknown task option.*'target'"),
    ({"per_agent": [{"touch": False}, {}]}, r"infant_0 has touch=False"),
    ({"per_agent": [{}, {"touch": {"exclude": ["left_hand"]}}]},
     r"infant_1's touch excludes \['left_hand'\]"),
])
def test_bad_options_say_what_is_allowed(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):   # ConfigError is a ValueError
        social_touch_v0.parallel_env(**kwargs)


@pytest.mark.parametrize("distance", [0.35, 0.40])
def test_the_infants_sit_apart_at_rest_over_the_distance_range(distance):
    """With zero commands for 1 s, nothing of one infant touches the other."""
    env = social_touch_v0.parallel_env(task_options={"distance": distance,
                                                     "distance_spread": 0.0}, max_steps=100)
    env.reset(seed=0)
    while env.agents:
        _, _, _, _, info = env.step(_zero(env))
        for a in info:
            assert not any(e["agents"] for e in info[a]["touch"].values())
        assert info["infant_0"]["first_touch"] is None


def _overlap_cm(world) -> float:
    """The deepest interpenetration (cm) between geoms of the two agents that collide, by
    MuJoCo's own distance (two held bodies make no contacts, so contacts would miss it)."""
    m, d = world.model, world.data
    solid = (m.geom_contype | m.geom_conaffinity) != 0
    first, second = (np.flatnonzero(solid & (world.geom_agent == i)) for i in (0, 1))
    worst = 0.0
    for g in first:
        for h in second:
            if np.linalg.norm(d.geom_xpos[g] - d.geom_xpos[h]) < (m.geom_rbound[g]
                                                                   + m.geom_rbound[h]):
                dist = mujoco.mj_geomDistance(m, d, int(g), int(h), 0.0, None)
                worst = max(worst, -100.0 * dist)
    return worst


@pytest.mark.parametrize("per_agent", [[{}, {"age_months": 6}], [{"age_months": 33}, {}],
                                       [{"posture": "lying"}, {"body": "adult",
                                                               "posture": "kneeling"}]])
def test_other_bodies_start_clear_of_each_other(per_agent):
    """Other bodies keep the floor between their forward depths as two 18-month-olds have it;
    that left a 6-month-old partner's head 3.5 cm in the toucher's, a 33-month-old toucher's
    feet 2.5 cm in the partner's, a lying toucher's feet 5 cm in the kneeling adult's thighs.
    The pair is now moved apart until clear, even at the closest distance a reset draws: after
    every reset nothing of one is inside the other (a touch within the check's 1 cm aside)."""
    env = social_touch_v0.scripted_env(per_agent=per_agent)
    for seed in range(6):
        env.reset(seed=seed)
        assert _overlap_cm(env.unwrapped.world) < 1.0, (per_agent, seed)
    env.close()


def test_the_scripted_toucher_touches_a_younger_partner():
    """With the 6-month-old partner placed clear, the scripted toucher still touches its
    target (seeds 0-1; 4 / 4 over seeds 0-3 when measured)."""
    from mimo_social.tasks.social_touch import SocialTouchController
    env = social_touch_v0.scripted_env(per_agent=[{}, {"age_months": 6}])
    inner = env.unwrapped
    for seed in range(2):
        obs, _ = env.reset(seed=seed)
        toucher = SocialTouchController()
        toucher.reset(inner, "infant_0", np.random.default_rng(seed))
        while env.agents:
            obs, _, _, _, info = env.step({"infant_0": toucher.act(inner, "infant_0",
                                                                   obs["infant_0"])})
        assert info["infant_0"]["is_success"], (seed, info["infant_0"])
    env.close()
