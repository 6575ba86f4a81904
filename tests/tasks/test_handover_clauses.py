"""One test per clause of the handover's success definition (the task table's `success` row):
the receiver holds the ball when (1) >= `min_parts` segments of its right hand touch it, (2) its
hand is closed around it (contacts on both sides of the ball's centre along the palm's normal:
one at least `grasp_height` radii past the centre, away from the palm, one on the palm's side),
(3) the giver's hand does not touch it and (4) it is above `drop_height`; success is (5) that
hold kept without a break for `hold_time`. Each test fails when its clause is removed from
`Handover.rewards` (checked by hand when the tests were written, issue 30).

The states are recorded from physical episodes (the scripted receiver's hold, the open never-
closing palm, a giver that never lets go) and then judged by the task's own hooks
(`rewards` then `terminations`) with the state held still, so that one clause at a time is
changed: an option, the giver's arm, the whole receiver lowered, the ball on the back of the
hand."""

import mujoco
import numpy as np
import pytest

from mimo_social.envs import handover_v0
from mimo_social.partners.hand_offer import HandOffer
from mimo_social.tasks.handover import OFFER_TARGET, OpenPalm, ReceiveController
from mimo_social.tasks.handover.controller import ARM, hand_frame, palm_posture
from test_receive_controller import episode  # this folder is on the path (rootdir-less tests)

pytestmark = pytest.mark.text_infos   # these tests read the text infos (info_text=True)

HOLD = 30                       # hold_time 0.3 s at the default control step (0.01 s)


def _record(receiver, seed, want, giver=None):
    """Run ``receiver`` against the scripted giver (or ``giver``) until ``want(info, verdict)``
    (the step's info, and the verdict on its state held still: see :func:`_judge`); the state
    (qpos) then."""
    env = handover_v0.scripted_env(giver, task_options={"end_on_success": False}, max_steps=600)
    env.reset(seed=seed)
    inner = env.unwrapped
    receiver.reset(inner, "infant_0", None)
    judge = _env()
    for _ in range(600):
        _, _, term, _, infos = env.step({"infant_0": receiver.act(inner, "infant_0", None)})
        qpos = inner.world.data.qpos.copy()
        _put(judge, qpos)
        if want(infos["infant_0"], _judge(judge, 1)[0]):
            return qpos
        assert not term["infant_0"]
    raise AssertionError(f"seed {seed}: the wanted state never came")


@pytest.fixture(scope="module")
def held():
    """The scripted receiver's hold (seed 1000), 40 steps into it: closed, the giver gone."""
    return _record(ReceiveController(), 1000,
                   lambda i, v: i["held_steps"] >= 40 and v["holder"] == "receiver")


@pytest.fixture(scope="module")
def open_palm():
    """The ball resting on the open palm and the thumb (OpenPalm, seed 1006, 1.9 s in): two
    segments, the giver's hand off it, the fingers never closed."""
    return _record(OpenPalm(), 1006, lambda i, v: i["time"] > 1.9 and v["receiver_parts"] >= 2
                   and v["holder"] != "giver")


@pytest.fixture(scope="module")
def shared():
    """The receiver's fingers closed on the ball while the giver, which never lets go here
    (``hold_time`` 5 s), still touches it (seed 1001)."""
    giver = HandOffer(target=OFFER_TARGET, grip=True, release="on_hold", hold_time=5.0)
    return _record(ReceiveController(), 1001, lambda i, v: v["holder"] == "giver"
                   and v["receiver_parts"] >= 4, giver)


def _env(task_options=None):
    env = handover_v0.parallel_env(task_options=task_options or {})
    env.reset(seed=0)
    return env


def _put(env, qpos, edit=None):
    w = env.world
    w.data.qpos[:] = qpos
    w.data.qvel[:] = 0.0
    if edit is not None:
        edit(env)
    mujoco.mj_forward(w.model, w.data)


def _judge(env, steps=2 * HOLD):
    """The task's verdict on the world as it is, ``steps`` control steps in a row (nothing
    moves): the receiver's info each step."""
    out = []
    for _ in range(steps):
        env.task.rewards(env)
        done, infos = env.task.terminations(env)
        assert done[0] == done[1]
        out.append(dict(infos[0], done=bool(done[0])))
    return out


