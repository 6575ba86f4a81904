"""The mirror task (facial mimicry) through its public API."""

import numpy as np
import pytest
from gymnasium import spaces

from mimo_social.envs import mirror_v0
from mimo_social.core.gym_adapter import SingleAgentEnv
from mimo_social.core.wrappers import FlattenParallel
from mimo_social.train.envs import make_sb3_single
from mimo_social.expressions.faces import EXPRESSIONS
from mimo_social.partners import Partner
from mimo_social.partners.expression import ExpressionShow
from mimo_social.tasks.mirror.controller import MirrorController

pytestmark = pytest.mark.text_infos   # these tests read the text infos (info_text=True)

NO_MOTORS = np.zeros(0, np.float32)


def act(expression):
    return {"motors": NO_MOTORS, "expression": np.int64(expression)}


class Shows(Partner):
    """A fixed face, motors at rest (the test's own scripted partner)."""

    def __init__(self, expression):
        self.expression = expression

    def act(self, env, agent, observation):
        return act(self.expression)


def test_three_agents_and_bad_options_raise_clear_errors():
    with pytest.raises(ValueError, match="n_agents=3; allowed: 2 to 2"):
        mirror_v0.parallel_env(n_agents=3)
    with pytest.raises(ValueError, match="distance"):
        mirror_v0.parallel_env(task_options={"distance": 0.1})
    with pytest.raises(ValueError, match="scripted_partner"):
        mirror_v0.parallel_env(task_options={"scripted_partner": "yes"})
    with pytest.raises(ValueError, match="unknown task option"):
        mirror_v0.parallel_env(task_options={"reward": 2})
    with pytest.raises(ValueError, match=r"roles='both'.*'leader', 'free'"):
        mirror_v0.parallel_env(task_options={"roles": "both"})
    with pytest.raises(ValueError, match="assisted_gaze"):
        mirror_v0.parallel_env(task_options={"assisted_gaze": 1})
    with pytest.raises(ValueError, match="success_fraction=1.5"):
        mirror_v0.parallel_env(task_options={"success_fraction": 1.5})
    with pytest.raises(ValueError, match=r"leader_hold_s.*\(min, max\) seconds"):
        mirror_v0.parallel_env(task_options={"leader_hold_s": (2.0, 1.0)})


def test_spaces_eyes_and_expression_action():
    env = mirror_v0.parallel_env()
    for a in env.possible_agents:
        obs_space = env.observation_space(a)
        # head and eyes held: no free joint, so no proprioception key (never an empty array)
        assert set(obs_space.spaces) == {"eye_left", "eye_right"}
        assert obs_space["eye_left"].shape == (64, 64, 3)
        assert env.action_space(a)["expression"].n == len(EXPRESSIONS)
        assert env.action_space(a)["motors"].shape == (0,)
    assert env.max_steps == 500
    aimed = mirror_v0.parallel_env(task_options={"assisted_gaze": True})
    assert aimed.observation_space("infant_0")["proprioception"].shape == (36,)


def test_match_reward_both_learners_with_free_roles():
    env = mirror_v0.parallel_env(task_options={"roles": "free"})
    env.reset(seed=0)
    for e0, e1 in [(1, 1), (1, 2), (6, 6), (0, 3)]:
        _, rew, term, trunc, info = env.step({"infant_0": act(e0), "infant_1": act(e1)})
        want = float(e0 == e1)
        assert rew == {"infant_0": want, "infant_1": want}
        for a in env.possible_agents:
            assert info[a]["match"] is (e0 == e1)
            assert info[a]["is_success"] is False        # per episode: 400 matched steps
            assert not info[a]["is_leader"]
            assert not term[a] and not trunc[a]


def test_episode_is_500_steps_without_termination():
    env = mirror_v0.parallel_env(vision=False)
    env.reset(seed=0)
    for k in range(500):
        _, _, term, trunc, _ = env.step({a: act(0) for a in env.agents})
        assert not any(term.values())
        assert all(trunc.values()) == (k == 499)
    assert env.agents == []


