"""The positional actuation model: target joint angles tracked by a torque-limited servo."""

import dataclasses
import pickle

import mujoco
import numpy as np
import pytest

import mimo_social  # noqa: F401  (headless GL before mujoco renders)
from mimo_social.body.actuation import MODELS, Positional, positional_controls
from mimo_social.body.actuation import positional as P
from mimo_social.body.postures import POSTURES
from mimo_social.core.env import MimoParallelEnv
from mimo_social.envs import free_play_v0
from mimo_social.tasks.free_play import FreePlay


class FixedFreePlay(FreePlay):
    """Free play with the hip held in the air (a fixed base)."""

    def setup(self, i, config):
        return dataclasses.replace(super().setup(i, config), base="fixed")


def positional_env(posture="sitting", hands="mitten", fixed=False, **kw):
    settings = dict(actuation="positional", posture=posture, hands=hands, expressions=False, **kw)
    if fixed:
        return MimoParallelEnv(FixedFreePlay(1), max_steps=10**6, **settings)
    return free_play_v0.parallel_env(n_agents=1, max_steps=10**6, **settings)


def joint_errors_deg(env, u):
    """|q - q*| (deg) of every motor of agent 0 for controls ``u``."""
    act, m, d = env.actuation[0], env.world.model, env.world.data
    qadr = m.jnt_qposadr[m.actuator_trnid[act.actuator_ids, 0]]
    return np.rad2deg(np.abs(d.qpos[qadr] - act.targets(u)))


def step_checked(env, u, steps):
    """Step agent 0 (``infant_0``, or ``caregiver_0`` for an adult) with ``u``; the servo
    torques stay within the limits at every step."""
    act, d = env.actuation[0], env.world.data
    agent = env.possible_agents[0]
    for _ in range(steps):
        _, _, _, _, infos = env.step({agent: u})
        assert not infos[agent]["instability"], infos[agent]["instability"]
        f = d.actuator_force[act.actuator_ids]
        assert np.all(f <= act.torque_pos + 1e-9) and np.all(f >= -act.torque_neg - 1e-9)
    return infos[agent]


# -- the mapping and the servo ---------------------------------------------------------------------
def test_controls_are_targets_on_the_joint_range_and_the_motors_become_servos():
    assert MODELS["positional"] is Positional
    env = positional_env()
    env.reset(seed=0)
    act, m, d = env.actuation[0], env.world.model, env.world.data
    box = env.action_space("infant_0")
    assert box.shape == (44,) and box.low.min() == -1 and box.high.max() == 1
    lo = np.deg2rad([j.range_deg[0] for j in act.joints])
    hi = np.deg2rad([j.range_deg[1] for j in act.joints])
    np.testing.assert_allclose(act.targets(-np.ones(44)), lo)
    np.testing.assert_allclose(act.targets(np.ones(44)), hi)
    np.testing.assert_allclose(act.targets(np.zeros(44)), 0.5 * (lo + hi))
    ids = act.actuator_ids
    jnt = m.actuator_trnid[ids, 0]
    assert np.all(m.actuator_biastype[ids] == mujoco.mjtBias.mjBIAS_AFFINE)
    np.testing.assert_allclose(m.actuator_gainprm[ids, 0], act.kp)
    k_s = m.jnt_stiffness[jnt]
    np.testing.assert_allclose(m.actuator_biasprm[ids, 1], k_s - act.kp)   # the spring cancelled
    np.testing.assert_allclose(m.actuator_biasprm[ids, 2], -act.kv)
    np.testing.assert_allclose(m.actuator_ctrlrange[ids], np.stack([lo, hi], 1))
    np.testing.assert_allclose(m.actuator_forcerange[ids],
                               np.stack([-act.torque_neg, act.torque_pos], 1))
    # gains: kp = min(T_mean / 0.1 rad, (0.4 / h)^2 I), kv critical
    inertia = 1 / m.dof_invweight0[m.jnt_dofadr[jnt]]
    t_mean = 0.5 * (act.torque_neg + act.torque_pos)
    np.testing.assert_allclose(act.kp, np.minimum(t_mean / 0.1, (0.4 / 0.005) ** 2 * inertia))
    np.testing.assert_allclose(act.kv, 2 * np.sqrt(act.kp * inertia))
    # reset holds the pose the agent is in: the targets are its angles, not mid-range
    np.testing.assert_allclose(d.ctrl[ids], d.qpos[m.jnt_qposadr[jnt]], atol=1e-12)


@pytest.mark.parametrize("hands, body", [("mitten", {}), ("five_fingers", {}),
                                         ("mitten", {"age_months": 0}),
                                         ("mitten", {"body": "adult"})])
