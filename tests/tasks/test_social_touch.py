"""Social touch: the toucher touches a named part of its partner, who feels it on its skin."""

import mujoco
import numpy as np
import pytest

from mimo_social.envs import social_touch_v0
from mimo_social.core.kinematics import hand_geoms, reach_sites
from mimo_social.partners import Still

MITTEN_TARGETS = ("head", "upper_body", "lower_body", "left_upper_arm", "left_lower_arm",
                  "left_hand", "left_fingers", "left_upper_leg", "left_lower_leg")


def _zero(env):
    return {a: np.zeros(env.action_space(a).shape, np.float32) for a in env.agents}


def _hand_onto(env, part):
    """Move the toucher's right arm (joint angles, no physics) so that its fingertips go to the
    centre of mass of the partner's ``part``."""
    w = env.world
    m, d = w.model, w.data
    a = w.agents[0]
    k = a.actuated_joint_idx
    target = d.xipos[m.body(f"infant_1/{part}").id].copy()
    reach_sites(m, d, a.qpos_adr[k], a.dof_adr[k], a.joint_range[k, 0], a.joint_range[k, 1],
                a.fingertip_sites[0], target, 300)
    mujoco.mj_forward(m, d)


def test_spaces_and_skins():
    env = social_touch_v0.parallel_env()
    obs, infos = env.reset(seed=0)
    assert env.task.targets == MITTEN_TARGETS
    s0, s1 = env.observation_space("infant_0"), env.observation_space("infant_1")
    assert set(s0) == {"proprioception", "touch", "target"} and s0["target"].shape == (9,)
    assert set(s1) == {"proprioception", "touch"}
    assert env.action_space("infant_0").shape == (8,)              # the right arm
    assert env.action_space("infant_1").shape == (16,)             # both arms
    touch = env.system("touch")
    assert set(touch.layout("infant_0")) == {"right_upper_arm", "right_lower_arm", "right_hand",
                                             "right_fingers"}
    assert set(MITTEN_TARGETS) < set(touch.layout("infant_1"))    # the whole body
    for a in env.possible_agents:
        assert env.observation_space(a).contains(obs[a])
        # the skins feel the floor and the own body (crossed legs), never the other infant
        assert not any(e["agents"] for e in infos[a]["touch"].values())
    assert infos["infant_0"]["touch"] == {}                          # the arm starts free
    assert {"left_hand", "left_upper_leg"} <= set(infos["infant_1"]["touch"])  # hands on legs
    assert obs["infant_1"]["touch"].any()


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
        seen.add(target)
    assert len(seen) >= 4
    fixed = social_touch_v0.parallel_env(task_options={"target": "left_hand"})
    for seed in range(3):
        obs, _ = fixed.reset(seed=seed)
        assert obs["infant_0"]["target"][MITTEN_TARGETS.index("left_hand")] == 1.0


def test_every_default_target_is_within_reach():
    """Random postures of the toucher's right arm touch each default target (and the far side
    of the partner never)."""
    env = social_touch_v0.parallel_env()
    env.reset(seed=0)
    w = env.world
    m, d = w.model, w.data
    a = w.agents[0]
    k = a.actuated_joint_idx
    hand = [int(g) for g in hand_geoms(w, 0, 0)]
    parts = {p: [int(g) for g in np.flatnonzero(m.geom_bodyid == m.body(f"infant_1/{p}").id)]
             for p in MITTEN_TARGETS + ("right_hand", "right_foot")}
    hits = dict.fromkeys(parts, 0)
    rng = np.random.default_rng(0)
    fromto = np.zeros(6)
    for _ in range(1500):
        d.qpos[a.qpos_adr[k]] = rng.uniform(a.joint_range[k, 0], a.joint_range[k, 1])
        mujoco.mj_kinematics(m, d)
        for p, geoms in parts.items():
            hits[p] += min(mujoco.mj_geomDistance(m, d, h, g, 0.05, fromto)
                           for h in hand for g in geoms) < 0.0
    assert all(hits[p] > 0 for p in MITTEN_TARGETS), hits
    assert hits["right_hand"] == hits["right_foot"] == 0, hits


