"""The scripted receiver of the handover (ReceiveController): it takes the ball from the scripted
giver through its own motors; random, zero-action and hack receivers do not, and score less."""

import mujoco
import numpy as np
import pytest

from mimo_social.envs import handover_v0
from mimo_social.partners import zero_action
from mimo_social.tasks.reach.controller import ReachController
from mimo_social.tasks.handover.controller import (ARM, CupAndLeave, OpenPalm, ReceiveController,
                                                      hand_frame, palm_posture)
from mimo_social.tasks.handover import HandoverOptions, scripted_giver

pytestmark = pytest.mark.text_infos   # these tests read the text infos (info_text=True)

SEEDS = range(1000, 1030)


def _env(task_options=None, **kwargs):
    opts = HandoverOptions(**(task_options or {}))
    return handover_v0.scripted_env(scripted_giver(opts), task_options=task_options or {},
                                    **kwargs)


def episode(policy, seed, env=None, extra_steps=0):
    """One episode of the receiver ``policy`` ("zero", "random" or a Partner); returns
    (success, dropped, steps, return, last info)."""
    env = env or _env()
    inner = env.unwrapped
    env.reset(seed=seed)
    space = env.action_space("infant_0")
    if policy == "random":
        space.seed(seed)
    elif policy != "zero":
        policy.reset(inner, "infant_0", np.random.default_rng(seed))
    total, steps = 0.0, 0
    while True:
        if policy == "zero":
            action = zero_action(space)
        elif policy == "random":
            action = space.sample()
        else:
            action = policy.act(inner, "infant_0", None)
        _, rew, term, trunc, infos = env.step({"infant_0": action})
        total += rew["infant_0"]
        steps += 1
        info = infos["infant_0"]
        if term["infant_0"] or trunc["infant_0"]:
            return info["is_success"], info["dropped"], steps, total, info


@pytest.mark.parametrize("seed", [1000, 1001])
def test_the_scripted_receiver_takes_the_ball(seed):
    ok, dropped, steps, ret, info = episode(ReceiveController(), seed)
    assert ok and not dropped and info["holder"] == "receiver"
    assert steps < 400                                          # within 4 s
    assert ret > 9.0                                            # success 10 + the approach


def test_the_received_ball_stays_in_the_receivers_hand():
    env = _env({"end_on_success": False}, max_steps=450)
    receiver = ReceiveController()
    env.reset(seed=1000)
    inner = env.unwrapped
    receiver.reset(inner, "infant_0", None)
    infos = []
    for _ in range(450):
        _, _, term, _, info = env.step({"infant_0": receiver.act(inner, "infant_0", None)})
        infos.append(info["infant_0"])
        assert not term["infant_0"]
    first = next(k for k, i in enumerate(infos) if i["is_success"])
    assert len(infos) - first > 150                             # watched > 1.5 s after success
    assert all(i["holder"] == "receiver" and i["receiver_parts"] >= 2 for i in infos[first:])
    assert env.partners["infant_1"].released
    w = inner.world
    palm = w.data.site_xpos[w.agents[0].palm_sites[0]]
    assert np.linalg.norm(w.data.xpos[w.prop_bodies["ball"]] - palm) < 0.05   # in the palm


def test_the_scripted_receiver_works_with_muscles():
    env = _env(per_agent=[{"actuation": "muscle"}, {}])
    ok, dropped, *_ = episode(ReceiveController(), 1002, env)
    assert ok and not dropped


@pytest.mark.parametrize("offer", [None, (0.17, 0.12, -0.06), (0.19, 0.08, -0.10)])
def test_the_receiving_hand_is_within_the_receivers_reach(offer):
    """Inverse kinematics of the receiver's right arm: the cup posture (palm up beside the
    giver's hand) is reached within 1 mm and 0.01 rad, for the default offer and offers 2 cm
    off it; the ball is about 20 cm from the receiver's right shoulder."""
    opts = {} if offer is None else {"offer_target": offer}
    env = _env(opts)
    env.reset(seed=0)
    inner = env.unwrapped
    receiver = ReceiveController()
    receiver.reset(inner, "infant_0", None)
    w = inner.world
    start = np.deg2rad([60.0, 20.0, -60.0, -60.0, -80.0, 0.0, 0.0])
    _, res, err = palm_posture(w, 0, receiver._cup_point(w.data), receiver._frame, start=start)
    assert res < 1e-3 and err < 0.01
    shoulder = w.data.xpos[w.model.body("infant_0/right_upper_arm").id]
    ball = w.data.xpos[w.prop_bodies["ball"]]
    assert 0.17 < np.linalg.norm(ball - shoulder) < 0.23
    if offer is None:
        assert np.linalg.norm(ball - shoulder) == pytest.approx(0.201, abs=0.002)


