"""The adult caregiver body (``body="adult"``): a 1.65 m, 60 kg woman built from the 18-month
tables with adult proportions (Drillis & Contini 1966 via Winter 2009 Fig. 4.1), mass fractions
(de Leva 1996, female), ranges (AAOS 1965) and torques (body/data/adult_*.csv, README)."""

import math
import pickle

import mujoco
import numpy as np
import pytest

from mimo_social.body import adult
from mimo_social.body.adult import (ADULT_RANGES, ADULT_TORQUES, ANTHROPOMETRY, BODY_MASS,
                                    MASS_FRACTIONS, STATURE, adult_tables, region_ratios)
from mimo_social.body.builder import build_infant
from mimo_social.body.joint_groups import held_posture
from mimo_social.body.postures import posture_joints
from mimo_social.body.tables import load_body, subtree
from mimo_social.core.config import AgentConfig
from mimo_social.core.world import AgentSetup, World, _support_below
from mimo_social.envs import free_play_v0

HANDS = ("mitten", "five_fingers")


def standing_model(hands):
    """The adult compiled alone, every joint at 0 (standing straight), positions computed."""
    m = build_infant(hands, body="adult").spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    return m, d


def heights(m, d):
    """Landmark heights above the soles (m): top of the head, joints (segment origins)."""
    bottom = _support_below(m, d, np.arange(m.ngeom)).min()
    head = m.geom("head").id
    z = {n: d.xpos[m.body(n).id, 2] - bottom
         for n in ("hip", "right_upper_arm", "right_lower_arm", "right_upper_leg",
                   "right_lower_leg", "right_foot", "right_eye")}
    z["top"] = d.geom_xpos[head, 2] + m.geom_size[head, 0] - bottom
    return z


@pytest.mark.parametrize("hands", HANDS)
def test_stature_and_mass_are_the_reference_adults(hands):
    m, d = standing_model(hands)
    assert heights(m, d)["top"] == pytest.approx(STATURE, abs=1e-6)          # 1.65 m
    # de Leva's female fractions sum to 0.9999: 59.994 kg
    assert m.body_subtreemass[m.body("hip").id] == pytest.approx(0.9999 * BODY_MASS, rel=1e-6)
    assert load_body(hands, body="adult").body == "adult"
    assert load_body(hands, body="adult").total_mass == pytest.approx(59.994, rel=1e-6)


@pytest.mark.parametrize("hands", HANDS)
def test_segment_lengths_are_the_published_fractions_of_stature(hands):
    """Within 0.1 % of Drillis & Contini's fractions: shoulder, hip and knee heights, upper arm,
    forearm (elbow to wrist pivot), hand, thigh, foot length; the head circumference is
    Bushby et al.'s. The ankle sits lower than 0.039 H (the foot's height comes with its mass)
    and the shank takes the difference (see body/data/README.md)."""
    m, d = standing_model(hands)
    z, H, a = heights(m, d), STATURE, ANTHROPOMETRY
    t = load_body(hands, body="adult")
    wrist = d.xanchor[m.joint("right_wrist_flexion").id, 2] - (d.xpos[m.body("hip").id, 2]
                                                               - z["hip"])
    fractions = {
        "shoulder_height": z["right_upper_arm"] / H, "hip_height": z["right_upper_leg"] / H,
        "knee_height": z["right_lower_leg"] / H,
        "upper_arm": (z["right_upper_arm"] - z["right_lower_arm"]) / H,
        "forearm": (z["right_lower_arm"] - wrist) / H,
        "thigh": (z["right_upper_leg"] - z["right_lower_leg"]) / H,
        "hand": adult._lengths(t)["hand"] / H, "foot_length": adult._lengths(t)["foot_length"] / H,
    }
    for name, value in fractions.items():
        assert value == pytest.approx(a[name], rel=1e-3), name
    ankle = z["right_foot"] / H
    assert 0.02 < ankle < a["ankle_height"]
    assert (z["right_lower_leg"] - z["right_foot"]) / H == pytest.approx(0.285 - ankle)
    head = next(g for g in t.geoms if g.name == "head")
    assert 2 * math.pi * head.size[0] == pytest.approx(0.552)                  # 55.2 cm


