"""Heterogeneous agents: body size and strength (``scale``, ``strength``) and mixed bodies.

The scaling laws (docs/bodies.md): lengths x s, masses x s^3, inertias x s^5, motor torques and
joint stiffness x s^4 (x strength for motors), damping x s^4.5, armature x s^5, muscle fmax
x s^4 x strength, vmax x s^-0.5, touch spacing x s.
"""

import pickle

import mujoco
import numpy as np
import pytest

from mimo_social.body.actuation import Muscle, SpringDamper
from mimo_social.body.builder import build_infant
from mimo_social.body.tables import load_body
from mimo_social.envs import free_play_v0
from mimo_social.core.config import AgentConfig, ConfigError, PhysicsConfig
from mimo_social.core.world import AgentSetup, World, _support_below

MODEL_ARRAYS = ("body_pos", "body_quat", "body_mass", "body_inertia", "body_ipos", "geom_size",
                "geom_pos", "geom_friction", "jnt_pos", "jnt_range", "jnt_stiffness",
                "dof_damping", "dof_armature", "dof_frictionloss", "actuator_ctrlrange",
                "site_pos", "cam_pos")


def compiled(hands="mitten", **kw):
    return build_infant(hands, **kw).spec.compile()


def zero_actions(env):
    out = {}
    for a in env.agents:
        sp = env.action_space(a)
        motors = sp["motors"] if hasattr(sp, "spaces") else sp
        z = np.zeros(motors.shape, np.float32)
        out[a] = {"motors": z, "expression": 0} if hasattr(sp, "spaces") else z
    return out


def straight_height(env, i):
    """Top of the head above the lowest point of agent i with every hinge at 0 (standing up)."""
    m, d = env.world.model, env.world.data
    a = env.world.agents[i]
    d.qpos[a.qpos_adr] = 0.0
    mujoco.mj_kinematics(m, d)
    top = d.geom_xpos[a.head_geom, 2] + m.geom_size[a.head_geom, 0]
    bottom = _support_below(m, d, a.geom_ids).min()
    eye = d.cam_xpos[a.eye_cameras, 2].mean() - bottom
    return top - bottom, eye


def inter_agent_contacts(env) -> int:
    d, ga = env.world.data, env.world.geom_agent
    g1, g2 = d.contact.geom1[: d.ncon], d.contact.geom2[: d.ncon]
    return int(((ga[g1] != ga[g2]) & (ga[g1] >= 0) & (ga[g2] >= 0)).sum())


# -- scale 1 is the published body -------------------------------------------------------------
@pytest.mark.parametrize("hands", ["mitten", "five_fingers"])
def test_scale_one_is_the_model_of_before(hands):
    assert load_body(hands) is load_body(hands, 1.0, 1.0) is load_body(hands, scale=1, strength=1)
    m0, m1 = compiled(hands), compiled(hands, scale=1.0, strength=1.0)
    for name in MODEL_ARRAYS:
        np.testing.assert_array_equal(getattr(m0, name), getattr(m1, name), err_msg=name)
    # the figures of the body before sizes could change (total mass, sum of body offsets)
    mass, offsets = {"mitten": (10.90487, 2.38015), "five_fingers": (10.8999078, 3.23613)}[hands]
    assert m1.body_subtreemass[m1.body("hip").id] == pytest.approx(mass, rel=1e-12)
    assert np.abs(m1.body_pos).sum() == pytest.approx(offsets, rel=1e-12)


def test_scale_one_places_infants_as_before():
    env = free_play_v0.parallel_env(n_agents=2, per_agent=[{}, {"posture": "sitting",
                                                                "scale": 1.0, "strength": 1.0}])
    env.reset(seed=0)
    q = env.world.initial_qpos
    a0, a1 = env.world.agents
    np.testing.assert_allclose(q[a0.free_qpos:a0.free_qpos + 3], (-0.59, 0.0, 0.348071192),
                               atol=1e-9)
    np.testing.assert_allclose(q[a1.free_qpos:a1.free_qpos + 3], (0.59, 0.0, 0.0685812801),
                               atol=1e-9)