def _arm(world, i):
    a = world.agents[i]
    return a.qpos_adr[[a.joint_names.index(n) for n in ARM]]


def test_success_needs_the_hold_for_hold_time(held):
    """Clause 5: success after exactly hold_time (0.3 s = 30 steps), not before."""
    env = _env()
    _put(env, held)
    infos = _judge(env, HOLD)
    assert [i["held_steps"] for i in infos] == list(range(1, HOLD + 1))
    assert all(i["holder"] == "receiver" for i in infos)
    assert not any(i["is_success"] or i["done"] for i in infos[:-1])
    assert infos[-1]["is_success"] and infos[-1]["done"]
    env = _env({"hold_time": 0.5})
    _put(env, held)
    infos = _judge(env, 50)
    assert not any(i["is_success"] for i in infos[:-1]) and infos[-1]["is_success"]


def test_a_break_in_the_hold_starts_the_count_again(held, open_palm):
    """Clause 5, 'without a break': 29 held steps, one step not held (the open palm), 29 held
    steps again: no success; the 30th in a row is."""
    env = _env()
    _put(env, held)
    assert not any(i["is_success"] for i in _judge(env, HOLD - 1))
    _put(env, open_palm)
    gap = _judge(env, 1)[0]
    assert gap["holder"] == "none" and gap["held_steps"] == 0
    _put(env, held)
    infos = _judge(env, HOLD)
    assert not any(i["is_success"] for i in infos[:-1]) and infos[-1]["is_success"]


def test_the_giver_still_touching_the_ball_is_no_hold(shared):
    """Clause 3: the receiver's closed hand on the ball while the giver's hand touches it is
    the giver's ball: no hold, no success; the same state with the giver's arm moved away (its
    hand off the ball) is a success after hold_time."""
    env = _env()
    _put(env, shared)
    infos = _judge(env)
    assert all(i["holder"] == "giver" and i["held_steps"] == 0 for i in infos)
    assert all(i["receiver_parts"] >= 4 for i in infos)
    assert not any(i["is_success"] or i["done"] for i in infos)

    def giver_away(e):
        e.world.data.qpos[_arm(e.world, 1)] = 0.0              # the arm hangs, far from it

    _put(env, shared, giver_away)
    infos = _judge(env, HOLD)
    assert all(i["holder"] == "receiver" for i in infos) and infos[-1]["is_success"]


def test_a_ball_below_drop_height_is_not_held(held):
    """Clause 4: the same hold with the whole receiver (and the ball in its hand) 0.3 m lower,
    the ball then below drop_height (0.25 m): dropped, not held, no success, the episode ends.
    Unlowered, the state is a hold."""
    env = _env()
    w = env.world
    ball = w.prop_bodies["ball"]

    def lower(e):
        root = e.world.agents[0].root_body
        e.world.model.body_pos[root, 2] -= 0.3
        e.world.data.qpos[e.world.prop_qpos["ball"] + 2] -= 0.3

    _put(env, held, lower)
    assert w.data.xpos[ball][2] < 0.25
    infos = _judge(env)
    assert all(i["dropped"] and i["done"] for i in infos)
    assert all(i["receiver_parts"] >= 2 for i in infos)           # still in the hand
    assert all(i["holder"] == "none" and i["held_steps"] == 0 for i in infos)
    assert not any(i["is_success"] for i in infos)
    env = _env()
    _put(env, held)
    assert env.world.data.xpos[ball][2] > 0.25
    assert _judge(env, 1)[0]["holder"] == "receiver"


def test_fewer_segments_than_min_parts_is_no_hold(held):
    """Clause 1: the hold touches the ball with n segments; with min_parts n + 1 it is no hold,
    with min_parts n a success after hold_time."""
    env = _env()
    _put(env, held)
    n = _judge(env, 1)[0]["receiver_parts"]
    assert n >= 2
    env = _env({"min_parts": n + 1})
    _put(env, held)
    infos = _judge(env)
    assert all(i["holder"] == "none" and i["held_steps"] == 0 for i in infos)
    assert not any(i["is_success"] for i in infos)
    env = _env({"min_parts": n})
    _put(env, held)
    assert _judge(env, HOLD)[-1]["is_success"]


