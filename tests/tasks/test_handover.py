"""The handover task: API, seeds, the physical initial grasp, the reward (the shaping toward the
giver's ready posture) and success rules (each clause of the success: test_handover_clauses.py)."""

import mujoco
import numpy as np
import pytest

from mimo_social.envs import handover_v0
from mimo_social.tasks.handover import OFFER_TARGET, READY_OFFSET, HandoverOptions, scripted_giver
from mimo_social.tasks.handover.controller import ARM, ReceiveController, hand_frame, palm_posture
from mimo_social.partners import ScriptedPartners, zero_action
from mimo_social.partners.hand_offer import HandOffer

pytestmark = pytest.mark.text_infos   # these tests read the text infos (info_text=True)

RECEIVER_TARGET = (0.10, 0.0, -0.12)   # a palm-up hand in front of the receiver, clear of the giver


def _scripted(task_options=None, **kwargs):
    """The scripted env with the handover's scripted giver (``scripted_giver``)."""
    opts = HandoverOptions(**(task_options or {}))
    return handover_v0.scripted_env(scripted_giver(opts), task_options=task_options or {},
                                    **kwargs)


def _ball(env):
    w = env.unwrapped.world
    return w.data.xpos[w.prop_bodies["ball"]].copy()


def _ready_point(env):
    """The ready point, computed here from the table's words: READY_OFFSET (forward, left, up)
    from the offered ball's centre at reset, in the receiver's heading frame (it faces +x)."""
    w = env.unwrapped.world
    R = w.data.xmat[w.agents[0].root_body].reshape(3, 3)
    np.testing.assert_allclose(R[:, 0], (1.0, 0.0, 0.0), atol=1e-9)
    return _ball(env) + np.asarray(READY_OFFSET)


def _potential(env, ready, in_hand=False):
    """The shaping's potential as the table states it (default scales 10, 2, 2): -10 x the palm
    centre's distance to the ready point + 2 x the palm normal's upward component (+ 2 x the
    four fingers' mean flexion fraction when the ball is in the receiver's hand)."""
    w = env.unwrapped.world
    d = w.data
    a = w.agents[0]
    site = a.palm_sites[0]
    R = d.xmat[w.model.site_bodyid[site]].reshape(3, 3)
    phi = -10.0 * np.linalg.norm(d.site_xpos[site] - ready) + 2.0 * (-R[2, 1])
    if in_hand:
        k = [j for j, n in enumerate(a.joint_names)
             if n.split("_")[1:2] in (["index"], ["middle"], ["ring"], ["little"])
             and n.split("_")[-1] in ("mcp", "pip", "dip")]
        frac = d.qpos[a.qpos_adr[k]] / a.joint_range[k, 1]
        phi += 2.0 * float(np.clip(frac, 0.0, 1.0).mean())
    return phi


def test_agents_and_spaces():   # the API checks: tests/conformance
    env = handover_v0.parallel_env(max_steps=40)
    assert env.possible_agents == ["infant_0", "infant_1"]
    assert env.action_space("infant_0").shape == (29,)            # right arm 7 + 22 fingers
    assert set(env.observation_space("infant_0").spaces) == {"proprioception", "touch"}


def test_reset_seed_draws_the_receivers_arm():
    env = handover_v0.parallel_env()
    a = env.world.agents[0]
    k = a.qpos_adr[a.actuated_joint_idx[:4]]
    env.reset(seed=1)
    q1 = env.world.data.qpos[k].copy()
    env.reset(seed=2)
    q2 = env.world.data.qpos[k].copy()
    env.reset(seed=1)
    np.testing.assert_array_equal(env.world.data.qpos[k], q1)
    assert np.abs(q1 - q2).max() > 1e-3


def test_scripted_env_exposes_the_receiver_and_the_giver_hands_over_on_hold():
    env = _scripted(max_steps=20)
    assert env.possible_agents == ["infant_0"]
    giver = env.partners["infant_1"]
    assert isinstance(giver, HandOffer) and giver.release == "on_hold" and giver.grip
    assert giver.target == OFFER_TARGET
    other = scripted_giver(HandoverOptions(offer_target=(0.17, 0.08, -0.06)))
    assert other.target == (0.17, 0.08, -0.06)
    # the env's own default giver (what the Gymnasium id and the baselines use) is the same
    plain = handover_v0.scripted_env(max_steps=20).partners["infant_1"]
    assert plain.release == "on_hold" and plain.grip and plain.target == OFFER_TARGET
    moved = handover_v0.scripted_env(task_options={"offer_target": (0.17, 0.08, -0.06)})
    assert moved.partners["infant_1"].target == (0.17, 0.08, -0.06)


