"""The five-fingered body (published v2: five fingers per hand, two toes per foot)."""

import mujoco
import numpy as np
import pytest
from pettingzoo.test import parallel_api_test, parallel_seed_test

import mimo_social  # noqa: F401  (headless GL before mujoco renders)
from mimo_social.body.actuation import MODELS
from mimo_social.body.builder import build_infant
from mimo_social.body.tables import load_body
from mimo_social.envs import free_play_v0, high_five_v0, reach_v0
from mimo_social.core.config import AgentConfig, PhysicsConfig
from mimo_social.body.joint_groups import held_posture
from mimo_social.core.kinematics import hand_geoms
from mimo_social.core.world import AgentSetup, Prop, World

FINGERS = ("index", "middle", "ring", "little", "thumb")


@pytest.fixture(scope="module")
def infant():
    b = build_infant("five_fingers", base="fixed")
    m = b.spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    return b, m, d


def test_builds_with_88_motors_and_the_published_mass(infant):
    b, m, _ = infant
    assert m.nu == 88 and len(b.actuated) == 88
    assert m.body_subtreemass[m.body("hip").id] == pytest.approx(10.90, abs=0.005)
    for side in ("right", "left"):
        hand = [n for n in b.actuated if n.startswith(f"{side}_") and
                (n.split("_")[1] in FINGERS or "wrist" in n)]
        assert len(hand) == 25                               # wrist 3 + 22 finger joints
        for finger, count in (("thumb", 5), ("little", 5), ("index", 4), ("middle", 4), ("ring", 4)):
            assert len([n for n in hand if n.startswith(f"{side}_{finger}_")]) == count
        assert {f"{side}_big_toe", f"{side}_toes"} <= set(b.actuated)
    # 30 body + 6 eyes + 2 x 26 hands (wrist 3 + 22 fingers ... + the toes split in two)
    assert m.nv == 88 + 3                                    # + the coupled upper trunk


def test_finger_figures_follow_the_published_v2_table(infant):
    _, m, _ = infant
    expected = {  # range (deg), (-T_neg, T_pos) (Nm) = gear * forcerange
        "right_index_mcp": ((-20, 90), (-0.0619 * 0.345, 0.0619)),
        "right_middle_pip": ((-5, 100), (-0.039 * 0.345, 0.039)),
        "left_little_dip": ((-5, 80), (-0.0049 * 0.345, 0.0049)),
        "right_thumb_swivel": ((-10, 110), (-0.373 * 0.345, 0.373)),
        "left_thumb_adduction": ((-60, 0), (-0.134, 0.134)),
        "right_little_cup": ((0, 40), (-0.064 * 0.345, 0.064)),
        "right_big_toe": ((-60, 80), (-0.165, 0.165 * 0.3)),
    }
    for name, (rng, torques) in expected.items():
        np.testing.assert_allclose(np.rad2deg(m.joint(name).range), rng, atol=1e-9)
        np.testing.assert_allclose(m.actuator(name).ctrlrange, torques, rtol=1e-6)
    j = m.joint("right_index_mcp")
    assert m.jnt_stiffness[j.id] == pytest.approx(0.0008)
    assert np.rad2deg(m.qpos_spring[j.qposadr[0]]) == pytest.approx(45)
    assert m.body_mass[m.body("right_thumb_metacarpal").id] == pytest.approx(0.005463)
    assert m.body_mass[m.body("left_hand").id] == pytest.approx(0.030162)


def test_every_body_with_geoms_has_a_touch_spacing(infant):
    _, m, _ = infant
    spacing = load_body("five_fingers").touch_spacing
    with_geoms = {m.body(b).name for b in range(1, m.nbody) if m.body_geomnum[b] > 0}
    assert not with_geoms - set(spacing), sorted(with_geoms - set(spacing))
    assert spacing["left_thumb_distal"] == 0.002 and spacing["right_little_metacarpal"] == 0.007


def _tip(m, d, body):
    g = int(m.body_geomadr[m.body(body).id])
    R = d.geom_xmat[g].reshape(3, 3)
    return d.geom_xpos[g] + R[:, 2] * (m.geom_size[g, 1] + m.geom_size[g, 0])