def test_an_open_palm_that_never_closes_is_no_hold(open_palm):
    """Clause 2: the ball resting on the open palm and the thumb (two segments, the giver's
    hand off it) is no hold; with grasp_height -1 (any contact counts as past the centre: the
    closure clause relaxed to the definition before issue 30) the same state is a success."""
    env = _env()
    _put(env, open_palm)
    infos = _judge(env)
    assert all(i["receiver_parts"] >= 2 and not i["dropped"] for i in infos)
    assert all(i["holder"] == "none" and i["held_steps"] == 0 for i in infos)
    assert not any(i["is_success"] for i in infos)
    env = _env({"grasp_height": -1.0})
    _put(env, open_palm)
    assert _judge(env, HOLD)[-1]["is_success"]


def test_fingers_not_far_enough_over_the_ball_are_no_hold(held):
    """Clause 2's height: the scripted hold's fingers reach up to ~0.3 radii past the ball's
    centre; asking for 0.9 radii makes it no hold."""
    env = _env({"grasp_height": 0.9})
    _put(env, held)
    infos = _judge(env)
    assert all(i["receiver_parts"] >= 2 and i["holder"] == "none" for i in infos)
    assert not any(i["is_success"] for i in infos)


def test_a_ball_on_the_back_of_the_hand_is_no_hold():
    """Clause 2's palm side: the ball lying on the back of the palm-down hand and its fingers
    (every contact past the ball's centre, none on the palm's side) is no hold."""
    env = _env()
    w = env.world
    m, d = w.model, w.data
    a = w.agents[0]
    shoulder = d.xpos[m.body("infant_0/right_upper_arm").id].copy()
    down = hand_frame((0.0, 0.0, -1.0), (1.0, 0.0, 0.0))
    q, res, _ = palm_posture(w, 0, shoulder + (0.15, 0.0, -0.10), down,
                             start=np.deg2rad([60.0, 20.0, -60.0, -60.0, -80.0, 0.0, 0.0]))
    assert res < 1e-3
    d.qpos[_arm(w, 0)] = q
    fingers = [k for k, n in enumerate(a.joint_names)
               if n.split("_")[1:2] in (["index"], ["middle"], ["ring"], ["little"])]
    d.qpos[a.qpos_adr[fingers]] = 0.0                          # straight fingers
    mujoco.mj_kinematics(m, d)
    site = a.palm_sites[0]
    R = d.xmat[m.site_bodyid[site]].reshape(3, 3)              # palm normal -y: down here
    bq = w.prop_qpos["ball"]
    for lift in np.arange(0.06, 0.0, -0.001):                  # lower it onto the back
        d.qpos[bq:bq + 3] = d.site_xpos[site] + lift * R[:, 1] + 0.03 * R[:, 2]
        d.qpos[bq + 3:bq + 7] = (1.0, 0.0, 0.0, 0.0)
        mujoco.mj_forward(m, d)
        if _judge(env, 1)[0]["receiver_parts"] >= 2:
            break
    infos = _judge(env)
    assert all(i["receiver_parts"] >= 2 and not i["dropped"] for i in infos)
    assert all(i["holder"] == "none" and i["held_steps"] == 0 for i in infos)
    assert not any(i["is_success"] for i in infos)


def test_the_givers_own_grasp_is_not_the_receivers():
    """The ball in the giver's closed hand at reset (the receiver's hand away) is the giver's:
    no receiver segments, no hold."""
    env = _env()
    infos = _judge(env)
    assert all(i["holder"] == "giver" and i["receiver_parts"] == 0 for i in infos)
    assert not any(i["is_success"] for i in infos)


@pytest.mark.parametrize("seed", [1006, 1008])
def test_the_open_never_closing_palm_does_not_succeed(seed):
    """The hack of the issue (an open cupped palm held out, never closing: it succeeded under
    the earlier definition, on these two seeds too) fails a whole episode and returns less
    than the scripted receiver on the same seed (30 episodes: the task table's baselines)."""
    ok, dropped, steps, ret, info = episode(OpenPalm(), seed)
    assert not ok
    scripted = episode(ReceiveController(), seed)
    assert scripted[0] and ret < scripted[3] - 5.0
