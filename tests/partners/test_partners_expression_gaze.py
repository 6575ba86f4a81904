"""The scripted partners ExpressionShow and GazeAtTarget do what they say."""

import numpy as np
import pytest

from mimo_social.envs import joint_attention_v0, mirror_v0
from mimo_social.expressions.faces import EXPRESSIONS
from mimo_social.partners import Partner, ScriptedPartners
from mimo_social.partners.expression import ExpressionShow
from mimo_social.partners.gaze import GazeAtTarget, look_angles

NO_MOTORS = np.zeros(0, np.float32)
LEARNER_MIRROR = {"motors": NO_MOTORS, "expression": np.int64(0)}
STILL_HEAD = np.zeros(9, np.float32)


class Recording(Partner):
    """Passes a partner's actions through and keeps them."""

    def __init__(self, inner):
        self.inner, self.actions = inner, []

    def reset(self, env, agent, rng):
        self.inner.reset(env, agent, rng)

    def act(self, env, agent, observation):
        a = self.inner.act(env, agent, observation)
        self.actions.append(a)
        return a


def _runs(seq):
    """Lengths and values of the runs of equal consecutive values."""
    values, lengths = [seq[0]], [1]
    for v in seq[1:]:
        if v == values[-1]:
            lengths[-1] += 1
        else:
            values.append(v)
            lengths.append(1)
    return values, lengths


# -- ExpressionShow ----------------------------------------------------------------------------
def _show(seed, steps=300, **kwargs):
    partner = Recording(ExpressionShow(**kwargs))
    env = mirror_v0.scripted_env(partner, vision=False, max_steps=1000)
    env.reset(seed=seed)
    shown, world = [], []
    for _ in range(steps):
        env.step({"infant_0": LEARNER_MIRROR})
        shown.append(partner.inner.current)
        world.append(env.unwrapped.world.expression_of(1))
    return partner, shown, world


def test_expression_show_holds_each_face_for_hold_s_and_never_repeats():
    partner, shown, world = _show(0, steps=600, hold_s=(0.1, 0.2))
    assert shown == world  # what it says it shows is the face on its head
    values, lengths = _runs(shown)
    assert len(values) >= 30
    # inner runs: 10 to 20 steps of 10 ms (a repeated face would make a run longer than 20)
    assert all(10 <= n <= 20 for n in lengths[1:-1]), lengths
    assert len(set(lengths[1:-1])) > 3  # random times, not one fixed period
    assert set(values) == set(range(len(EXPRESSIONS)))
    for a in partner.actions:  # motors at rest, face from the action space
        assert a["motors"].shape == (0,)
        assert 0 <= int(a["expression"]) < len(EXPRESSIONS)


def test_expression_show_default_hold_in_a_plain_scripted_partners_wrapper():
    partner = Recording(ExpressionShow())
    env = ScriptedPartners(mirror_v0.parallel_env(vision=False, max_steps=1000),
                           {"infant_1": partner})
    env.reset(seed=1)
    seq = []
    for _ in range(600):
        env.step({"infant_0": LEARNER_MIRROR})
        seq.append(partner.inner.current)
    values, lengths = _runs(seq)
    assert all(100 <= n <= 200 for n in lengths[1:-1]), lengths
    assert len(values) >= 3


def test_expression_show_subset_alternates_and_is_seeded():
    _, shown, _ = _show(3, hold_s=(0.05, 0.05), expressions=["happy", "sad"])
    values, lengths = _runs(shown)
    assert set(values) == {EXPRESSIONS.index("happy"), EXPRESSIONS.index("sad")}
    assert all(n == 5 for n in lengths[1:-1])
    a = _show(7, steps=200, hold_s=(0.05, 0.3))[1]
    assert a == _show(7, steps=200, hold_s=(0.05, 0.3))[1]
    assert a != _show(8, steps=200, hold_s=(0.05, 0.3))[1]