@pytest.mark.parametrize("target", ["upper_body", "left_lower_arm", "left_upper_leg"])
def test_touching_the_target_rewards_both_and_the_partner_feels_it(target):
    env = social_touch_v0.parallel_env(task_options={"target": target})
    env.reset(seed=0)
    _hand_onto(env, target)
    obs, r, term, trunc, info = env.step(_zero(env))
    for a in ("infant_0", "infant_1"):
        assert info[a]["is_success"] and info[a]["target_felt"] and term[a] and not trunc[a]
        assert target in info[a]["touched_parts"]
        assert r[a] == pytest.approx(100.0 - info[a]["fingertip_distance"])
    # the touched infant's skin: force on that part, and the toucher named as its source
    assert "infant_0" in info["infant_1"]["touch"][target]["agents"]
    lo, hi = env.system("touch").layout("infant_1")[target]
    assert obs["infant_1"]["touch"][lo:hi].sum() > 0.0
    # the toucher feels it too, on its right hand
    assert {"right_hand", "right_fingers"} & set(info["infant_0"]["touch"])
    assert env.agents == []


def test_touching_another_part_does_not_end_the_episode():
    env = social_touch_v0.parallel_env(task_options={"target": "left_lower_leg"})
    env.reset(seed=0)
    _hand_onto(env, "upper_body")
    obs, r, term, _, info = env.step(_zero(env))
    assert info["infant_0"]["touched_parts"] == ["upper_body"]
    assert "infant_0" in info["infant_1"]["touch"]["upper_body"]["agents"]  # felt, not the target
    assert not info["infant_0"]["is_success"] and not info["infant_1"]["target_felt"]
    assert not term["infant_0"] and not term["infant_1"]
    assert r["infant_0"] == pytest.approx(-info["infant_0"]["fingertip_distance"])
    assert r["infant_0"] < 0.0
    assert env.agents == ["infant_0", "infant_1"]


def test_without_end_on_touch_the_episode_goes_on():
    env = social_touch_v0.parallel_env(task_options={"target": "upper_body",
                                                     "end_on_touch": False,
                                                     "success_reward": 5.0})
    env.reset(seed=0)
    _hand_onto(env, "upper_body")
    _, r, term, _, info = env.step(_zero(env))
    assert info["infant_1"]["is_success"] and not term["infant_1"]
    assert r["infant_1"] == pytest.approx(5.0 - info["infant_1"]["fingertip_distance"])


def test_the_toucher_looks_at_the_target():
    env = social_touch_v0.parallel_env(task_options={"target": "left_hand"})
    env.reset(seed=0)
    w = env.world
    d = w.data
    mujoco.mj_camlight(w.model, d)
    part = d.xpos[w.model.body("infant_1/left_hand").id]
    cam = w.agents[0].eye_cameras[0]
    look = -d.cam_xmat[cam].reshape(3, 3)[:, 2]
    to_part = part - d.cam_xpos[cam]
    assert look @ to_part / np.linalg.norm(to_part) > np.cos(np.deg2rad(2.0))


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
    assert env.task.targets == tuple(t for t in MITTEN_TARGETS if t != "left_fingers")
    env.step(_zero(env))


@pytest.mark.parametrize("kwargs, pattern", [
    ({"n_agents": 3}, r"n_agents=3 not allowed.*dyad"),
    ({"task_options": {"targets": ["head", "tail"]}}, r"targets \['tail'\] are not body parts"),
    ({"task_options": {"targets": "head"}}, r"targets='head' not allowed"),
    ({"task_options": {"target": "right_toes"}}, r"target='right_toes' not allowed; one of"),
    ({"task_options": {"distance": 0.1}}, r"distance=0.1 not allowed; allowed: a number from 0.25 to 0.4"),
    ({"task_options": {"success_reward": "lots"}}, r"success_reward='lots' not allowed"),
    ({"task_options": {"end_on_touch": 1}}, r"end_on_touch=1.*True or False"),
    ({"task_options": {"colour": "red"}}, r"unknown task option.*'target'"),
    ({"per_agent": [{"touch": False}, {}]}, r"infant_0 has touch=False"),
    ({"per_agent": [{}, {"touch": {"exclude": ["head"]}}]},
     r"infant_1's touch excludes \['head'\]"),
])
def test_bad_options_say_what_is_allowed(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):   # ConfigError is a ValueError
        social_touch_v0.parallel_env(**kwargs)


@pytest.mark.parametrize("distance", [0.25, 0.4])
def test_the_infants_sit_apart_at_rest_over_the_distance_range(distance):
    """With zero commands for 1 s, nothing of one infant touches the other."""
    env = social_touch_v0.parallel_env(task_options={"distance": distance}, max_steps=100)
    env.reset(seed=0)
    while env.agents:
        _, _, _, _, info = env.step(_zero(env))
        for a in info:
            assert not any(e["agents"] for e in info[a]["touch"].values())