@pytest.mark.parametrize("hands", HANDS)
def test_mass_fractions_are_de_levas(hands):
    """Each limb segment (with the hand's fingers and the foot's toes) has de Leva's female
    fraction of 60 kg within 0.1 %; head and trunk together theirs (the head sphere, sized by
    the head circumference, weighs less than de Leva's head and neck, the trunk the rest)."""
    t = load_body(hands, body="adult")
    mass = {}
    for g in t.geoms:
        mass[g.body] = mass.get(g.body, 0.0) + g.mass
    for group, (segments, fraction) in MASS_FRACTIONS.items():
        if group in ("head", "trunk"):
            continue
        for side in ("right_", "left_"):
            names = []
            for s in segments:
                s = side + s[len("right_"):]
                names += subtree(t, s[:-1]) if s.endswith("+") else [s]
            assert sum(mass[n] for n in names) / BODY_MASS == pytest.approx(fraction, rel=1e-3)
    head_trunk = sum(mass[n] for n in ("head", "right_eye", "left_eye", "hip", "lower_body",
                                       "upper_body"))
    assert head_trunk / BODY_MASS == pytest.approx(0.0668 + 0.4257, rel=1e-3)
    assert 0.045 < (mass["head"] + mass["right_eye"] + mass["left_eye"]) / BODY_MASS < 0.0668


@pytest.mark.parametrize("hands", HANDS)
def test_ranges_and_torques_are_the_data(hands):
    t, infant = load_body(hands, body="adult"), load_body(hands)
    joints = {j.name: j for j in t.joints}
    assert [j.name for j in t.joints] == [j.name for j in infant.joints]
    for name, rng in ADULT_RANGES.items():
        assert joints[name].range_deg == rng
        assert joints[name.replace("right_", "left_")].range_deg == rng
    assert joints["left_knee"].torque_neg == pytest.approx(66.8)       # flexion
    assert joints["right_knee"].torque_pos == pytest.approx(144.6)     # extension
    assert joints["right_elbow"].torque_neg == pytest.approx(40.5)     # flexion
    assert ADULT_TORQUES["right_elbow"] == (40.5, None)
    ratio = region_ratios(infant)
    assert ratio["arm"] == pytest.approx(40.5 / 3.6)
    before = {j.name: j for j in infant.joints}
    for name, j in joints.items():
        if j.gear is None or name.endswith(("knee", "elbow")) or "_eye_" in name:
            continue
        r = ratio["arm" if name.startswith("head") or j.body in subtree(t, "right_upper_arm")
                  or j.body in subtree(t, "left_upper_arm") else "leg"]
        assert j.torque_neg == pytest.approx(before[name].torque_neg * r), name
        assert j.torque_pos == pytest.approx(before[name].torque_pos * r), name
        if j.fmax_neg is not None:   # the muscles in proportion
            assert j.fmax_neg / before[name].fmax_neg == pytest.approx(r), name
    # the eyes keep the volume law: an adult eye (r 12 mm) barely stronger than the infant's
    eye = joints["right_eye_horizontal"].torque_pos / before["right_eye_horizontal"].torque_pos
    assert 1.0 < eye < 1.5


@pytest.mark.parametrize("hands", HANDS)
def test_the_adult_has_the_infants_parts_and_names(hands):
    t, infant = adult_tables(hands), load_body(hands)
    for field in ("segments", "geoms", "joints", "sites"):
        assert [x.name for x in getattr(t, field)] == [x.name for x in getattr(infant, field)]
    assert t.hands == hands and t.scale == 1.0
    assert load_body(hands, body="adult", scale=0.5).standing_height == pytest.approx(0.825)


def test_the_adults_face_shows_every_expression():
    world = World([AgentSetup(AgentConfig()), AgentSetup(AgentConfig(body="adult"),
                                                         position=(1.0, 0.0))])
    for e in range(7):
        world.set_expression(1, e)
        assert world.expression_of(1) == e
    assert world.expression_of(0) == 0


