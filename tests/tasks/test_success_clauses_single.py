"""One test per clause of the success definitions of reach, selfbody, standup and catch (the task
tables' `success` and `termination` rows, issue 30). Each clause below names the test that fails
when the clause is removed from the task's code (checked by mutating a scratch copy of the task,
one clause at a time, when the tests were written); clauses guarded elsewhere name that test.

reach (`Reach.rewards`, `Reach.terminations`)
  R1 a geom of the right hand touches the ball: test_reach.py::
     test_reward_is_minus_the_fingertips_distance_until_the_hand_touches
  R2 no other part counts: test_reach.py::test_the_forearm_on_the_ball_is_no_success
  R3 the episode ends on success, `is_success` says so: test_reach.py::
     test_reward_is_minus_the_fingertips_distance_until_the_hand_touches

selfbody (`SelfBody.rewards`, `SelfBody._contacts`)
  S1 the target's body part feels the infant itself on its skin:
     test_selfbody_the_target_parts_skin_must_feel_the_touch
  S2 the contact is the right hand's (not the forearm's):
     test_selfbody_the_forearm_on_the_target_is_no_success
  S3 on the target primitive (not another primitive of the same part):
     test_selfbody_another_primitive_of_the_target_part_is_no_success
  S4 with a positive normal force: test_selfbody_a_hand_contact_without_force_is_no_success
  S5 the episode ends on success: test_selfbody.py::
     test_touching_the_target_primitive_pays_500_and_ends

standup (`Standup.terminations`)
  T1 the head at least `success_gain` above its settled start height (not the reward's
     reference): test_standup_the_head_must_rise_success_gain_above_its_start
  T2 for `success_hold` (1 s): test_standup.py::test_success_needs_the_head_held_up,
     test_standup_a_break_starts_the_hold_again
  T3 without a break: test_standup_a_break_starts_the_hold_again
  T4 no termination (a fixed 500 steps): test_standup_success_does_not_end_the_episode

catch (`Catch.rewards`, `Catch.terminations`)
  C1 the right hand touches the ball (no other part of the infant):
     test_catch_the_ball_on_the_forearm_is_no_catch
  C2 for `hold_time` (1 s): test_catch.py::
     test_catch_randomises_the_ball_and_pays_one_a_touching_step_and_the_steps_left
  C3 without a break: test_catch_a_break_starts_the_hold_again
  C4 and not dropped: test_catch_a_held_ball_too_far_from_the_palm_centre_is_dropped
  C5 dropped: more than `drop_margin` below the palm centre: test_catch.py::
     test_catch_fails_when_the_ball_drops_below_the_hand
  C6 dropped: more than `max_distance` from the palm centre:
     test_catch_a_ball_far_to_the_side_is_dropped
  C7 the episode ends on success (test_catch.py::
     test_catch_randomises_the_ball_and_pays_one_a_touching_step_and_the_steps_left) and on a
     drop (test_catch.py::test_catch_fails_when_the_ball_drops_below_the_hand)

The selfbody states are physical: seeded random right-arm postures, one zero-action step each,
until the step's contacts show the wanted case. The standup and catch states are set (the body
lifted, the ball put on the hand) and judged by the task's own hooks (`rewards`, then
`terminations`) with nothing moving, so that one clause at a time changes.
"""

import mujoco
import numpy as np

from mimo_social.core.kinematics import hand_geoms
from mimo_social.envs import catch_v0, selfbody_v0, standup_v0
import pytest

pytestmark = pytest.mark.text_infos   # these tests read the text infos (info_text=True)

A = "infant_0"


# -- selfbody ------------------------------------------------------------------------------------
def _selfbody(target, **kwargs):
    env = selfbody_v0.parallel_env(task_options={"target": target}, max_steps=10**6, **kwargs)
    env.reset(seed=0)
    return env


