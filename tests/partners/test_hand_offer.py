"""The HandOffer scripted partner: it brings its hand out, holds it, grips and releases."""

import mujoco
import numpy as np
import pytest

from mimo_social.envs import handover_v0, high_five_v0
from mimo_social.partners import zero_action
from mimo_social.core.kinematics import hand_geoms
from mimo_social.tasks.handover import OFFER_TARGET, scripted_giver
from mimo_social.partners.hand_offer import HandOffer, offer_posture
from mimo_social.tasks.handover.controller import ReceiveController, hand_frame, palm_posture
from mimo_social.tasks.reach.controller import ReachController


def handover_text(*args, **kwargs):
    """The handover's scripted env with text infos (the holder by name)."""
    return handover_v0.scripted_env(*args, info_text=True, **kwargs)


def _palm(env, i=1):
    w = env.unwrapped.world
    return w.data.site_xpos[w.agents[i].palm_sites[0]].copy()


@pytest.mark.parametrize("hands", ["mitten", "five_fingers"])
@pytest.mark.parametrize("actuation", ["spring_damper", "muscle"])
def test_hand_reaches_the_offer_position_within_a_second(hands, actuation):
    partner = HandOffer(grip=False, release=None)
    env = high_five_v0.scripted_env(partner, hands=hands, actuation=actuation,
                                    task_options={"end_on_touch": False})
    env.reset(seed=0)
    start = _palm(env)
    assert np.linalg.norm(start - partner.target_position) > 0.1   # the arm starts hanging
    idle = {"infant_0": zero_action(env.action_space("infant_0"))}
    for _ in range(100):                                            # 1 s at 100 Hz
        env.step(idle)
    assert np.linalg.norm(_palm(env) - partner.target_position) < 0.03
    for _ in range(50):                                             # and it stays there
        env.step(idle)
    assert np.linalg.norm(_palm(env) - partner.target_position) < 0.02


@pytest.mark.parametrize("palm, normal, cos", [("up", (0, 0, 1), 0.99),
                                               ("forward", (-1, 0, 0), 0.85)])
def test_target_is_solved_relative_to_the_shoulder_with_the_palm_turned(palm, normal, cos):
    env = high_five_v0.parallel_env(hands="five_fingers", expressions=False)
    env.reset(seed=0)
    w = env.world
    m, d = w.model, w.data
    a = w.agents[1]                       # faces -x: forward is -x, left is -y
    target = (0.15, 0.05, -0.06)
    posture = offer_posture(w, 1, None, target, palm=palm, palm_tilt=(0.0, 0.0))
    d2 = mujoco.MjData(m)
    d2.qpos[:] = d.qpos
    for n, v in posture.items():
        d2.qpos[a.qpos_adr[a.joint_names.index(n)]] = v
    mujoco.mj_kinematics(m, d2)
    shoulder = d2.xpos[m.body("infant_1/right_upper_arm").id]
    np.testing.assert_allclose(d2.site_xpos[a.palm_sites[0]] - shoulder, (-0.15, -0.05, -0.06),
                               atol=2e-3)
    hand = m.site_bodyid[a.palm_sites[0]]
    # the palm's normal (forward: within about 30 deg, as far as the wrist's range allows)
    assert -d2.xmat[hand].reshape(3, 3)[:, 1] @ normal > cos


def _take_touch(env):
    """Put the receiver's right hand against the ball from the receiver's side: the hand moves
    toward the ball in 5 mm steps (joint angles set by IK) until it first touches it."""
    inner = env.unwrapped
    w = inner.world
    m, d = w.model, w.data
    a = w.agents[0]
    ball = d.xpos[w.prop_bodies["ball"]].copy()
    shoulder = d.xpos[m.body("infant_0/right_upper_arm").id].copy()
    hand = np.zeros(m.ngeom, bool)
    hand[hand_geoms(w, 0)] = True
    ball_geom = m.body_geomadr[w.prop_bodies["ball"]]
    for back in np.arange(0.09, 0.02, -0.005):
        rel = ball - np.array([back, 0.0, 0.0]) - shoulder    # infant_0 faces +x
        posture = offer_posture(w, 0, None, tuple(rel), palm="posture")
        for n, v in posture.items():
            d.qpos[a.qpos_adr[a.joint_names.index(n)]] = v
        mujoco.mj_forward(m, d)
        if any(ball_geom in (c.geom1, c.geom2) and (hand[c.geom1] or hand[c.geom2])
               for c in d.contact[:d.ncon]):
            return
    raise AssertionError("the receiver's hand never reached the ball")