@pytest.mark.parametrize("actuation", ["spring_damper", "muscle"])
def test_the_ball_stays_in_the_givers_hand_when_the_receiver_is_idle(actuation):
    env = _scripted(per_agent=[{}, {"actuation": actuation}])
    obs, _ = env.reset(seed=0)
    inner = env.unwrapped
    w = inner.world
    m, d = w.model, w.data
    palm = w.agents[1].palm_sites[0]
    # a physical grasp at rest: the ball lies in the palm, fingers touch it, nothing is welded
    assert m.neq == 0
    assert np.linalg.norm(d.qvel[w.prop_dof["ball"]:][:3]) < 0.05
    start = _ball(env)
    ready = _ready_point(env)
    idle = {"infant_0": zero_action(env.action_space("infant_0"))}
    before = _potential(env, ready)
    total = 0.0
    for _ in range(200):                                            # 2 s
        _, rew, term, trunc, infos = env.step(idle)
        info = infos["infant_0"]
        assert info["holder"] == "giver" and not info["dropped"] and not info["is_success"]
        assert not term["infant_0"]
        # the shaping: the potential's increase (toward the ready point, palm up), for both
        now = _potential(env, ready)
        assert rew["infant_0"] == pytest.approx(now - before, abs=1e-9)
        assert info["partner_rewards"]["infant_1"] == rew["infant_0"]
        before = now
        total += rew["infant_0"]
    assert env.partners["infant_1"].tip == 0.0 and not env.partners["infant_1"].released
    assert np.linalg.norm(_ball(env) - start) < 0.02
    assert np.linalg.norm(_ball(env) - d.site_xpos[palm]) < 0.06
    assert abs(total) < 0.5                                          # doing nothing earns ~0
    tip = d.site_xpos[w.agents[0].palm_sites[0]]
    assert info["distance"] == pytest.approx(np.linalg.norm(tip - _ball(env)), abs=1e-9)


def test_the_shaping_leads_to_where_the_giver_waits():
    """The ready point lies where the scripted giver's condition for tipping the ball holds
    (an open palm up beside its hand: HandOffer.open_hand_ready): a palm put there kinematically,
    facing up, satisfies it; the potential is higher there than with the palm at the ball (where
    the shaping pointed before issue 30) or hanging; the scripted receiver's shaping return up
    to the giver's tip is the potential's rise, and the giver tips once its palm is there."""
    env = _scripted(max_steps=600)
    env.reset(seed=1000)
    inner = env.unwrapped
    w = inner.world
    m, d = w.model, w.data
    a = w.agents[0]
    giver = env.partners["infant_1"]
    ready = _ready_point(env)
    hang = _potential(env, ready)
    k = a.qpos_adr[[a.joint_names.index(n) for n in ARM]]
    saved = d.qpos.copy()
    up = hand_frame((0.0, 0.0, 1.0), (1.0, 0.0, 0.0))
    start = np.deg2rad([60.0, 20.0, -60.0, -60.0, -80.0, 0.0, 0.0])
    q, res, _ = palm_posture(w, 0, ready, up, start=start)
    assert res < 2e-3
    d.qpos[k] = q
    mujoco.mj_forward(m, d)
    assert giver.open_hand_ready(d)                                  # what the giver waits for
    at_ready = _potential(env, ready)
    q, res, _ = palm_posture(w, 0, _ball(env) - (0.0, 0.0, 0.035), up, start=start)
    d.qpos[k] = q
    mujoco.mj_kinematics(m, d)
    at_ball = _potential(env, ready)
    assert at_ready > at_ball + 0.3 and at_ready > hang + 2.0
    d.qpos[:] = saved
    mujoco.mj_forward(m, d)
    receiver = ReceiveController()
    receiver.reset(inner, "infant_0", None)
    total, phi0 = 0.0, _potential(env, ready)
    while giver.tip == 0.0:
        _, rew, *_ = env.step({"infant_0": receiver.act(inner, "infant_0", None)})
        total += rew["infant_0"]
    palm = d.site_xpos[a.palm_sites[0]]
    assert np.linalg.norm(palm - ready) < 0.02
    assert total == pytest.approx(_potential(env, ready) - phi0, abs=1e-6)
    assert total > 0.8 * (at_ready - phi0)                           # most of the way there