def _arm_search(env, want, tries=3000):
    """Seeded random right-arm postures (the rest of the body as reset), each followed by one
    zero-action step, until ``want(env, info)``; that step's info. Resets after a success."""
    w = env.world
    m, d = w.model, w.data
    a = w.agents[0]
    k = a.actuated_joint_idx
    lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
    rest = d.qpos.copy()
    rng = np.random.default_rng(0)
    for _ in range(tries):
        if not env.agents:
            env.reset(seed=0)
        d.qpos[:] = rest
        d.qvel[:] = 0.0
        d.qpos[a.qpos_adr[k]] = rng.uniform(lo, hi)
        mujoco.mj_forward(m, d)
        _, _, _, _, infos = env.step({A: np.zeros(8, np.float32)})
        if want(env, infos[A]):
            return infos[A]
    raise AssertionError("the wanted posture never came")


def _contacts(env, geoms_a, geom_b):
    """This step's active contacts (distance <= 0) between ``geoms_a`` and ``geom_b``."""
    d = env.world.data
    c = d.contact[:d.ncon]
    on = (np.isin(c.geom1, geoms_a) & (c.geom2 == geom_b)) \
        | (np.isin(c.geom2, geoms_a) & (c.geom1 == geom_b))
    return int(np.sum(on & (c.dist <= 0.0)))


def _felt(env, part):
    return env.system("touch").touched_by(0).get(part, {}).get("self", False)


def _geom(env, name):
    return env.world.model.geom(f"{A}/{name}").id


def test_selfbody_the_target_parts_skin_must_feel_the_touch():
    """S1: the hand pressed on the head: a success; the same with the head's skin left out
    (``touch`` excludes it): the hand presses the target, but the infant cannot feel it."""
    for exclude, success in (((), True), (("head",), False)):
        env = _selfbody("head", touch={"density": 0.25, "normal_only": True,
                                       "exclude": exclude})
        assert env.task.place_hand_on(env, "head") <= 0.0
        _, rew, term, _, infos = env.step({A: np.zeros(8, np.float32)})
        info = infos[A]
        assert "head" in info["touched"] and _felt(env, "head") is success
        assert info["is_success"] is success and bool(term[A]) is success
        assert (rew[A] == 500.0) is success
        env.close()


def test_selfbody_the_forearm_on_the_target_is_no_success():
    """S2: the right forearm pressed on the head, the hand touching nothing: the head feels the
    infant itself, yet it is no success; the hand on the head is."""
    env = _selfbody("head")
    head, forearm = _geom(env, "head"), _geom(env, "right_lower_arm")
    info = _arm_search(env, lambda e, i: _contacts(e, [forearm], head) > 0
                       and not i["touched"] and _felt(e, "head"))
    assert not info["is_success"] and env.agents == [A]
    assert env.task.place_hand_on(env, "head") <= 0.0
    assert env.step({A: np.zeros(8, np.float32)})[4][A]["is_success"]
    env.close()


def test_selfbody_another_primitive_of_the_target_part_is_no_success():
    """S3: the hand pressed on chest_lower only; the target chest_middle is on the same body
    part (upper_body), which feels the touch: no success. The same posture with chest_lower as
    the target is one."""
    env = _selfbody("chest_middle")
    info = _arm_search(env, lambda e, i: i["touched"] == ["chest_lower"])
    assert _felt(env, "upper_body") and env.task.target_part == "upper_body"
    assert not info["is_success"] and env.agents == [A]
    posture = env.world.data.qpos.copy()
    other = _selfbody("chest_lower")
    other.world.data.qpos[:] = posture         # as after that step (the arm moved for 5 ms)
    other.world.data.qvel[:] = 0.0
    mujoco.mj_forward(other.world.model, other.world.data)
    info = other.step({A: np.zeros(8, np.float32)})[4][A]
    assert "chest_lower" in info["touched"] and info["is_success"]
    env.close()
    other.close()