def _finger_flexion(env):
    w = env.unwrapped.world
    a = w.agents[1]
    k = [a.joint_names.index(f"right_{f}_{j}") for f in ("index", "middle", "ring")
         for j in ("mcp", "pip")]
    return float(np.mean(w.data.qpos[a.qpos_adr[k]]))


@pytest.mark.parametrize("delay", [0.0, 0.2])
def test_fingers_open_after_the_partners_touch(delay):
    partner = HandOffer(target=OFFER_TARGET, release="on_touch", release_delay=delay)
    env = handover_text(partner, task_options={"end_on_success": False})
    env.reset(seed=0)
    closed = _finger_flexion(env)
    assert closed > np.deg2rad(30)                     # the grasp: fingers curled on the ball
    _take_touch(env)
    idle = {"infant_0": zero_action(env.action_space("infant_0"))}
    env.step(idle)
    assert partner.touched_at is not None
    assert partner.released == (delay == 0.0)
    for _ in range(int(round(delay / 0.01)) + 1):
        env.step(idle)
    assert partner.released
    for _ in range(40):
        env.step(idle)
    assert _finger_flexion(env) < closed - np.deg2rad(20)   # opened


def test_no_touch_no_release_and_the_ball_stays_held():
    partner = HandOffer(target=OFFER_TARGET, release="on_touch")
    env = handover_text(partner)
    env.reset(seed=0)
    closed = _finger_flexion(env)
    idle = {"infant_0": zero_action(env.action_space("infant_0"))}
    for _ in range(100):
        _, _, term, _, infos = env.step(idle)
    assert not partner.released and partner.touched_at is None
    assert abs(_finger_flexion(env) - closed) < np.deg2rad(10)
    assert infos["infant_0"]["holder"] == "giver" and not term["infant_0"]


def test_without_release_the_grip_is_kept_after_a_touch():
    partner = HandOffer(target=OFFER_TARGET, release=None)
    env = handover_text(partner)
    env.reset(seed=0)
    _take_touch(env)
    env.step({"infant_0": zero_action(env.action_space("infant_0"))})
    assert not partner.released


def test_partner_acts_only_through_its_action_space():
    env = handover_v0.parallel_env(per_agent=[{}, {"actuation": "muscle", "expressions": True}])
    partner = HandOffer()
    env.reset(seed=0)
    partner.reset(env, "infant_1", np.random.default_rng(0))
    action = partner.act(env, "infant_1", None)
    assert env.action_space("infant_1").contains(action)
    assert action["motors"].shape == (58,)