@pytest.mark.parametrize("side", ["right", "left"])
def test_flexion_curls_every_finger_towards_the_palm(infant, side):
    b, m, d = infant
    tables = load_body("five_fingers")
    hand = m.body(f"{side}_hand").id
    palm = m.site(f"{side}_palm_centre").id
    palm_side = -1.0 if side == "right" else 1.0   # the palm faces the hand's -y (right), +y (left)

    def pose(extra):
        d.qpos[:] = 0.0
        for n, v in {f"{side}_thumb_swivel": 40, f"{side}_thumb_adduction": -35, **extra}.items():
            d.qpos[m.joint(n).qposadr[0]] = np.deg2rad(v)
        mujoco.mj_kinematics(m, d)
        R = d.xmat[hand].reshape(3, 3)
        return R, d.xpos[hand].copy(), d.site_xpos[palm].copy()

    for finger in FINGERS:
        flexors = [j.name for j in tables.joints if j.name.startswith(f"{side}_{finger}_")
                   and j.name.split("_")[-1] in ("mcp", "pip", "dip", "cup", "swivel", "ip")]
        assert len(flexors) == (4 if finger == "little" else 3)
        R, o, c = pose({})
        tip0 = R.T @ (_tip(m, d, f"{side}_{finger}_distal") - o)
        centre = R.T @ (c - o)
        for j in flexors:
            base = {f"{side}_thumb_swivel": 40}.get(j, 0)
            R, o, _ = pose({j: base + 20})
            tip1 = R.T @ (_tip(m, d, f"{side}_{finger}_distal") - o)
            # the tip moves to the palm side, and closer to the palm centre
            assert palm_side * (tip1[1] - tip0[1]) > 0.002, (j, tip1 - tip0)
            assert np.linalg.norm(tip1 - centre) < np.linalg.norm(tip0 - centre), j


def test_left_hand_mirrors_the_right(infant):
    _, m, _ = infant
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    for part in ("hand", "thumb_distal", "little_distal", "index_middle", "big_toe"):
        r = d.xpos[m.body(f"right_{part}").id]
        left = d.xpos[m.body(f"left_{part}").id]
        np.testing.assert_allclose(r * [1, -1, 1], left, atol=1e-9)


@pytest.mark.parametrize("posture", ["standing", "sitting", "lying"])
def test_no_self_contact_in_the_initial_postures(posture):
    env = free_play_v0.parallel_env(n_agents=1, posture=posture, hands="five_fingers")
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    floor = m.geom("floor").id
    pairs = {(m.body(m.geom_bodyid[c.geom1]).name, m.body(m.geom_bodyid[c.geom2]).name)
             for c in d.contact[: d.ncon] if floor not in (c.geom1, c.geom2)}
    assert not pairs, pairs


# -- grasping a ball ---------------------------------------------------------------------------------
# the right arm forward, palm up (degrees)
PALM_UP = {"right_shoulder_horizontal": 95.7, "right_shoulder_abduction": 24.3,
           "right_shoulder_rotation": -89.7, "right_elbow": -84.2,
           "right_wrist_rotation": -76.9, "right_wrist_flexion": 34.7, "right_wrist_ulnar": 12.3}
BALL_R = 0.018