def test_selfbody_a_hand_contact_without_force_is_no_success():
    """S4: the hand in contact with the target (shoulders) with no normal force (the solver
    gives the contact nothing; the hand presses on the chest beside it), while the target's part
    feels the hand's press: not touched, no success."""
    env = _selfbody("shoulders")
    hand = hand_geoms(env.world, 0, 0)
    target = _geom(env, "shoulders")
    info = _arm_search(env, lambda e, i: _contacts(e, hand, target) > 0
                       and "shoulders" not in i["touched"] and _felt(e, "upper_body"))
    assert info["touched"] and not info["is_success"] and env.agents == [A]
    env.close()


# -- standup ---------------------------------------------------------------------------------------
def _standup(**options):
    env = standup_v0.parallel_env(task_options=options)
    env.reset(seed=0)
    return env


def _lifted(env, rest, lift, steps):
    """The body as reset, lifted ``lift`` m (the head with it), judged ``steps`` control steps
    in a row by the task's hooks (nothing moves): each step's info."""
    w = env.world
    out = []
    for _ in range(steps):
        w.data.qpos[:] = rest
        w.data.qpos[w.agents[0].free_qpos + 2] += lift
        w.data.qvel[:] = 0.0
        mujoco.mj_kinematics(w.model, w.data)
        env.task.rewards(env)
        done, infos = env.task.terminations(env)
        out.append(dict(infos[0], done=bool(done[0])))
    return out


def test_standup_the_head_must_rise_success_gain_above_its_start():
    """T1: 0.2 m (success_gain) above the settled start, whatever the reward's reference: the
    head 1 cm short of it for 2 s is no success; 1 cm past it, a success after 1 s."""
    for reference in (0.2, 0.0, None):
        env = _standup(head_reference=reference)
        rest = env.world.data.qpos.copy()
        low = _lifted(env, rest, 0.19, 200)
        assert all(abs(i["head_gain"] - 0.19) < 1e-9 for i in low)
        assert not any(i["is_success"] for i in low)
        high = _lifted(env, rest, 0.21, 100)
        assert not any(i["is_success"] for i in high[:-1]) and high[-1]["is_success"]
        env.close()


def test_standup_a_break_starts_the_hold_again():
    """T2, T3: 99 steps up, 1 step down, 99 steps up: no success (198 steps up in all); the
    100th step up in a row is one."""
    env = _standup()
    rest = env.world.data.qpos.copy()
    steps = _lifted(env, rest, 0.25, 99) + _lifted(env, rest, 0.0, 1)
    steps += _lifted(env, rest, 0.25, 99)
    assert not any(i["is_success"] for i in steps)
    assert _lifted(env, rest, 0.25, 1)[0]["is_success"]
    env.close()


def test_standup_success_does_not_end_the_episode():
    """T4: the head held up keeps the episode going (the reward grows with the head's height:
    standing longer pays); the task ends nothing, only the 500 steps do."""
    env = _standup(success_gain=0.0, success_hold=0.05)
    steps = 0
    while env.agents:
        _, _, term, trunc, infos = env.step({A: np.zeros(27, np.float32)})
        steps += 1
        assert not term[A]
        if steps == 10:
            assert infos[A]["is_success"]
    assert steps == 500 and trunc[A]
    env.close()


# -- catch -----------------------------------------------------------------------------------------
def _catch(**options):
    env = catch_v0.parallel_env(task_options=options)
    env.reset(seed=0)
    return env


def _rest_on(env, geom, direction):
    """Put the ball against ``geom`` from ``direction`` (a unit vector from the geom's centre),
    0.5 mm into it; the qpos then."""
    w = env.world
    m, d = w.model, w.data
    ball = env.task._ball_geom
    start = d.geom_xpos[geom] + 0.1 * np.asarray(direction)
    env.task.place_ball(env, start)
    gap = mujoco.mj_geomDistance(m, d, ball, geom, 1.0, None)
    env.task.place_ball(env, start - (gap + 0.0005) * np.asarray(direction))
    return d.qpos.copy()


def _on_palm(env):
    a = env.world.agents[0]
    palm = env.world.model.site_bodyid[a.palm_sites[0]]
    geom = [g for g in hand_geoms(env.world, 0, 0) if env.world.model.geom_bodyid[g] == palm]
    return _rest_on(env, geom[0], (0.0, 0.0, 1.0))