# -- the laws at scale 2 -----------------------------------------------------------------------
def test_scale_two_follows_the_laws():
    m1, m2 = compiled(), compiled(scale=2.0)
    hip = m1.body("hip").id
    assert m2.body_subtreemass[hip] / m1.body_subtreemass[hip] == pytest.approx(8.0, rel=1e-6)
    massive = m1.body_mass > 0
    np.testing.assert_allclose(m2.body_mass[massive] / m1.body_mass[massive], 8.0, rtol=1e-9)
    # MuJoCo computes the inertias from the scaled masses and shapes: x 2^5
    np.testing.assert_allclose(m2.body_inertia[massive] / m1.body_inertia[massive], 32.0,
                               rtol=1e-6)
    np.testing.assert_allclose(m2.body_pos, 2.0 * m1.body_pos, atol=1e-12)
    np.testing.assert_allclose(m2.geom_size, 2.0 * m1.geom_size, atol=1e-12)
    np.testing.assert_allclose(m2.site_pos, 2.0 * m1.site_pos, atol=1e-12)
    np.testing.assert_allclose(m2.jnt_range, m1.jnt_range)                 # angles unchanged
    np.testing.assert_allclose(m2.qpos_spring, m1.qpos_spring)
    np.testing.assert_allclose(m2.jnt_stiffness, 16.0 * m1.jnt_stiffness, rtol=1e-12)
    np.testing.assert_allclose(m2.dof_damping, 2.0 ** 4.5 * m1.dof_damping, rtol=1e-12)
    np.testing.assert_allclose(m2.dof_frictionloss, 16.0 * m1.dof_frictionloss, rtol=1e-12)
    np.testing.assert_allclose(m2.dof_armature, 32.0 * m1.dof_armature, rtol=1e-12)
    np.testing.assert_allclose(m2.geom_friction[:, 0], m1.geom_friction[:, 0])  # sliding
    np.testing.assert_allclose(m2.geom_friction[:, 1:], 2.0 * m1.geom_friction[:, 1:])
    np.testing.assert_allclose(m2.actuator_ctrlrange, 16.0 * m1.actuator_ctrlrange, rtol=1e-12)


def test_scale_two_is_twice_as_tall_with_eyes_twice_as_high():
    heights = []
    for s in (1.0, 2.0):
        env = free_play_v0.parallel_env(n_agents=1, scale=s)
        env.reset(seed=0)
        heights.append(straight_height(env, 0))
    (h1, e1), (h2, e2) = heights
    assert h1 == pytest.approx(0.778, abs=0.004)
    assert h2 / h1 == pytest.approx(2.0, rel=1e-9)
    assert e2 / e1 == pytest.approx(2.0, rel=1e-9)


@pytest.mark.parametrize("strength", [1.0, 1.5])
def test_knee_torque_scales_with_size_to_the_fourth_and_strength(strength):
    env = free_play_v0.parallel_env(n_agents=1, expressions=False, scale=2.0, strength=strength)
    env.reset(seed=0)
    a = env.world.agents[0]
    knee = a.actuated_names.index("right_knee")
    dof = a.dof_adr[a.joint_names.index("right_knee")]
    for u, published in ((1.0, 10.0), (-1.0, -6.5), (0.5, 5.0)):
        action = np.zeros(env.action_space("infant_0").shape, np.float32)
        action[knee] = u
        env.step({"infant_0": action})
        assert env.world.data.qfrc_actuator[dof] == pytest.approx(published * 16 * strength,
                                                                  rel=1e-9)
    assert isinstance(env.actuation[0], SpringDamper)