def test_scripted_env_rewards_only_the_learner():
    env = mirror_v0.scripted_env(Shows(4))
    assert env.possible_agents == ["infant_0"]
    inner = env.unwrapped
    assert inner.agent_configs[1].vision is None  # a scripted partner needs no eyes
    env.reset(seed=1)
    for k, e in enumerate((4, 2, 4)):
        _, rew, _, _, info = env.step({"infant_0": act(e)})
        assert rew["infant_0"] == float(e == 4)
        assert info["infant_0"]["match"] is (e == 4)
        assert info["infant_0"]["matched_steps"] == (1, 1, 2)[k]
        assert info["infant_0"]["partner_rewards"] == {"infant_1": 0.0}


def test_scripted_env_default_partner_is_expression_show():
    env = mirror_v0.scripted_env()
    partner = env.partners["infant_1"]
    assert isinstance(partner, ExpressionShow)
    env.reset(seed=3)
    for _ in range(50):
        _, rew, _, _, info = env.step({"infant_0": act(2)})
        assert env.unwrapped.world.expression_of(1) == partner.current
        assert rew["infant_0"] == float(partner.current == 2)


@pytest.mark.parametrize("assisted_gaze", [False, True])
def test_partner_expression_only_in_the_eye_images(assisted_gaze):
    """Change only the partner's face: every observation value of the learner stays the same
    except its eye images, which change (the expression is seen, never given)."""
    env = mirror_v0.parallel_env(task_options={"roles": "free", "assisted_gaze": assisted_gaze})
    images, others = [], []
    for e in range(len(EXPRESSIONS)):
        obs, _ = env.reset(seed=5)
        obs, *_ = env.step({"infant_0": act(0), "infant_1": act(e)})
        o = obs["infant_0"]
        # proprioception only with assisted gaze (head and eyes are joints then)
        assert set(o) == {"eye_left", "eye_right"} | ({"proprioception"} if assisted_gaze
                                                      else set())
        images.append(np.concatenate([o["eye_left"], o["eye_right"]]).astype(int))
        others.append(o.get("proprioception", np.zeros(1)))
    for e in range(1, len(EXPRESSIONS)):
        np.testing.assert_array_equal(others[e], others[0])
    # every pair of faces differs clearly (thousands of pixel levels summed; the renderer is
    # deterministic, so any difference is the face)
    for e in range(len(EXPRESSIONS)):
        for f in range(e):
            assert np.abs(images[e] - images[f]).sum() > 2000, (EXPRESSIONS[e], EXPRESSIONS[f])


def test_flat_wrappers_work_with_the_empty_motor_box():
    """A face-only agent's flat action is the expression id (Discrete(7)) in both wrappers."""
    flat = FlattenParallel(mirror_v0.parallel_env(task_options={"roles": "free"}))
    assert flat.action_space("infant_0") == spaces.Discrete(7)
    flat.reset(seed=0)
    _, rew, *_ = flat.step({a: 3 for a in flat.agents})
    assert rew["infant_0"] == 1.0
    _, rew, *_ = flat.step({"infant_0": 3, "infant_1": 4})
    assert rew["infant_0"] == 0.0
    single = make_sb3_single(SingleAgentEnv(mirror_v0.scripted_env()), flat=True)
    assert isinstance(single.observation_space, spaces.Box)
    assert single.action_space == spaces.Discrete(7)
    obs, _ = single.reset(seed=0)
    assert obs.shape == single.observation_space.shape
    obs, r, term, trunc, info = single.step(single.action_space.sample())
    assert r in (0.0, 1.0) and "is_success" in info


def test_the_posture_looks_at_the_partners_face_without_aiming():
    """Head and eyes are held straight ahead: the partner's face is in the middle of both eye
    images (its skin-coloured pixels are centred), with no gaze joint in the model."""
    env = mirror_v0.parallel_env(task_options={"roles": "free"})
    obs, _ = env.reset(seed=0)
    assert env.world.agents[0].gaze_idx.size == 0
    for eye in ("eye_left", "eye_right"):
        img = obs["infant_0"][eye].astype(int)
        skin = (img[..., 0] > 120) & (img[..., 0] - img[..., 2] > 40) & (img[..., 1] > 80)
        ys, xs = np.nonzero(skin)
        assert len(xs) > 300                                  # a face-sized patch
        assert abs(xs.mean() - 31.5) < 8 and abs(ys.mean() - 31.5) < 16