@pytest.mark.parametrize("kwargs, match", [
    ({"hold_s": (2.0, 1.0)}, "hold_s"), ({"hold_s": (0.0, 1.0)}, "hold_s"),
    ({"hold_s": "long"}, "hold_s"), ({"expressions": ["happy"]}, "at least 2"),
    ({"expressions": ["grumpy", "sad"]}, "unknown expression 'grumpy'"),
    ({"expressions": [0, 9]}, "unknown expression 9"),
])
def test_expression_show_bad_input(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ExpressionShow(**kwargs)


def test_expression_show_needs_an_expression_action():
    env = ScriptedPartners(joint_attention_v0.parallel_env(vision=False),
                           {"infant_1": ExpressionShow()})
    with pytest.raises(ValueError, match="expressions=True"):
        env.reset(seed=0)


# -- GazeAtTarget ------------------------------------------------------------------------------
def _partner_error_deg(env, toy):
    inner = env.unwrapped
    angle, _ = inner.task._rays.angles(inner.world.data)
    return float(np.rad2deg(angle[1, toy]))


def _swivel(env, agent=1):
    a = env.unwrapped.world.agents[agent]
    k = a.joint_names.index("head_swivel")
    return float(np.rad2deg(env.unwrapped.world.data.qpos[a.qpos_adr[k]]))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_gaze_at_target_looks_at_its_toy_after_one_second(seed):
    partner = GazeAtTarget(hold_s=(30.0, 30.0), head_share=1.0)
    env = joint_attention_v0.scripted_env(partner, vision=False)
    env.reset(seed=seed)
    start = _swivel(env)
    swivels = [start]
    for _ in range(100):
        _, _, _, _, info = env.step({"infant_0": STILL_HEAD})
        swivels.append(_swivel(env))
    assert _partner_error_deg(env, partner.target) < 2.0
    assert info["infant_0"]["target"] == partner.target
    # the head turns a lot (its turn is what the learner can see) ...
    assert abs(swivels[-1] - start) > 20.0
    wanted = look_angles(env.unwrapped, "infant_1", "body",
                         int(env.unwrapped.task.toy_bodies[partner.target]))
    assert abs(np.deg2rad(swivels[-1]) - wanted["head_swivel"]) < np.deg2rad(3.0)
    # ... and physically, through its motors: no jump from one step to the next
    assert np.max(np.abs(np.diff(swivels))) < 6.0


@pytest.mark.parametrize("share", [0.0, 0.3])
def test_gaze_at_target_turns_mostly_its_eyes_with_a_small_head_share(share):
    """The head makes ``share`` of the turn (more where the eyes cannot reach), the eyes the
    rest; the gaze lands on the toy all the same."""
    for seed in (0, 1, 2):
        partner = GazeAtTarget(hold_s=(30.0, 30.0), head_share=share)
        env = joint_attention_v0.scripted_env(partner, vision=False)
        env.reset(seed=seed)
        for _ in range(100):
            _, _, _, _, info = env.step({"infant_0": STILL_HEAD})
        assert _partner_error_deg(env, partner.target) < 3.0
        assert info["infant_0"]["target"] == partner.target
        full = np.rad2deg(look_angles(env.unwrapped, "infant_1", "body", int(
            env.unwrapped.task.toy_bodies[partner.target]))["head_swivel"])
        turned = _swivel(env)
        assert np.sign(turned) == np.sign(full)
        assert share * abs(full) - 3.0 < abs(turned) < abs(full) - 10.0, (seed, turned, full)
        a = env.unwrapped.world.agents[1]
        eye = np.rad2deg(env.unwrapped.world.data.qpos[
            a.qpos_adr[a.joint_names.index("right_eye_horizontal")]])
        assert abs(eye) > 10.0                                   # the eyes make the rest


def test_gaze_at_target_takes_the_tasks_head_share_range_per_shift():
    partner = GazeAtTarget(hold_s=(0.3, 0.3))
    env = joint_attention_v0.scripted_env(partner, vision=False, task_options={
        "partner_head_share": 0.4, "partner_head_jitter": 0.2})
    env.reset(seed=3)
    assert env.unwrapped.task.partner_head_share == pytest.approx((0.2, 0.6))
    shares = {partner.share}
    for _ in range(300):
        env.step({"infant_0": STILL_HEAD})
        shares.add(partner.share)
    assert len(shares) >= 5 and 0.2 <= min(shares) and max(shares) <= 0.6
    own = GazeAtTarget(head_share=(0.9, 1.0))
    env = joint_attention_v0.scripted_env(own, vision=False)
    env.reset(seed=3)
    assert 0.9 <= own.share <= 1.0


def test_gaze_at_target_switches_targets_at_random_times():
    partner = GazeAtTarget(hold_s=(0.6, 0.9))
    env = joint_attention_v0.scripted_env(partner, vision=False, max_steps=1000)
    env.reset(seed=4)
    targets, errors = [], []
    for _ in range(600):
        env.step({"infant_0": STILL_HEAD})
        targets.append(partner.target)
        errors.append(_partner_error_deg(env, partner.target))
    values, lengths = _runs(targets)
    assert len(values) >= 6
    assert all(60 <= n <= 90 for n in lengths[1:-1]), lengths
    assert len(set(values)) >= 3
    # it reaches each target: at the end of each hold its gaze is on the toy
    ends = np.cumsum(lengths)[:-1] - 1
    assert all(errors[e] < 3.0 for e in ends), [errors[e] for e in ends]


def test_gaze_at_target_named_targets_and_seed():
    partner = GazeAtTarget(targets=["toy_1", "infant_0/head"], hold_s=(30.0, 30.0))
    env = joint_attention_v0.scripted_env(partner, vision=False)
    env.reset(seed=0)
    assert partner.target in (0, 1)
    for _ in range(3):
        env.step({"infant_0": STILL_HEAD})
    t1 = [_run_targets(11), _run_targets(11), _run_targets(12)]
    assert t1[0] == t1[1] and t1[0] != t1[2]


def _run_targets(seed):
    partner = GazeAtTarget(hold_s=(0.2, 0.4))
    env = joint_attention_v0.scripted_env(partner, vision=False)
    env.reset(seed=seed)
    out = []
    for _ in range(150):
        env.step({"infant_0": STILL_HEAD})
        out.append(partner.target)
    return out


def test_gaze_at_target_bad_input():
    with pytest.raises(ValueError, match="hold_s"):
        GazeAtTarget(hold_s=(1.0, -1.0))
    with pytest.raises(ValueError, match="targets"):
        GazeAtTarget(targets="toy_0")
    with pytest.raises(ValueError, match="omega"):
        GazeAtTarget(omega=-1)
    for bad in (1.5, -0.1, (0.6, 0.2), "half", True):
        with pytest.raises(ValueError, match="head_share"):
            GazeAtTarget(head_share=bad)
    env = joint_attention_v0.scripted_env(GazeAtTarget(targets=["teddy"]), vision=False)
    with pytest.raises(ValueError, match="'teddy' is neither a body nor a site"):
        env.reset(seed=0)
    env = mirror_v0.scripted_env(GazeAtTarget(), vision=False)
    with pytest.raises(ValueError, match="no toys|does not actuate"):
        env.reset(seed=0)
    env = joint_attention_v0.scripted_env(GazeAtTarget(), vision=False, actuation="muscle")
    with pytest.raises(ValueError, match="spring_damper"):
        env.reset(seed=0)