def test_a_scaled_body_moves_like_the_infant_on_a_time_scale_sqrt_s():
    """Dynamic similarity: a released arm (gravity, joint springs and dampers, no motor) of a
    body 2.25 x as large swings like the infant's, 1.5 x slower."""
    def swing(scale, seconds, dt):
        w = World([AgentSetup(AgentConfig(scale=scale), base="fixed")],
                  physics=PhysicsConfig(timestep=dt), floor=False)
        m, d, a = w.model, w.data, w.agents[0]
        k = [a.qpos_adr[a.joint_names.index(n)] for n in ("right_shoulder_abduction",
                                                            "right_elbow")]
        d.qpos[k] = np.deg2rad([100.0, -30.0])
        mujoco.mj_forward(m, d)
        out = []
        for _ in range(int(round(seconds / dt))):
            mujoco.mj_step(m, d)
            out.append(d.qpos[k].copy())
        return np.rad2deg(out)

    q1 = swing(1.0, 0.6, 0.001)
    q2 = swing(2.25, 0.9, 0.0015)          # the same number of steps, each 1.5 x as long
    assert np.ptp(q1[:, 0]) > 80.0          # the arm falls ~90 degrees
    assert np.abs(q1 - q2).max() < 2.0      # and the large arm falls the same way, slower
    # at the same time (not the same scaled time) the large arm is far behind
    t1, t2 = 299, 199                       # 0.3 s into each run
    assert q2[t2, 0] - q1[t1, 0] > 10.0


# -- touch ---------------------------------------------------------------------------------------
def test_touch_has_the_same_points_at_every_scale_and_feels_the_weight():
    counts, felt = [], []
    for s in (1.0, 2.0):
        env = free_play_v0.parallel_env(n_agents=1, scale=s, posture="lying", expressions=False,
                                        touch={"normal_only": True, "frame": "world"})
        obs, _ = env.reset(seed=0)
        skin = env.system("touch").skins[0]
        counts.append(skin.counts())
        z = zero_actions(env)
        for _ in range(150):
            obs, *_ = env.step(z)
        m, a = env.world.model, env.world.agents[0]
        felt.append(obs["infant_0"]["touch"].sum() / (m.body_subtreemass[a.root_body] * 9.81))
        assert skin.part_spacing.max() < 1.0 * s + 1e-9
    assert counts[0] == counts[1] and sum(counts[0].values()) > 5000
    # lying still, the skin feels the body's weight (8 x heavier at scale 2)
    np.testing.assert_allclose(felt, 1.0, atol=0.02)


@pytest.mark.parametrize("scale", [0.5, 1.8, 2.5])
def test_touch_points_do_not_depend_on_rounding_at_any_scale(scale):
    """Lengths times 1.8 land a few parts of the five-fingered body on a rounding boundary of
    the point layout (e.g. 2 h / s = 2.5 rings): the skin is laid out on the unit body."""
    counts = []
    for s in (1.0, scale):
        env = free_play_v0.parallel_env(n_agents=1, hands="five_fingers", scale=s, touch=True)
        skin = env.system("touch").skins[0]
        counts.append(skin.counts())
        spacing = skin.part_spacing[skin.point_part]
        nearest = skin.nbr_dist[:, 1]                  # distance to each point's neighbour
        ok = np.isfinite(nearest)
        counts.append(float(np.median(nearest[ok] / spacing[ok])))
    assert counts[0] == counts[2]
    assert counts[1] == pytest.approx(counts[3], rel=1e-6)   # the same layout, scaled


# -- worlds with a larger partner ----------------------------------------------------------------
@pytest.mark.parametrize("posture", ["standing", "sitting"])
def test_free_play_with_a_larger_partner_is_stable_and_grounded(posture):
    env = free_play_v0.parallel_env(n_agents=2, posture=posture,
                                     per_agent=[{}, {"scale": 1.8}])
    env.reset(seed=0)
    w = env.world
    m, d = w.model, w.data
    small, big = w.agents
    assert inter_agent_contacts(env) == 0
    lows = [_support_below(m, d, a.geom_ids).min() for a in w.agents]
    np.testing.assert_allclose(lows, 0.002, atol=1e-6)          # both just above the floor
    hip = [d.xpos[a.root_body, 2] for a in w.agents]
    assert (hip[1] - 0.002) / (hip[0] - 0.002) == pytest.approx(1.8, rel=1e-6)
    if posture == "standing":                                     # standing on its feet
        low = _support_below(m, d, big.geom_ids)
        names = [m.geom(int(g)).name for g in big.geom_ids[low < 0.01]]
        assert names and all(("heel" in n or "sole" in n or "ball" in n or "toe" in n)
                             for n in names), names
    z = zero_actions(env)
    for t in range(300):              # 2 s stepping, then 1 s more to settle: the unactuated
        _, _, term, trunc, infos = env.step(z)   # infants slump (a sitting one falls back onto
        assert not any(infos[a]["instability"] for a in infos)  # its hands, at every scale)
        assert not any(term.values())
    assert np.isfinite(d.qpos).all() and np.abs(d.qvel).max() < 1.0  # at rest
    low = _support_below(m, d, big.geom_ids).min()
    assert abs(low) < 0.01                                         # on the floor, not in it
    assert d.xpos[big.root_body, 2] > 0.05