def held_world(body, posture, hands="mitten"):
    frozen = held_posture(load_body(hands, body=body), keep=(),
                          angles=posture_joints(posture, body))
    return World([AgentSetup(AgentConfig(body=body, posture=posture, hands=hands),
                             frozen=frozen)])


@pytest.mark.parametrize("body,posture", [("adult", "standing"), ("adult", "sitting"),
                                          ("adult", "kneeling"), ("infant", "kneeling")])
def test_held_postures_stay_put_for_two_seconds(body, posture):
    """Every joint held: the body rests where the world put it (less than 3 mm of sinking into
    the floor, 0.2 degrees of tilt) and steps 2 s without an instability. Kneeling rests on the
    knees and the toe tips; the adult stands on its soles and sits on its thighs."""
    world = held_world(body, posture)
    m, d = world.model, world.data
    me = world.names[0]   # caregiver_0 for the adult
    hip = m.body(f"{me}/hip").id
    x0, q0 = d.xpos[hip].copy(), d.xquat[hip].copy()
    assert world.step(int(round(2.0 / m.opt.timestep))) is None
    assert np.abs(d.xpos[hip] - x0).max() < 0.003
    tilt = 2 * np.degrees(np.arccos(min(1.0, abs(float(np.dot(q0, d.xquat[hip]))))))
    assert tilt < 0.2
    touching = {m.geom(int(g)).name.split("/")[1] for c in d.contact[:d.ncon]
                for g in (c.geom1, c.geom2) if m.geom(int(g)).name.startswith(f"{me}/")}
    if posture == "kneeling":
        assert touching == {"right_upper_leg", "left_upper_leg", "right_toe_tips",
                            "left_toe_tips"}


def test_an_adult_kneels_face_to_face_with_an_infant_in_free_play():
    """An infant and a kneeling adult build and step 2 s together; the adult's eyes are at
    1.15 m kneeling (0.76 m sitting, 1.58 m standing: docs/bodies.md)."""
    env = free_play_v0.parallel_env(n_agents=2, per_agent=[{}, {"body": "adult",
                                                                "posture": "kneeling"}])
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    eye = d.xpos[m.body("caregiver_0/right_eye").id, 2]
    assert eye == pytest.approx(1.15, abs=0.01)
    zero = {}
    for a in env.agents:
        sp = env.action_space(a)
        zero[a] = {"motors": np.zeros(sp["motors"].shape, np.float32), "expression": 0}
    for _ in range(int(round(2.0 / env.dt))):
        _, _, _, _, infos = env.step(zero)
        assert not any(i["instability"] for i in infos.values())


def test_an_env_with_an_adult_pickles_and_continues_exactly():
    env = free_play_v0.parallel_env(n_agents=2, per_agent=[{}, {"body": "adult",
                                                                "posture": "sitting"}])
    env.reset(seed=0)
    act = {a: {"motors": np.full(env.action_space(a)["motors"].shape, 0.3, np.float32),
               "expression": 2} for a in env.agents}
    for _ in range(5):
        env.step(act)
    copy = pickle.loads(pickle.dumps(env))
    assert copy.world.model.body_subtreemass[copy.world.agents[1].root_body] == \
        pytest.approx(59.994)
    a, b = env.step(act)[0], copy.step(act)[0]
    for agent in a:
        np.testing.assert_array_equal(a[agent]["proprioception"], b[agent]["proprioception"])


def test_the_adult_survives_bang_bang_actions():
    """Every motor at -1 or +1, redrawn each step, in free play (adult and infant): no
    instability in 1000 steps (longer runs: docs/bodies.md)."""
    env = free_play_v0.parallel_env(n_agents=2, hands="five_fingers", max_steps=1000,
                                    per_agent=[{}, {"body": "adult"}])
    env.reset(seed=1)
    rng = np.random.default_rng(1)
    for _ in range(1000):
        acts = {}
        for a in env.agents:
            n = env.action_space(a)["motors"].shape[0]
            acts[a] = {"motors": rng.choice([-1.0, 1.0], n).astype(np.float32),
                       "expression": 0}
        _, _, _, _, infos = env.step(acts)
        assert not any(i["instability"] for i in infos.values())