def test_servo_stays_within_the_stability_bound_of_the_timestep(hands, body):
    """Each joint alone: w h <= 0.4; the whole body (M^-1 K of every servo at once, free base):
    below 0.83, the bound of critical damping with an explicit spring and damper."""
    env = positional_env("sitting", hands, **body)
    env.reset(seed=0)
    act, m, d = env.actuation[0], env.world.model, env.world.data
    dof = m.jnt_dofadr[m.actuator_trnid[act.actuator_ids, 0]]
    h = m.opt.timestep
    assert np.all(np.sqrt(act.kp * m.dof_invweight0[dof]) * h <= P.OMEGA_DT + 1e-12)
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    s = np.zeros(m.nv)
    s[dof] = np.sqrt(act.kp)
    lam = np.linalg.eigvalsh(s[:, None] * np.linalg.inv(M) * s[None, :]).max()
    # measured 0.50 sitting (0.53 standing, lying) at 18 months, 0.58 newborn, 0.43 adult
    assert np.sqrt(lam) * h < 0.7


# -- holding and moving ----------------------------------------------------------------------------
@pytest.mark.parametrize("hands", ["mitten", "five_fingers"])
def test_holds_a_sitting_pose_under_gravity_with_a_free_base(hands):
    env = positional_env("sitting", hands)
    env.reset(seed=0)
    u = positional_controls(env, "infant_0", "sitting")
    step_checked(env, u, 200)                       # 2 s
    err = joint_errors_deg(env, u)
    assert err.max() < 2.5 and err.mean() < 0.4     # measured 1.53 / 0.20 (mitten), 1.55 / 0.13


def test_holds_a_standing_pose_with_a_fixed_base_and_moves_to_another():
    env = positional_env("standing", fixed=True)
    env.reset(seed=0)
    u = positional_controls(env, 0, "standing")
    step_checked(env, u, 200)
    err = joint_errors_deg(env, u)
    assert err.max() < 1.0 and err.mean() < 0.15    # measured 0.44 / 0.07
    pose = dict(POSTURES["standing"]["joints"], right_shoulder_abduction=60,
                left_shoulder_abduction=60, right_elbow=-60, left_elbow=-60, head_swivel=30,
                lower_trunk_twist=10, right_hip_flexion=-30, left_hip_flexion=-30,
                right_knee=-40, left_knee=-40)
    v = positional_controls(env, 0, pose, degrees=True)
    moved = np.abs(v - u) > 1e-9
    assert moved.sum() == 10
    step_checked(env, v, 30)                        # 0.3 s
    err = joint_errors_deg(env, v)
    assert err[moved].max() < 3.0                   # measured within 2 deg after 0.18 s
    step_checked(env, v, 170)
    err = joint_errors_deg(env, v)
    assert err.max() < 1.5 and err.mean() < 0.3     # measured 0.85 / 0.18 at 2 s


@pytest.mark.parametrize("posture, fixed, body, max_deg, mean_deg", [
    ("sitting", False, {"age_months": 0}, 10.0, 1.0),    # measured 7.97 (fingers on the floor) / 0.62
    ("sitting", False, {"age_months": 6}, 4.5, 0.6),     # 3.10 / 0.36
    ("sitting", False, {"age_months": 24}, 2.0, 0.3),    # 1.26 / 0.18
    ("standing", True, {"age_months": 0}, 1.0, 0.15),    # 0.66 / 0.09
    ("sitting", False, {"body": "adult"}, 1.5, 0.25),    # 0.78 / 0.12
    ("standing", True, {"body": "adult"}, 0.6, 0.1),     # 0.28 / 0.05
])
def test_every_age_and_the_adult_hold_a_pose(posture, fixed, body, max_deg, mean_deg):
    env = positional_env(posture, fixed=fixed, **body)
    env.reset(seed=0)
    u = positional_controls(env, 0, posture)        # the body's own variant of the posture
    step_checked(env, u, 200)
    err = joint_errors_deg(env, u)
    assert err.max() < max_deg and err.mean() < mean_deg


def test_scaled_weaker_body_holds_within_a_larger_error():
    env = positional_env("sitting", scale=1.5, strength=0.5)
    env.reset(seed=0)
    u = positional_controls(env, 0, "sitting")
    step_checked(env, u, 200)
    err = joint_errors_deg(env, u)
    assert err.max() < 6.0 and err.mean() < 1.0


@pytest.mark.parametrize("hands, body", [("mitten", {}), ("five_fingers", {}),
                                         ("mitten", {"age_months": 0}),
                                         ("mitten", {"body": "adult"})])