def test_infants_of_three_sizes_start_apart():
    for posture in ("standing", "sitting", "lying"):
        env = free_play_v0.parallel_env(n_agents=3, posture=posture, expressions=False,
                                        per_agent=[{"scale": 2.5}, {}, {"scale": 0.5}])
        env.reset(seed=0)
        assert inter_agent_contacts(env) == 0, posture


def test_five_fingers_muscle_scaled_body_steps_stably():
    s = 1.5
    env = free_play_v0.parallel_env(n_agents=1, hands="five_fingers", actuation="muscle",
                                     scale=s, expressions=False)
    env.reset(seed=3)
    act = env.actuation[0]
    assert isinstance(act, Muscle) and act.n_axes == 88
    ref = Muscle([j for j in load_body("five_fingers").joints if j.actuator], np.zeros(0))
    np.testing.assert_allclose(act.fmax, ref.fmax * s ** 4, rtol=1e-12)
    np.testing.assert_allclose(act.vmax, ref.vmax / np.sqrt(s), rtol=1e-12)
    # the muscles' torque at full activation is the infant's x s^4
    q = np.zeros(88)
    for mine, theirs in zip(act.isometric_torque(q), ref.isometric_torque(q)):
        np.testing.assert_allclose(mine, theirs * s ** 4, rtol=1e-9)
    space = env.action_space("infant_0")
    space.seed(0)
    w = env.world
    start = w.data.xpos[w.agents[0].root_body].copy()
    for _ in range(200):
        _, _, _, _, infos = env.step({"infant_0": space.sample()})
        assert not infos["infant_0"]["instability"]
    assert np.isfinite(w.data.qvel).all() and np.abs(w.data.qvel).max() < 50
    assert _support_below(w.model, w.data, w.agents[0].geom_ids).min() > -0.01
    assert np.linalg.norm(w.data.xpos[w.agents[0].root_body] - start) > 1e-3  # it moved


def test_vision_of_a_scaled_agent_sees_from_its_own_height():
    """A 1.5 x partner looks down at the infant's head and the infant up at the partner's: the
    depth image at each head's projection is the distance to that head."""
    S = 48
    env = free_play_v0.parallel_env(n_agents=2, per_agent=[{}, {"scale": 1.5}],
                                    vision={"width": S, "height": S, "depth": True})
    obs, _ = env.reset(seed=0)
    m, d = env.world.model, env.world.data
    small, big = env.world.agents
    assert d.cam_xpos[big.eye_cameras, 2].min() > d.cam_xpos[small.eye_cameras, 2].max() + 0.2
    for viewer, other, above in ((big, small, False), (small, big, True)):
        cam = viewer.eye_cameras[1]                                  # the left eye
        head = d.geom_xpos[other.head_geom]
        R = d.cam_xmat[cam].reshape(3, 3)
        x, y, z = R.T @ (head - d.cam_xpos[cam])
        f = (S / 2) / np.tan(np.deg2rad(m.cam_fovy[cam]) / 2)
        col, row = S / 2 + f * x / -z, S / 2 - f * y / -z
        assert 0 <= col < S and 0 <= row < S
        assert (row < S / 2) == above                                # up or down in the image
        depth = obs[viewer.name]["depth_left"][int(row), int(col)]
        radius = m.geom_size[other.head_geom, 0]
        assert -z - radius - 0.02 < depth < -z, (viewer.name, depth, -z)
        assert obs[viewer.name]["eye_left"].std() > 5