def test_palm_posture_and_hand_frame():
    frame = hand_frame((0.0, 0.0, 1.0), (1.0, 0.0, 0.3))
    np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(-frame[:, 1], (0.0, 0.0, 1.0))          # the palm faces up
    np.testing.assert_allclose(frame[:, 2], (1.0, 0.0, 0.0), atol=1e-12)
    env = _env()
    env.reset(seed=0)
    w = env.unwrapped.world
    a = w.agents[0]
    shoulder = w.data.xpos[w.model.body("infant_0/right_upper_arm").id]
    goal = shoulder + np.array([0.15, 0.0, -0.12])
    q, res, err = palm_posture(w, 0, goal, frame,
                               start=np.deg2rad([60.0, 20.0, -60.0, -60.0, -80.0, 0.0, 0.0]))
    d = mujoco.MjData(w.model)
    d.qpos[:] = w.data.qpos
    d.qpos[a.qpos_adr[[a.joint_names.index(n) for n in ARM]]] = q
    mujoco.mj_kinematics(w.model, d)
    assert np.linalg.norm(d.site_xpos[a.palm_sites[0]] - goal) == pytest.approx(res, abs=1e-9)
    assert res < 1e-3 and err < 0.01


def test_the_controller_acts_only_through_the_action_space():
    env = _env(per_agent=[{"actuation": "muscle", "expressions": True}, {}])
    env.reset(seed=0)
    inner = env.unwrapped
    receiver = ReceiveController()
    receiver.reset(inner, "infant_0", np.random.default_rng(0))
    d = inner.world.data
    before = (d.qpos.copy(), d.qvel.copy(), d.ctrl.copy())
    action = receiver.act(inner, "infant_0", None)
    assert env.action_space("infant_0").contains(action)
    assert action["motors"].shape == (58,)
    for a, b in zip(before, (d.qpos, d.qvel, d.ctrl)):
        np.testing.assert_array_equal(a, b)                      # it wrote nothing


@pytest.mark.parametrize("policy", ["zero", "random"])
def test_zero_and_random_receivers_fail(policy):
    for seed in (1000, 1001):
        ok, *_ = episode(policy, seed)
        assert not ok


def test_hacks_score_less_than_the_scripted_receiver():
    scripted = episode(ReceiveController(), 1000)[3]
    touch = episode(ReachController(depth=0.02), 1000)           # fingertips into the ball
    leave = episode(CupAndLeave(), 1000)                         # take the shaping, leave
    cupped = episode(OpenPalm(cup_deg=(20.0, 20.0, 10.0)), 1000)  # the ball rests, never closed
    zero = episode("zero", 1000)[3]
    assert not touch[0] and touch[3] < scripted - 5.0
    assert not leave[0] and leave[1] and leave[3] < zero - 5.0   # a drop: worse than idling
    assert not cupped[0] and cupped[3] < scripted - 5.0


@pytest.mark.parametrize("kwargs, pattern", [
    ({"offset": (0.0, 0.0)}, r"offset=.*three numbers"),
    ({"lean": (0.3,)}, r"lean=.*toward the wrist, toward the thumb"),
    ({"cup_deg": (10, 10, 100)}, r"cup_deg=.*from 0 to 90"),
    ({"grip": 2}, r"grip=2.*from 0 to 1"),
    ({"frequency": 0}, r"frequency=0"),
    ({"below": -1}, r"below=-1"),
    ({"prop": ""}, r"prop=''"),
])
def test_bad_options_raise_clear_errors(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        ReceiveController(**kwargs)


def test_missing_motors_or_prop_are_reported():
    from mimo_social.envs import catch_v0
    env = catch_v0.parallel_env()                           # catch moves only wrist and fingers
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"ReceiveController: infant_0 does not actuate"):
        ReceiveController().reset(env, "infant_0", None)
    env = _env()
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"prop 'cube' is not in this env"):
        ReceiveController(prop="cube").reset(env.unwrapped, "infant_0", None)


@pytest.mark.slow
def test_thirty_episodes_scripted_random_zero_and_hacks():
    """The baselines row of the handover table (seeds 1000-1029, scripted giver)."""
    policies = {"scripted": ReceiveController, "zero": lambda: "zero",
                "random": lambda: "random", "touch": lambda: ReachController(depth=0.02),
                "cup_and_leave": CupAndLeave, "open_palm": OpenPalm,
                "open_palm_curled": lambda: OpenPalm(cup_deg=(20.0, 20.0, 10.0))}
    n = len(SEEDS)
    rows = {}
    for name, make in policies.items():
        res = [episode(make(), seed) for seed in SEEDS]
        ret = np.array([r[3] for r in res])
        wins = [r[2] for r in res if r[0]]
        rows[name] = (sum(r[0] for r in res), ret.mean(), ret.std(), sum(r[1] for r in res),
                      np.mean(wins) if wins else float("nan"))
        print(f"{name}: success {rows[name][0]} / {n}, return {ret.mean():.2f} +- {ret.std():.2f}"
              f", drops {rows[name][3]}, steps to success {rows[name][4]:.0f}")
    assert rows["scripted"][0] >= 0.8 * n                       # >= 80 %
    for name in policies:
        if name != "scripted":
            assert rows[name][0] <= 0.15 * n                    # <= 15 %
            assert rows[name][1] < rows["scripted"][1]
    assert rows["cup_and_leave"][1] < rows["zero"][1]           # dropping: worse than idling