@pytest.mark.parametrize("kwargs, pattern", [
    ({"release": "later"}, r"release='later'.*None, 'on_touch', 'on_hold'"),
    ({"hold_parts": 0}, r"hold_parts=0.*integer from 1 to 16"),
    ({"hold_parts": 2.5}, r"hold_parts=2.5"),
    ({"hold_load": -0.1}, r"hold_load=-0.1.*from 0 to 2"),
    ({"hold_time": "soon"}, r"hold_time='soon'"),
    ({"present": 3}, r"present=3.*from 0 to 2"),
    ({"ready_radius": 0}, r"ready_radius=0"),
    ({"palm_tilt": (0.1,)}, r"palm_tilt=.*two numbers"),
    ({"withdraw": (0.0, 0.5)}, r"withdraw=.*two numbers from 0 to 0.2"),
    ({"grip": "yes"}, r"grip='yes'.*True or False"),
    ({"release_delay": -1}, r"release_delay=-1.*from 0 to 60"),
    ({"target": (1.0, 0.0, 0.0)}, r"target=.*within 0.5 m"),
    ({"target": "front"}, r"target='front'"),
    ({"posture": {"right_knee": 10}}, r"posture joints \['right_knee'\] unknown"),
    ({"grip_strength": 2.0}, r"grip_strength=2.0.*from 0 to 1"),
    ({"frequency": 0}, r"frequency=0"),
    ({"palm": "down"}, r"palm='down'.*'up', 'forward', 'posture'"),
    ({"palm": "forward", "pour": 1.0}, r"pour=1.0 needs palm='up'"),
])
def test_bad_options_raise_clear_errors(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        HandOffer(**kwargs)


def test_unknown_prop_or_missing_arm_motors_are_reported():
    env = high_five_v0.scripted_env(HandOffer(prop="cube"))
    with pytest.raises(ValueError, match=r"prop 'cube' is not in this env"):
        env.reset(seed=0)
    from mimo_social.envs import catch_v0
    env = catch_v0.parallel_env()                        # catch moves only wrist and fingers
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"does not actuate \['right_shoulder_horizontal'"):
        HandOffer(release=None).reset(env, "infant_0", np.random.default_rng(0))


def test_pour_tips_the_palm_toward_the_fingers_after_release():
    normals = {}
    for pour in (0.0, 1.0):
        partner = HandOffer(target=OFFER_TARGET, release="on_touch", pour=pour,
                            withdraw=(0.0, 0.0))
        env = handover_text(partner, task_options={"end_on_success": False,
                                                              "drop_height": 0.0})
        env.reset(seed=0)
        _take_touch(env)
        idle = {"infant_0": zero_action(env.action_space("infant_0"))}
        for _ in range(60):
            env.step(idle)
        assert partner.released
        w = env.unwrapped.world
        hand = w.model.site_bodyid[w.agents[1].palm_sites[0]]
        R = w.data.xmat[hand].reshape(3, 3)
        normals[pour] = -R[:, 1]                  # the palm's normal
    n0, n1 = normals[0.0], normals[1.0]
    assert n0[2] > 0.95                             # without pour the palm stays up
    assert n1[2] < n0[2] - 0.1                      # with pour it tips ...
    assert n1[0] < n0[0] - 0.2                      # ... over the fingertips, toward infant_0 (-x)


# -- release="on_hold": the giver lets go only once the receiver's hand carries the ball ----------

class _Hold(HandOffer):
    """A receiver that holds its right arm in the posture that puts the palm centre at a point
    (relative to the ball) with a given palm normal and finger direction, fingers straight."""

    def __init__(self, offset, normal, fingers=(1.0, 0.0, 0.0), point=False):
        super().__init__(grip=False, release=None, palm="posture")
        self.offset, self.normal, self.fingers, self.point = offset, normal, fingers, point

    def reset(self, env, agent, rng):
        w = env.world
        ball = w.data.xpos[w.prop_bodies["ball"]]
        start = np.deg2rad([60.0, 20.0, -60.0, -60.0, -80.0, 0.0, 0.0])
        q, res, err = palm_posture(w, 0, ball + np.asarray(self.offset),
                                   hand_frame(self.normal, self.fingers), start=start)
        assert res < 0.002 and err < 0.01
        self.posture_deg = {**self.posture_deg,
                            **dict(zip(self.posture_deg, np.rad2deg(q)))}
        a = w.agents[0]                       # put the arm there at once; the PD then holds it
        w.data.qpos[a.qpos_adr[[a.joint_names.index(n) for n in self.posture_deg]]] = q
        names = list(a.actuated_names)
        curled = [k for k, n in enumerate(names) if self.point and n.split("_")[-1] in
                  ("mcp", "pip", "dip", "ip") and not n.startswith("right_index")]
        if curled:                            # pointing: every finger but the index curled
            k = a.actuated_joint_idx[curled]
            w.data.qpos[a.qpos_adr[k]] = np.minimum(np.deg2rad(90.0), a.joint_range[k, 1])
        mujoco.mj_forward(w.model, w.data)
        super().reset(env, agent, rng)
        self.target_angles = self.target_angles.copy()
        self.target_angles[curled] = w.data.qpos[self._qadr[curled]]