def test_receiver_holding_the_ball_alone_is_a_success_for_both():
    env = handover_v0.parallel_env(max_steps=200)
    env.reset(seed=0)
    env.task.put_ball_in_hand(env, 0, RECEIVER_TARGET)             # the ball moves over
    mujoco.mj_forward(env.world.model, env.world.data)
    receiver = HandOffer(target=RECEIVER_TARGET, release=None)
    giver = HandOffer(target=OFFER_TARGET)
    receiver.reset(env, "infant_0", None)
    giver.reset(env, "infant_1", None)
    hold = round(0.3 / env.dt)
    steps = []
    for _ in range(100):
        _, rew, term, trunc, infos = env.step({"infant_0": receiver.act(env, "infant_0", None),
                                               "infant_1": giver.act(env, "infant_1", None)})
        steps.append(infos["infant_0"])
        if term["infant_0"]:
            break
    last = steps[-1]
    assert last["is_success"] and last["holder"] == "receiver"
    assert last["receiver_parts"] >= 2 and last["held_steps"] == hold
    assert term == {"infant_0": True, "infant_1": True}
    assert rew["infant_0"] == rew["infant_1"]
    assert 9.0 < rew["infant_0"] < 11.0                              # + success_reward (10)
    # success needs the hold to last: the steps before it were not successes
    assert not any(s["is_success"] for s in steps[:-1])
    assert sum(s["holder"] == "receiver" for s in steps) >= hold


def test_one_hand_part_or_a_giver_contact_is_not_a_handover():
    env = handover_v0.parallel_env(task_options={"min_parts": 10})  # more parts than possible
    env.reset(seed=0)
    env.task.put_ball_in_hand(env, 0, RECEIVER_TARGET)
    mujoco.mj_forward(env.world.model, env.world.data)
    receiver = HandOffer(target=RECEIVER_TARGET, release=None)
    receiver.reset(env, "infant_0", None)
    giver = HandOffer(target=OFFER_TARGET)
    giver.reset(env, "infant_1", None)
    for _ in range(60):
        _, _, term, _, infos = env.step({"infant_0": receiver.act(env, "infant_0", None),
                                         "infant_1": giver.act(env, "infant_1", None)})
        assert infos["infant_0"]["holder"] == "none" and not infos["infant_0"]["is_success"]
    assert not term["infant_0"]
    # at the start the giver holds the ball: never the receiver's, even with hands touching
    env = handover_v0.parallel_env()
    _, _ = env.reset(seed=0)
    _, _, _, _, infos = env.step({a: zero_action(env.action_space(a)) for a in env.agents})
    assert infos["infant_0"]["holder"] == "giver"


def test_a_dropped_ball_ends_the_episode_with_failure():
    env = _scripted()
    env.reset(seed=0)
    inner = env.unwrapped
    inner.task.place_ball(inner, (0.15, 0.6, 0.45))                # away from every hand
    idle = {"infant_0": zero_action(env.action_space("infant_0"))}
    total = 0.0
    for k in range(100):
        _, rew, term, trunc, infos = env.step(idle)
        info = infos["infant_0"]
        total += rew["infant_0"]
        if term["infant_0"]:
            break
        assert info["holder"] == "none" and not info["dropped"]
    assert info["dropped"] and not info["is_success"]
    assert _ball(env)[2] < 0.25
    assert info["partner_rewards"]["infant_1"] == rew["infant_0"]
    assert rew["infant_0"] < -10.0                                 # failure_reward (-10) ...
    assert total < -10.0                                           # ... worse than never trying
    assert k < 40                                                  # it falls in well under 0.4 s


