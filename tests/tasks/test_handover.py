"""The handover task: API, seeds, the physical initial grasp, the reward and success rules."""

import mujoco
import numpy as np
import pytest

from mimo_social.envs import handover_v0
from mimo_social.tasks.handover import OFFER_TARGET
from mimo_social.partners import ScriptedPartners, zero_action
from mimo_social.partners.hand_offer import HandOffer

RECEIVER_TARGET = (0.10, 0.0, -0.12)   # a palm-up hand in front of the receiver, clear of the giver


def _ball(env):
    w = env.unwrapped.world
    return w.data.xpos[w.prop_bodies["ball"]].copy()


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


def test_scripted_env_exposes_the_receiver():   # check_env: tests/conformance
    env = handover_v0.scripted_env(max_steps=20)
    assert env.possible_agents == ["infant_0"]
    assert isinstance(env.partners["infant_1"], HandOffer)
    assert env.partners["infant_1"].release == "on_touch"


@pytest.mark.parametrize("actuation", ["spring_damper", "muscle"])
def test_the_ball_stays_in_the_givers_hand_when_the_receiver_is_idle(actuation):
    env = handover_v0.scripted_env(per_agent=[{}, {"actuation": actuation}])
    obs, _ = env.reset(seed=0)
    inner = env.unwrapped
    w = inner.world
    m, d = w.model, w.data
    palm = w.agents[1].palm_sites[0]
    # a physical grasp at rest: the ball lies in the palm, fingers touch it, nothing is welded
    assert m.neq == 0
    assert np.linalg.norm(d.qvel[w.prop_dof["ball"]:][:3]) < 0.05
    start = _ball(env)
    idle = {"infant_0": zero_action(env.action_space("infant_0"))}
    for _ in range(100):                                            # 1 s
        _, rew, term, trunc, infos = env.step(idle)
        info = infos["infant_0"]
        assert info["holder"] == "giver" and not info["dropped"] and not info["is_success"]
        assert not term["infant_0"]
    assert np.linalg.norm(_ball(env) - start) < 0.02
    assert np.linalg.norm(_ball(env) - d.site_xpos[palm]) < 0.06
    # the shaping reward is minus the receiver's fingertip distance to the ball, for both
    tip = d.site_xpos[w.agents[0].fingertip_sites[0]]
    assert rew["infant_0"] == pytest.approx(-np.linalg.norm(tip - _ball(env)), abs=1e-9)
    assert info["partner_rewards"]["infant_1"] == rew["infant_0"]


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
    assert rew["infant_0"] == rew["infant_1"] == pytest.approx(10.0 - last["distance"])
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


@pytest.mark.parametrize("charge", [True, False])
def test_a_dropped_ball_ends_the_episode_with_failure(charge):
    env = handover_v0.scripted_env(task_options={"charge_remaining": charge})
    env.reset(seed=0)
    inner = env.unwrapped
    inner.task.place_ball(inner, (0.15, 0.6, 0.45))                # away from every hand
    idle = {"infant_0": zero_action(env.action_space("infant_0"))}
    for k in range(100):
        _, rew, term, trunc, infos = env.step(idle)
        info = infos["infant_0"]
        if term["infant_0"]:
            break
        assert info["holder"] == "none" and not info["dropped"]
        assert rew["infant_0"] == pytest.approx(-info["distance"])
    assert info["dropped"] and not info["is_success"]
    assert _ball(env)[2] < 0.25
    rest = 600 - info["step"] if charge else 0          # the remaining steps, charged
    assert rew["infant_0"] == pytest.approx(-1.0 - info["distance"] * (1 + rest))
    assert info["partner_rewards"]["infant_1"] == rew["infant_0"]
    assert k < 40                                                  # it falls in well under 0.4 s


def test_the_receiver_feels_the_ball_and_its_gaze_follows_it():
    env = handover_v0.parallel_env()
    obs, _ = env.reset(seed=0)
    assert not obs["infant_0"]["touch"].any()
    w = env.world
    a = w.agents[0]
    gaze = a.qpos_adr[a.gaze_idx[0]]                                # head swivel
    before = w.data.qpos[gaze]
    env.task.put_ball_in_hand(env, 0, RECEIVER_TARGET)
    mujoco.mj_forward(w.model, w.data)
    felt = 0.0
    for _ in range(5):
        obs, *_ = env.step({ag: zero_action(env.action_space(ag)) for ag in env.agents})
        felt = max(felt, float(obs["infant_0"]["touch"].sum()))
    assert felt > 0                                                  # the ball on its skin
    assert abs(w.data.qpos[gaze] - before) > 0.05                    # the head turned to it


@pytest.mark.parametrize("kwargs, pattern", [
    ({"task_options": {"ball_colour": "red"}}, r"unknown task option.*allowed"),
    ({"task_options": {"ball_radius": 0.1}}, r"ball_radius=0.1.*from 0.015 to 0.045"),
    ({"task_options": {"min_parts": 2.5}}, r"min_parts=2.5.*integer"),
    ({"task_options": {"hold_time": "long"}}, r"hold_time='long'"),
    ({"task_options": {"offer_target": (0, 0)}}, r"offer_target=.*forward, left, up"),
    ({"task_options": {"end_on_success": 1}}, r"end_on_success=1.*True or False"),
    ({"task_options": {"charge_remaining": "no"}}, r"charge_remaining='no'.*True or False"),
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
    assert isinstance(handover_v0.scripted_env(), ScriptedPartners)