def test_mixed_bodies_build_and_step():
    env = free_play_v0.parallel_env(
        n_agents=3, max_steps=50,
        per_agent=[{"hands": "mitten", "actuation": "spring_damper",
                    "vision": {"width": 32, "height": 24}},
                   {"hands": "five_fingers", "actuation": "muscle", "touch": True,
                    "vision": {"width": 16, "height": 16}, "scale": 1.3},
                   {"hands": "five_fingers", "actuation": "spring_damper", "scale": 2.2,
                    "strength": 0.6, "expressions": False}])
    obs, _ = env.reset(seed=0)
    sp = {a: env.action_space(a) for a in env.agents}
    assert sp["infant_0"]["motors"].shape == (44,) and sp["infant_0"]["motors"].low.min() == -1
    assert sp["infant_1"]["motors"].shape == (176,) and sp["infant_1"]["motors"].low.min() == 0
    assert sp["infant_2"].shape == (88,)
    assert obs["infant_0"]["eye_left"].shape == (24, 32, 3)
    assert obs["infant_1"]["eye_right"].shape == (16, 16, 3)
    assert "eye_left" not in obs["infant_2"] and "touch" not in obs["infant_0"]
    assert obs["infant_1"]["touch"].size == 3 * env.system("touch").skins[1].n_points
    assert inter_agent_contacts(env) == 0
    knee = env.world.agents[2].actuated_names.index("right_knee")
    assert env.actuation[2].torque_pos[knee] == pytest.approx(10.0 * 2.2 ** 4 * 0.6)
    for k, a in enumerate(env.agents):
        sp[a].seed(k)
    for _ in range(50):
        obs, _, term, trunc, infos = env.step({a: sp[a].sample() for a in env.agents})
        assert not any(infos[a]["instability"] for a in infos)
        for a in obs:
            assert env.observation_space(a).contains(obs[a]), a
    assert all(trunc.values())


def test_scaled_env_pickles_with_its_body():
    env = free_play_v0.parallel_env(n_agents=2, actuation="muscle", expressions=False,
                                     per_agent=[{"scale": 0.7}, {"scale": 2.0, "strength": 2.0}])
    env.reset(seed=1)
    for k, a in enumerate(env.agents):
        env.action_space(a).seed(k)
    for _ in range(5):
        env.step({a: env.action_space(a).sample() for a in env.agents})
    clone = pickle.loads(pickle.dumps(env))
    assert [t.scale for t in clone.world.tables] == [0.7, 2.0]
    np.testing.assert_array_equal(clone.world.model.body_mass, env.world.model.body_mass)
    actions = {a: np.full(env.action_space(a).shape, 0.4, np.float32) for a in env.agents}
    o1, *_ = env.step(actions)
    o2, *_ = clone.step(actions)
    for a in o1:
        np.testing.assert_allclose(o1[a]["proprioception"], o2[a]["proprioception"], atol=1e-9)


# -- bad input -----------------------------------------------------------------------------------
@pytest.mark.parametrize("key, value, allowed", [
    ("scale", 0.3, "0.5 to 2.5"), ("scale", 2.6, "0.5 to 2.5"), ("scale", "big", "0.5 to 2.5"),
    ("scale", float("nan"), "0.5 to 2.5"), ("scale", True, "0.5 to 2.5"),
    ("strength", 0.05, "0.1 to 3"), ("strength", 3.5, "0.1 to 3"),
    ("strength", None, "0.1 to 3")])
def test_out_of_range_scale_and_strength_name_the_allowed_range(key, value, allowed):
    with pytest.raises(ConfigError, match=f"{key}.*{allowed}"):
        AgentConfig(**{key: value})
    with pytest.raises(ConfigError, match=f"infant_1.*{key}.*{allowed}"):
        free_play_v0.parallel_env(n_agents=2, per_agent=[{}, {key: value}])
    with pytest.raises(ValueError, match=allowed):
        load_body("mitten", **{key: value})