def figures(hands="mitten"):
    """The adult as built: stature, mass, landmark fractions, group mass fractions, eye heights
    in the held postures (printed by ``python tests/body/test_adult.py``)."""
    m, d = standing_model(hands)
    z, H = heights(m, d), STATURE
    t = load_body(hands, body="adult")
    head = next(g for g in t.geoms if g.name == "head")
    print(f"{hands}: stature {z['top']:.4f} m, mass {t.total_mass:.3f} kg, "
          f"head circumference {2 * math.pi * head.size[0]:.3f} m")
    for name in ("right_upper_arm", "right_lower_arm", "right_upper_leg", "right_lower_leg",
                 "right_foot", "right_eye"):
        print(f"  {name} height {z[name]:.4f} m = {z[name] / H:.4f} H")
    print("  hand, foot, ankle (fractions of H):",
          {k: round(v / H, 4) for k, v in adult._lengths(t).items()})
    mass = {}
    for g in t.geoms:
        mass[g.body] = mass.get(g.body, 0.0) + g.mass
    for group, names in adult._groups(load_body(hands)).items():
        extra = ("right_eye", "left_eye") if group == "head" else ()
        print(f"  {group}: {sum(mass[n] for n in names + list(extra)):.3f} kg = "
              f"{sum(mass[n] for n in names + list(extra)) / BODY_MASS:.4f} "
              f"(de Leva {MASS_FRACTIONS[group][1]})")
    env = free_play_v0.parallel_env(n_agents=2, touch=True, hands=hands,
                                    per_agent=[{}, {"body": "adult"}])
    obs, _ = env.reset(seed=0)
    print(f"  touch points: adult {obs['caregiver_0']['touch'].size}, infant "
          f"{obs['infant_0']['touch'].size}")
    for body, posture in (("adult", "standing"), ("adult", "sitting"), ("adult", "kneeling"),
                          ("infant", "standing"), ("infant", "sitting"), ("infant", "kneeling")):
        world = held_world(body, posture, hands)
        eye = world.model.body(f"{world.names[0]}/right_eye").id
        mujoco.mj_forward(world.model, world.data)
        start = world.data.xpos[eye, 2]
        world.step(int(round(2.0 / world.model.opt.timestep)))
        print(f"  {body} {posture} (held): eyes at {start:.3f} m, after 2 s "
              f"{world.data.xpos[eye, 2]:.3f} m")


def stress(hands="mitten", actuation="spring_damper", strength=1.0, posture="standing",
           steps=5000, body="adult", seed=0):
    """Bang-bang actions for one agent in free play: prints the instabilities (the env resets
    after each) and the fastest hinge (``python tests/body/test_adult.py stress five_fingers
    spring_damper 3 standing 50000``)."""
    env = free_play_v0.parallel_env(n_agents=1, body=body, hands=hands, actuation=actuation,
                                    strength=float(strength), posture=posture,
                                    max_steps=int(steps), info_text=True)   # the reasons
    env.reset(seed=int(seed))
    rng = np.random.default_rng(int(seed))
    m, d = env.world.model, env.world.data
    agent = env.agents[0]
    n = env.action_space(agent)["motors"].shape[0]
    fastest, unstable = np.zeros(m.nv), []
    for t in range(int(steps)):
        u = rng.choice([-1.0, 1.0], n).astype(np.float32)
        _, _, term, trunc, infos = env.step({agent: {"motors": u, "expression": 0}})
        fastest = np.maximum(fastest, np.abs(d.qvel))
        if "instability" in infos[agent]:
            unstable.append((t, infos[agent]["instability"].split(":")[1][:60]))
        if term[agent] or trunc[agent]:
            env.reset(seed=t)
    dof = int(np.argmax(fastest[6:])) + 6
    joint = next(m.joint(j).name for j in range(m.njnt) if m.jnt_dofadr[j] == dof)
    print(f"{body} {hands} {actuation} strength {strength} {posture}: {steps} steps, "
          f"{len(unstable)} instabilities {unstable}; fastest hinge {joint} "
          f"{fastest[dof]:.0f} rad/s")


if __name__ == "__main__":
    import sys

    if sys.argv[1:2] == ["stress"]:
        stress(*sys.argv[2:])
    else:
        figures()