def test_bang_bang_targets_stay_stable_and_within_the_torque_limits(hands, body):
    env = positional_env("standing", hands, **body)
    env.reset(seed=0)
    n = env.actuation[0].n_controls
    rng = np.random.default_rng(0)
    for _ in range(20):                             # 2000 steps, new targets every step
        for _ in range(100):
            step_checked(env, rng.choice([-1.0, 1.0], n).astype(np.float32), 1)


# -- per agent, observation, costs, pickling ------------------------------------------------------
def test_mixed_world_leaves_the_spring_damper_agent_as_it_was():
    env = free_play_v0.parallel_env(n_agents=2, expressions=False, posture="sitting",
                                    per_agent=[{"actuation": "spring_damper"},
                                               {"actuation": "positional"}])
    m = env.world.model
    fields = ("actuator_gainprm", "actuator_biasprm", "actuator_biastype", "actuator_ctrlrange",
              "actuator_forcerange", "jnt_stiffness", "dof_damping", "qpos_spring")
    before = {f: getattr(m, f).copy() for f in fields}
    env.reset(seed=0)
    sd, pos = env.actuation
    u = positional_controls(env, "infant_1", "sitting")
    env.step({"infant_0": np.zeros(44, np.float32), "infant_1": u})
    mine = pos.actuator_ids
    for f in fields:
        after = getattr(m, f)
        other = np.ones(len(after), bool)
        if f.startswith("actuator"):
            other[mine] = False
            assert not np.array_equal(after[mine], before[f][mine]) or f == "actuator_forcerange"
        np.testing.assert_array_equal(after[other], before[f][other], err_msg=f)
    with pytest.raises(ValueError, match="infant_0.*actuation='positional'"):
        positional_controls(env, "infant_0", "sitting")


def test_observation_is_targets_and_servo_torques_and_costs_are_relative_torques():
    env = positional_env("sitting")
    env.reset(seed=0)
    act, d = env.actuation[0], env.world.data
    u = positional_controls(env, 0, "lying")
    obs, _, _, _, infos = env.step({"infant_0": u})
    prop = obs["infant_0"]["proprioception"]
    sl = env.senses[0][0].slices["actuation"]
    tau = d.actuator_force[act.actuator_ids]
    np.testing.assert_allclose(prop[sl], np.concatenate([u, tau]), rtol=1e-6, atol=1e-7)
    space = env.observation_space("infant_0")["proprioception"]
    assert space.contains(prop)
    np.testing.assert_allclose(space.high[sl][44:], act.torque_pos, rtol=1e-6)
    t = np.where(tau >= 0, act.torque_pos, act.torque_neg)
    v = tau / t
    assert infos["infant_0"]["cost"] == pytest.approx(float(v @ v) / 44)
    assert infos["infant_0"]["weighted_cost"] == pytest.approx(
        float((v * v) @ t) / (44 * t.sum()))
    assert 0 < infos["infant_0"]["cost"] <= 1


def test_pose_helper_names_what_is_wrong():
    env = positional_env("sitting")
    env.reset(seed=0)
    act = env.actuation[0]
    u = positional_controls(env, 0, {"right_elbow": -1.0})
    k = act.control_names.index("right_elbow")
    assert act.targets(u)[k] == pytest.approx(-1.0, abs=1e-6)
    others = np.arange(44) != k                     # the rest: the spring reference angles
    np.testing.assert_allclose(act.targets(u)[others],
                               np.deg2rad([j.springref_deg for j in act.joints])[others],
                               atol=1e-6)   # float32 controls
    assert positional_controls(env, 0, {"right_elbow": -999.0}, degrees=True)[k] == -1.0
    with pytest.raises(ValueError, match="infant_0.*'right_elbo'.*not joints"):
        positional_controls(env, 0, {"right_elbo": 0.0})
    with pytest.raises(ValueError, match="infant_0.*right_elbow.*finite"):
        positional_controls(env, 0, {"right_elbow": float("nan")})
    with pytest.raises(ValueError, match="infant_0.*posture 'crouching'.*allowed"):
        positional_controls(env, 0, "crouching")
    with pytest.raises(ValueError, match="agent='infant_7'"):
        positional_controls(env, "infant_7", "sitting")