def _handover(receiver, steps, seed=0, **task):
    giver = scripted_giver()
    env = handover_text(giver, task_options={"end_on_success": False, **task})
    env.reset(seed=seed)
    inner = env.unwrapped
    receiver.reset(inner, "infant_0", np.random.default_rng(seed))
    infos = []
    for _ in range(steps):
        _, _, term, _, info = env.step({"infant_0": receiver.act(inner, "infant_0", None)})
        infos.append({**info["infant_0"], "tip": giver.tip, "released": giver.released})
        if term["infant_0"]:
            break
    return env, giver, infos


def test_the_giver_keeps_the_ball_on_the_back_of_a_hand_or_a_one_finger_poke():
    # the back of the receiver's hand laid on the ball (palm up above it), then held just over
    # it for 1.5 s
    env, giver, infos = _handover(_Hold((0.0, 0.0, 0.028), (0.0, 0.0, 1.0), (1.0, 1.0, 0.0)),
                                  150)
    assert infos[0]["receiver_parts"] >= 1                           # the back touched it
    assert giver.tip == 0.0 and not giver.released and giver.touched_at is None
    assert infos[-1]["holder"] == "giver" and not infos[-1]["dropped"]
    # the receiver's index finger (the others curled) pressed on the ball from the side for 2 s
    f = np.array([1.0, 0.5, 0.0]) / np.linalg.norm([1.0, 0.5, 0.0])
    poke = _Hold(-0.06 * f + np.array([0.0, 0.0, 0.03]), (-f[1], f[0], 0.0), (f[0], f[1], -0.5),
                 point=True)
    env, giver, infos = _handover(poke, 200)
    touched = [i["receiver_parts"] for i in infos]
    assert max(touched) >= 1 and sum(t > 0 for t in touched) > 100     # it kept touching
    assert giver.tip == 0.0 and not giver.released and giver.touched_at is None
    assert infos[-1]["holder"] == "giver" and not infos[-1]["dropped"]
    # reaching for the ball with the fingertips (the reach controller, into the ball) for 3 s
    env, giver, infos = _handover(ReachController(depth=0.02), 300)
    assert not giver.released and infos[-1]["holder"] == "giver"


def test_an_open_hand_held_out_gets_the_ball_and_only_then_the_giver_lets_go():
    receiver = ReceiveController()
    env, giver, infos = _handover(receiver, 400, seed=1000)
    w = env.unwrapped.world
    assert giver.released and giver.touched_at is not None
    release = next(k for k, i in enumerate(infos) if i["released"])
    # the giver presented (tipped) its palm before letting go, and let go only after the
    # receiver's hand had held the ball (>= 2 segments touching) for the hold time (0.2 s)
    assert infos[release - 1]["tip"] > 0.5
    assert all(i["receiver_parts"] >= 2 for i in infos[release - 20:release])
    # afterwards the ball stays in the receiver's hand, the giver's fingers open, its hand down
    last = infos[-1]
    assert last["holder"] == "receiver" and not last["dropped"] and last["receiver_parts"] >= 2
    palm = w.data.site_xpos[w.agents[1].palm_sites[0]]
    assert palm[2] < giver.target_position[2] - 0.02                  # lowered
    assert _finger_flexion(env) < np.deg2rad(25)


def test_the_tip_needs_the_open_hand_held_there():
    # an open hand beside the giver's for 0.1 s only: no tip; held on: the palm tips
    receiver = _Hold((0.01, -0.055, -0.047), (-0.3, -0.1, 1.0))
    giver = scripted_giver()
    env = handover_text(giver)
    env.reset(seed=0)
    inner = env.unwrapped
    receiver.reset(inner, "infant_0", None)
    for _ in range(10):
        env.step({"infant_0": receiver.act(inner, "infant_0", None)})
    assert giver.open_hand_ready(inner.world.data) and giver.tip == 0.0
    for _ in range(60):
        env.step({"infant_0": receiver.act(inner, "infant_0", None)})
    assert giver.tip > 0.3