def _grasp(actuation, flex=True, steps=300):
    tables = load_body("five_fingers")
    fingers = tuple(j.name for j in tables.joints
                    if j.body.startswith("right_") and j.body.split("_")[1] in FINGERS)
    frozen = held_posture(tables, keep=fingers, angles=PALM_UP)
    cfg = AgentConfig(hands="five_fingers", actuation=actuation, expressions=False)
    w = World([AgentSetup(cfg, frozen=frozen, base="fixed", actuated=fingers)],
              [Prop("ball", "sphere", (BALL_R,), (0.5, 0.5, 1.0), 0.1)], PhysicsConfig())
    m, d = w.model, w.data
    a = w.agents[0]
    for k, n in enumerate(a.joint_names):  # fingers stretched, the thumb relaxed
        if n in fingers:
            d.qpos[a.qpos_adr[k]] = np.deg2rad({"right_thumb_swivel": 40,
                                                "right_thumb_adduction": -35}.get(n, 0.0))
    mujoco.mj_forward(m, d)
    hand = m.site_bodyid[a.palm_sites[0]]
    R = d.xmat[hand].reshape(3, 3)
    assert -R[2, 1] > 0.99                                   # the palm faces up
    q = w.prop_qpos["ball"]
    d.qpos[q:q + 3] = d.site_xpos[a.palm_sites[0]] + (0.00584 + BALL_R + 0.001) * -R[:, 1] \
        + 0.02 * R[:, 2]
    mujoco.mj_forward(m, d)
    by = {j.name: j for j in tables.joints}
    act = MODELS[actuation]([by[n] for n in a.actuated_names], a.actuator_ids)
    act.reset(m, d)
    closing = np.array([0.0 if not flex or n.split("_")[-1] in ("spread", "pivot") else 1.0
                        for n in a.actuated_names])
    act.apply(m, d, closing if actuation == "spring_damper" else np.r_[0 * closing, closing])
    for _ in range(steps):
        act.substep(m, d)
        mujoco.mj_step(m, d)
    mujoco.mj_forward(m, d)
    ball = m.geom("ball").id
    touching = {m.body(m.geom_bodyid[c.geom1 + c.geom2 - ball]).name.split("/")[1]
                for c in d.contact[: d.ncon] if ball in (c.geom1, c.geom2)
                and c.geom1 + c.geom2 - ball in set(hand_geoms(w, 0).tolist())}
    dist = np.linalg.norm(d.xpos[m.body("ball").id] - d.site_xpos[a.palm_sites[0]])
    return touching, dist


@pytest.mark.parametrize("actuation", ["spring_damper", "muscle"])
def test_flexors_close_the_fingers_around_a_ball(actuation):
    touching, dist = _grasp(actuation)
    segments = {t for t in touching if t != "right_hand"}
    fingers = {t.split("_")[1] for t in segments}
    assert len(segments) >= 4 and len(fingers) >= 3 and "thumb" in fingers, touching
    assert dist < 0.04                                       # the ball is held at the palm
    relaxed, _ = _grasp(actuation, flex=False)               # without flexors: no grip
    assert len({t for t in relaxed if t != "right_hand"}) < len(segments)


# -- in the envs ---------------------------------------------------------------------------------------
MIXED = [{"hands": "mitten", "actuation": "spring_damper"},
         {"hands": "five_fingers", "actuation": "muscle"}]


def test_mixed_world_passes_the_pettingzoo_api_test():
    env = free_play_v0.parallel_env(n_agents=2, per_agent=MIXED, max_steps=50)
    parallel_api_test(env, num_cycles=60)
    assert env.action_space("infant_0")["motors"].shape == (44,)
    assert env.action_space("infant_1")["motors"].shape == (176,)


def test_mixed_world_seeds():
    parallel_seed_test(lambda: free_play_v0.parallel_env(n_agents=2, max_steps=30,
                                                         per_agent=MIXED[::-1]))


def test_tasks_take_the_five_fingered_hand():
    env = reach_v0.parallel_env(hands="five_fingers")
    env.reset(seed=0)
    assert env.action_space("infant_0").shape == (29,)       # arm 7 + 22 finger joints
    assert len(hand_geoms(env.world, 0)) == 4 + 17            # palm 4 + finger segments
    env.step({"infant_0": np.zeros(29, np.float32)})
    env = high_five_v0.parallel_env(per_agent=MIXED, max_steps=5)
    env.reset(seed=0)
    assert env.action_space("infant_1")["motors"].shape == (58,)   # 29 axes, 2 muscles each
    for _ in range(5):
        env.step({a: env.action_space(a).sample() for a in env.agents})


@pytest.mark.parametrize("kwargs, pattern", [
    ({"hands": "claws"}, r"hands='claws'.*'mitten', 'five_fingers'"),
    ({"actuation": "hydraulic"}, r"actuation='hydraulic'.*'spring_damper', 'muscle'"),
    ({"per_agent": [{}, {"hands": "claws"}]}, r"infant_1.*five_fingers"),
])
def test_bad_values_list_the_allowed_ones(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        free_play_v0.parallel_env(**kwargs)
    with pytest.raises(ValueError, match="allowed.*five_fingers"):
        build_infant(hands="claws")