def _judge(env, qpos, steps):
    """The ball and body at ``qpos``, at rest, judged ``steps`` times by the task's hooks:
    each step's (info, reward, done)."""
    w = env.world
    out = []
    for _ in range(steps):
        w.data.qpos[:] = qpos
        w.data.qvel[:] = 0.0
        mujoco.mj_forward(w.model, w.data)
        r = float(env.task.rewards(env)[0])
        done, infos = env.task.terminations(env)
        out.append((infos[0], r, bool(done[0])))
    return out


def test_catch_the_ball_on_the_palm_is_caught_after_one_second():
    """The positive case the clauses below change: 100 steps on the palm (hold_time 1 s)."""
    env = _catch()
    steps = _judge(env, _on_palm(env), 100)
    assert [i["held_steps"] for i, _, _ in steps] == list(range(1, 101))
    assert not any(i["is_success"] or d for i, _, d in steps[:-1])
    assert steps[-1][0]["is_success"] and steps[-1][2] and not steps[-1][0]["dropped"]
    env.close()


def test_catch_the_ball_on_the_forearm_is_no_catch():
    """C1: the ball lying on the right forearm for 2 s touches the infant (`parts_touching`),
    not its right hand: no hold, no success, no end."""
    env = _catch()
    forearm = env.world.model.geom(f"{A}/right_lower_arm").id
    steps = _judge(env, _rest_on(env, forearm, (0.0, 0.0, 1.0)), 200)
    hand = hand_geoms(env.world, 0, 0)
    d = env.world.data
    c = d.contact[:d.ncon]
    assert not np.any(np.isin(c.geom1, hand) | np.isin(c.geom2, hand))
    for info, r, done in steps:
        assert info["parts_touching"] >= 1 and info["held_steps"] == 0
        assert not info["is_success"] and not info["dropped"] and not done and r <= 1.0
    env.close()


def test_catch_a_break_starts_the_hold_again():
    """C3: 99 steps on the palm, one step with the ball 3 cm above it (in the air, not dropped),
    99 steps on the palm: no success; the 100th in a row is."""
    env = _catch()
    held = _on_palm(env)
    env.task.place_ball(env, env.world.data.xpos[env.task._ball_body] + [0.0, 0.0, 0.03])
    air = env.world.data.qpos.copy()
    steps = _judge(env, held, 99) + _judge(env, air, 1) + _judge(env, held, 99)
    assert steps[99][0]["held_steps"] == 0 and not steps[99][0]["dropped"]
    assert not any(i["is_success"] or d for i, _, d in steps)
    info, _, done = _judge(env, held, 1)[0]
    assert info["is_success"] and done
    env.close()


def test_catch_a_held_ball_too_far_from_the_palm_centre_is_dropped():
    """C4: success needs the ball not dropped: with max_distance 0 (the ball on the palm is
    farther than that from its centre) and hold_time 0 (one step), the held ball is a drop,
    not a catch."""
    env = _catch(max_distance=0.0, hold_time=0.0)
    info, r, done = _judge(env, _on_palm(env), 1)[0]
    assert info["held_steps"] == 1 and info["dropped"] and done
    assert not info["is_success"] and r == -100.0
    env.close()


def test_catch_a_ball_far_to_the_side_is_dropped():
    """C6: the ball 0.6 m to the side of the palm, at its height (not below it): more than
    max_distance (0.5 m) away, a drop: -100 and the end; 0.4 m away it is not."""
    env = _catch()
    palm = env.world.data.site_xpos[env.world.agents[0].palm_sites[0]].copy()
    for side, dropped in ((0.6, True), (0.4, False)):
        env.task.place_ball(env, palm + [0.0, side, 0.0])
        info, r, done = _judge(env, env.world.data.qpos.copy(), 1)[0]
        assert info["dropped"] is dropped and done is dropped and (r == -100.0) is dropped
        assert not info["is_success"]
    env.close()