def test_pickled_copy_continues_identically():
    env = positional_env("sitting")
    env.reset(seed=0)
    rng = np.random.default_rng(1)
    for _ in range(5):
        env.step({"infant_0": rng.uniform(-1, 1, 44).astype(np.float32)})
    clone = pickle.loads(pickle.dumps(env))
    assert np.array_equal(clone.world.model.actuator_biasprm, env.world.model.actuator_biasprm)
    for _ in range(20):
        u = {"infant_0": rng.uniform(-1, 1, 44).astype(np.float32)}
        o1, _, _, _, i1 = env.step(u)
        o2, _, _, _, i2 = clone.step(u)
        np.testing.assert_array_equal(o1["infant_0"]["proprioception"],
                                      o2["infant_0"]["proprioception"])
        assert i1["infant_0"]["cost"] == i2["infant_0"]["cost"]
    np.testing.assert_array_equal(env.world.data.qpos, clone.world.data.qpos)


# -- the figures of docs/bodies.md: `python tests/body/test_positional.py` ------------------------
def step_response(joint, to_deg, hands="mitten"):
    """One joint of a fixed-base standing infant stepped to ``to_deg``, the rest held, control
    every physics step (5 ms): rise time (10-90 %), overshoot (% of the step), the time after
    which it stays within 2 deg, the error (deg) at 1 s, and the step (deg)."""
    env = positional_env("standing", hands, fixed=True, physics={"frame_skip": 1})
    env.reset(seed=0)
    act, m, d = env.actuation[0], env.world.model, env.world.data
    step_checked(env, positional_controls(env, 0, "standing"), 100)
    k = act.control_names.index(joint)
    q_adr = m.jnt_qposadr[m.actuator_trnid[act.actuator_ids[k], 0]]
    start = d.qpos[q_adr]
    v = positional_controls(env, 0, dict(POSTURES["standing"]["joints"], **{joint: to_deg}),
                            degrees=True)
    goal = act.targets(v)[k]
    trace = []
    for _ in range(200):                                            # 1 s
        step_checked(env, v, 1)
        trace.append(d.qpos[q_adr])
    trace = np.array(trace)
    x = (trace - start) / (goal - start)
    t = env.dt * np.arange(1, len(x) + 1)
    rise = t[np.argmax(x >= 0.9)] - t[np.argmax(x >= 0.1)]
    err = np.rad2deg(np.abs(trace - goal))
    outside = np.flatnonzero(err > 2.0)
    settle = t[outside[-1] + 1] if len(outside) else 0.0
    return rise, 100 * max(0.0, x.max() - 1), settle, err[-1], np.rad2deg(goal - start)


def report():
    for posture, hands, fixed in (("sitting", "mitten", False), ("sitting", "five_fingers", False),
                                  ("standing", "mitten", True), ("lying", "mitten", False)):
        env = positional_env(posture, hands, fixed=fixed)
        env.reset(seed=0)
        u = positional_controls(env, 0, posture)
        info = step_checked(env, u, 200)
        err = joint_errors_deg(env, u)
        worst = env.actuation[0].control_names[int(err.argmax())]
        print(f"hold {posture:8s} {hands:12s} {'fixed' if fixed else 'free '} base, 2 s: max "
              f"{err.max():.2f} deg ({worst}), mean {err.mean():.2f} deg, cost {info['cost']:.4f}")
    for posture, body, fixed in (("sitting", {"age_months": 0}, False),
                                 ("sitting", {"age_months": 0, "hands": "five_fingers"}, False),
                                 ("sitting", {"age_months": 6}, False),
                                 ("sitting", {"age_months": 12}, False),
                                 ("sitting", {"age_months": 24}, False),
                                 ("standing", {"age_months": 0}, True),
                                 ("sitting", {"body": "adult"}, False),
                                 ("kneeling", {"body": "adult"}, False),
                                 ("standing", {"body": "adult"}, True)):
        env = positional_env(posture, fixed=fixed, **body)
        env.reset(seed=0)
        u = positional_controls(env, 0, posture)
        step_checked(env, u, 200)
        err = joint_errors_deg(env, u)
        worst = env.actuation[0].control_names[int(err.argmax())]
        print(f"hold {posture:8s} {body} {'fixed' if fixed else 'free'} base, 2 s: max "
              f"{err.max():.2f} deg ({worst}), mean {err.mean():.2f} deg")
    for joint, to in (("right_elbow", -90), ("right_shoulder_abduction", 90), ("right_knee", -60),
                      ("head_swivel", 45), ("right_wrist_flexion", 45), ("right_fingers", -120)):
        rise, over, settle, final, size = step_response(joint, to)
        print(f"step {joint:25s} {size:+6.1f} deg: rise {1000 * rise:4.0f} ms, overshoot "
              f"{over:4.1f} %, within 2 deg after {1000 * settle:5.0f} ms, error at 1 s {final:.2f} deg")


if __name__ == "__main__":
    report()
