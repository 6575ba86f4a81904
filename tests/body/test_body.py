"""The infant body against the published figures (mimo-figures.md, paper Table I)."""

import mujoco
import numpy as np
import pytest

from mimo_social.body.builder import build_infant
from mimo_social.body.tables import load_body
from mimo_social.envs import free_play_v0


@pytest.fixture(scope="module")
def infant():
    b = build_infant()
    m = b.spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    return b, m, d


def test_mass_matches_published_total(infant):
    _, m, _ = infant
    assert m.body_subtreemass[m.body("hip").id] == pytest.approx(10.90, abs=0.01)


def test_standing_height_is_77_8_cm():
    env = free_play_v0.parallel_env(n_agents=1)
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    a = env.world.agents[0]
    # straighten every joint to measure the standing height with the head upright
    d.qpos[a.qpos_adr] = 0.0
    mujoco.mj_kinematics(m, d)
    from mimo_social.core.world import _support_below
    top = d.geom_xpos[a.head_geom, 2] + m.geom_size[a.head_geom, 0]
    bottom = _support_below(m, d, a.geom_ids).min()
    assert top - bottom == pytest.approx(0.778, abs=0.004)


def test_degrees_of_freedom(infant):
    b, m, _ = infant
    assert m.nu == 44                     # 30 body + 6 eyes + 2 x 4 mitten hand
    eyes = [n for n in b.actuated if "_eye_" in n]
    hands = [n for n in b.actuated if "wrist" in n or "fingers" in n]
    assert len(eyes) == 6 and len(hands) == 8 and m.nu - 14 == 30
    assert m.nv == 6 + 47                 # free root + 47 hinges (3 coupled trunk joints)
    assert m.neq == 3                     # the trunk's coupled pairs


def test_joint_ranges_and_torques_follow_table_I(infant):
    _, m, _ = infant
    expected = {  # Table I (deg) and the directional torques (Nm)
        "right_knee": ((-145, 4), (-6.5, 10)),
        "right_elbow": ((-146, 5), (-3.6, 2.988)),
        "head_swivel": ((-111, 111), (-1.8, 1.8)),
        "right_hip_flexion": ((-133, 20), (-8, 8)),
        "left_shoulder_abduction": ((-84, 183), (-2.75, 4)),
        "trunk_bend": (None, (-10.58, 8.0937)),
    }
    for name, (rng, (tneg, tpos)) in expected.items():
        if rng is not None:
            np.testing.assert_allclose(np.rad2deg(m.joint(name).range), rng, atol=1e-6)
        np.testing.assert_allclose(m.actuator(name).ctrlrange, (tneg, tpos), rtol=1e-3)


def test_left_side_mirrors_right(infant):
    _, m, d = infant
    r = d.xpos[m.body("right_hand").id]
    l_ = d.xpos[m.body("left_hand").id]
    np.testing.assert_allclose(r * [1, -1, 1], l_, atol=1e-9)
    tables = load_body()
    by = {j.name: j for j in tables.joints}
    assert by["left_hip_abduction"].axis == (-1.0, 0.0, -0.0) or by["left_hip_abduction"].axis == (-1, 0, 0)


def test_passive_parameters_are_the_published_ones(infant):
    _, m, _ = infant
    j = m.joint("right_knee")
    assert m.jnt_stiffness[j.id] == pytest.approx(1.63)
    assert m.dof_damping[j.dofadr[0]] == pytest.approx(0.53)
    assert m.dof_frictionloss[j.dofadr[0]] == pytest.approx(0.065)
    assert m.dof_armature[j.dofadr[0]] == pytest.approx(0.003)
    assert np.rad2deg(m.qpos_spring[j.qposadr[0]]) == pytest.approx(-30)


@pytest.mark.parametrize("posture", ["standing", "sitting", "lying"])
def test_no_self_contact_in_the_initial_postures(posture):
    env = free_play_v0.parallel_env(n_agents=1, posture=posture)
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    floor = m.geom("floor").id
    pairs = {(m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]) for c in d.contact[: d.ncon]
             if floor not in (c.geom1, c.geom2)}
    assert not pairs, [(m.body(a).name, m.body(b).name) for a, b in pairs]


def test_frozen_joints_disappear_and_motors_with_them():
    b = build_infant(frozen={"right_knee": -0.5, "left_knee": -0.5}, base="fixed")
    m = b.spec.compile()
    assert "right_knee" not in b.joints and "right_knee" not in b.actuated
    assert m.nu == 42 and m.nv == 45


def test_bad_body_arguments():
    with pytest.raises(ValueError, match="allowed"):
        build_infant(hands="claws")
    with pytest.raises(ValueError, match="known joints"):
        build_infant(frozen={"tail": 0.0})
    with pytest.raises(ValueError, match="outside its range"):
        build_infant(frozen={"right_knee": 1.0})