@pytest.mark.parametrize("assisted", [False, True])
def test_the_receiver_feels_the_ball_and_its_gaze_follows_it_only_when_assisted(assisted):
    env = handover_v0.parallel_env(task_options={"assisted_gaze": assisted})
    obs, _ = env.reset(seed=0)
    assert not obs["infant_0"]["touch"].any()
    w = env.world
    a = w.agents[0]
    if not assisted:                          # head and eyes held at rest, in the body itself
        assert "head_swivel" not in a.joint_names
        assert env.observation_space("infant_0")["proprioception"].shape == (174,)
    else:
        assert env.observation_space("infant_0")["proprioception"].shape == (210,)
        gaze = a.qpos_adr[a.joint_names.index("head_swivel")]
        before = w.data.qpos[gaze]
    env.task.put_ball_in_hand(env, 0, RECEIVER_TARGET)
    mujoco.mj_forward(w.model, w.data)
    felt = 0.0
    for _ in range(5):
        obs, *_ = env.step({ag: zero_action(env.action_space(ag)) for ag in env.agents})
        felt = max(felt, float(obs["infant_0"]["touch"].sum()))
    assert felt > 0                                                  # the ball on its skin
    if assisted:
        assert abs(w.data.qpos[gaze] - before) > 0.05                # the head turned to it


def _receiver_obs(offer, assisted, steps=5, seed=3):
    env = _scripted(task_options={"offer_target": offer, "assisted_gaze": assisted})
    obs, _ = env.reset(seed=seed)
    out = [obs["infant_0"]]
    idle = {"infant_0": zero_action(env.action_space("infant_0"))}
    for _ in range(steps):
        obs, _, _, _, infos = env.step(idle)
        assert infos["infant_0"]["receiver_parts"] == 0              # no contact with the ball
        out.append(obs["infant_0"])
    ball = _ball(env)
    return out, ball


def test_where_the_ball_is_offered_does_not_reach_the_receivers_observation():
    """Only the offer position changes (the task option offer_target): the receiver's
    observations at reset and over 5 zero-action steps, before any contact, are identical; with
    the privileged assisted_gaze they are not."""
    a, ball_a = _receiver_obs(OFFER_TARGET, False)
    b, ball_b = _receiver_obs((0.15, 0.06, -0.04), False)
    assert np.linalg.norm(ball_a - ball_b) > 0.03                     # the ball is elsewhere
    for oa, ob in zip(a, b):
        for key in oa:
            np.testing.assert_array_equal(oa[key], ob[key])
    a, _ = _receiver_obs(OFFER_TARGET, True)
    b, _ = _receiver_obs((0.15, 0.06, -0.04), True)
    assert np.abs(a[0]["proprioception"] - b[0]["proprioception"]).max() > 1e-3


@pytest.mark.parametrize("kwargs, pattern", [
    ({"task_options": {"ball_colour": "red"}}, r"unknown task option.*allowed"),
    ({"task_options": {"ball_radius": 0.1}}, r"ball_radius=0.1.*from 0.015 to 0.045"),
    ({"task_options": {"min_parts": 2.5}}, r"min_parts=2.5.*integer"),
    ({"task_options": {"hold_time": "long"}}, r"hold_time='long'"),
    ({"task_options": {"offer_target": (0, 0)}}, r"offer_target=.*forward, left, up"),
    ({"task_options": {"end_on_success": 1}}, r"end_on_success=1.*True or False"),
    ({"task_options": {"shaping": "no"}}, r"shaping='no'.*True or False"),
    ({"task_options": {"shaping_scale": -1}}, r"shaping_scale=-1.*from 0"),
    ({"task_options": {"palm_up_scale": -1}}, r"palm_up_scale=-1.*from 0"),
    ({"task_options": {"grip_scale": "x"}}, r"grip_scale='x'"),
    ({"task_options": {"grasp_height": 2}}, r"grasp_height=2.*from -1 to 1"),
    ({"task_options": {"assisted_gaze": 1}}, r"assisted_gaze=1.*True or False"),
    ({"hands": "mitten"}, r"hands='mitten' not allowed.*five_fingers"),
    ({"posture": "sitting"}, r"posture='sitting' not allowed.*standing"),
    ({"n_agents": 3}, r"n_agents=3.*2 to 2"),
])
def test_bad_options_raise_clear_errors(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        handover_v0.parallel_env(**kwargs)


def test_aec_env_runs():
    env = handover_v0.env(max_steps=5)
    env.reset(seed=0)
    for agent in env.agent_iter():
        *_, term, trunc, _ = env.last()
        env.step(None if term or trunc else env.action_space(agent).sample())
    assert isinstance(_scripted(), ScriptedPartners)