def _episode(env, policy, seed):
    """One episode of the scripted env; the learner acts with ``policy`` (a Partner or
    "random"); returns (return, last info, first step with is_success or None)."""
    obs, _ = env.reset(seed=seed)
    inner = env.unwrapped
    space = env.action_space("infant_0")
    space.seed(seed)
    if policy != "random":
        policy.reset(inner, "infant_0", np.random.default_rng(seed))
    total, first, k = 0.0, None, 0
    while env.agents:
        a = space.sample() if policy == "random" else policy.act(inner, "infant_0", obs["infant_0"])
        obs, r, term, trunc, info = env.step({"infant_0": a})
        k += 1
        total += r["infant_0"]
        if first is None and info["infant_0"]["is_success"]:
            first = k
    return total, info["infant_0"], first


def test_success_is_per_episode_the_mirror_succeeds_random_and_neutral_fail():
    """The scripted mirror copies the partner's face (read from the world) with a one-step lag:
    about 99 % of the steps match, the episode succeeds from the 400th matched step on. Random
    faces and always neutral (the zero action) match about 1/7 of the steps and fail."""
    env = mirror_v0.scripted_env(vision=False)      # the policies here do not look
    total, info, first = _episode(env, MirrorController(), 1000)
    assert info["is_success"] and info["matched_steps"] == total >= 490
    assert 400 <= first <= 410
    for hack in ("random", MirrorController(face="neutral")):
        total, info, first = _episode(env, hack, 1000)
        assert not info["is_success"] and first is None and total < 200


@pytest.mark.slow
def test_twenty_episodes_scripted_random_zero_with_eyes():
    """Seeds 1000-1019, the default env (the learner's eyes rendered): scripted 20 / 20, random
    and always neutral 0 / 20, both with less return than the scripted mirror."""
    env = mirror_v0.scripted_env()
    runs = {name: [_episode(env, p, s) for s in range(1000, 1020)]
            for name, p in [("scripted", MirrorController()), ("random", "random"),
                            ("neutral", MirrorController(face="neutral"))]}
    wins = {k: sum(bool(i["is_success"]) for _, i, _ in v) for k, v in runs.items()}
    ret = {k: np.mean([t for t, _, _ in v]) for k, v in runs.items()}
    assert wins == {"scripted": 20, "random": 0, "neutral": 0}
    assert ret["scripted"] > 490 > 150 > max(ret["random"], ret["neutral"])


def test_two_learners_leader_face_set_by_the_task_only_the_follower_is_rewarded():
    """roles="leader": the leader's face follows the task's script whatever it asks for, only
    the follower is rewarded; "always neutral" from both earns chance, a follower that copies
    earns nearly every step and the episode's success."""
    env = mirror_v0.parallel_env(vision=False)
    leaders = set()
    for seed in range(4):
        env.reset(seed=seed)
        shown, total = [], {a: 0.0 for a in env.possible_agents}
        while env.agents:
            _, rew, _, _, info = env.step({a: act(0) for a in env.agents})
            shown.append(env.world.expression_of(0 if info["infant_0"]["is_leader"] else 1))
            for a in rew:
                total[a] += rew[a]
        leader = "infant_0" if info["infant_0"]["is_leader"] else "infant_1"
        follower = "infant_1" if leader == "infant_0" else "infant_0"
        assert info[follower]["is_leader"] is False
        leaders.add(leader)
        assert total[leader] == 0.0 and total[follower] < 200
        assert len(set(shown)) >= 3 and not info[follower]["is_success"]
    assert leaders == {"infant_0", "infant_1"}       # drawn per episode (seeded)
    copier = {a: MirrorController() for a in env.possible_agents}
    obs, _ = env.reset(seed=7)
    for a, p in copier.items():
        p.reset(env, a, np.random.default_rng(0))
    total = {a: 0.0 for a in env.possible_agents}
    while env.agents:
        obs, rew, _, _, info = env.step({a: p.act(env, a, None) for a, p in copier.items()})
        for a in rew:
            total[a] += rew[a]
    assert max(total.values()) >= 490 and min(total.values()) == 0.0
    assert info["infant_0"]["is_success"] and info["infant_1"]["is_success"]
