"""The imitation task (imitation of actions, seen through the eyes) through its public API."""

import numpy as np
import pytest

from mimo_social.envs import imitation_v0
from mimo_social.tasks.imitation.controller import ImitationController
from mimo_social.tasks.imitation.demonstrator import ACTION_POSES, Demonstrator
from mimo_social.tasks.imitation import ACTIONS
from mimo_social.tasks.imitation.measures import records, summary

BLIND = {"vision": False}      # the learner's eyes off where the test needs no pictures


def scripted(learner=BLIND, partner=None, **options):
    return imitation_v0.scripted_env(per_agent=[dict(learner), dict(partner or {})],
                                     task_options=options)


def seeds_by_action(env, first=0, n=40) -> dict:
    """One reset seed per demonstrated action (the task draws it from the seeded generator)."""
    out = {}
    for seed in range(first, first + n):
        env.reset(seed=seed)
        out.setdefault(env.unwrapped.task.demonstrated_action, seed)
        if len(out) == len(ACTIONS):
            return out
    raise AssertionError(f"not every action drawn in {n} seeds: {out}")


def episode(env, partner, seed):
    """The learner's last info and its return over one episode with a scripted policy."""
    [rec] = records(env, partner, 1, seed=seed)
    return rec


def test_bad_options_raise_clear_errors():
    with pytest.raises(ValueError, match="n_agents=3"):
        imitation_v0.parallel_env(n_agents=3)
    with pytest.raises(ValueError, match=r"actions \['wave'\] unknown.*head_touch"):
        imitation_v0.parallel_env(task_options={"actions": ["wave"]})
    with pytest.raises(ValueError, match="actions"):
        imitation_v0.parallel_env(task_options={"actions": ["clap", "clap"]})
    with pytest.raises(ValueError, match="wrong_reward"):
        imitation_v0.parallel_env(task_options={"wrong_reward": 1.0})
    with pytest.raises(ValueError, match="demo_s"):
        imitation_v0.parallel_env(task_options={"demo_s": 0.1})
    with pytest.raises(ValueError, match="action='wave'"):
        ImitationController(action="wave")
    with pytest.raises(ValueError, match="actuation='spring_damper'.*positional"):
        episode(scripted(learner={**BLIND, "actuation": "spring_damper"}),
                ImitationController(), 0)


def test_spaces_and_nothing_privileged():
    env = imitation_v0.scripted_env()
    space = env.observation_space("infant_0")
    assert set(space.spaces) == {"proprioception", "eye_left", "eye_right", "turn"}
    assert space["eye_left"].shape == (64, 64, 3)
    assert env.action_space("infant_0").shape == (16,)       # both arms, positional
    # before the demonstration every episode looks the same, whatever action is drawn
    seeds = seeds_by_action(env)
    first = [env.reset(seed=s)[0]["infant_0"] for s in seeds.values()]
    for obs in first[1:]:
        for k in obs:
            np.testing.assert_array_equal(obs[k], first[0][k])
    # two learners: the demonstrator alone is told the action (its own task)
    two = imitation_v0.parallel_env(per_agent=[BLIND, BLIND])
    obs, _ = two.reset(seed=seeds["clap"])
    assert obs["caregiver_0"]["instruction"].tolist() == [0, 0, 1, 0]
    assert obs["infant_0"]["instruction"].tolist() == [0, 0, 0, 0]


@pytest.mark.parametrize("body", ["adult", "infant"])
def test_each_outcome_fires_for_the_demonstration_and_the_reproduction(body):
    """The demonstrator (the kneeling adult, or an 18-month-old) shows each action with that
    action's outcome alone; the scripted learner reproduces it and succeeds."""
    partner = {} if body == "adult" else {"body": "infant"}
    for k, action in enumerate(ACTIONS):
        env = scripted(partner=partner, actions=[action])
        rec = episode(env, ImitationController(), 0)
        assert rec["demonstrated"] == k
        assert rec["demonstration"] == k, (body, action, rec)
        assert rec["demonstration_outcomes"] == 1 << k, (body, action, rec)
        assert rec["response"] == k and rec["is_success"], (body, action, rec)
        assert rec["return"] == 1.0
        assert 0 < rec["response_step"] < 100          # within a second of its turn


def test_reward_is_highest_for_the_demonstrated_action():
    """The scripted learner performing each action in turn, for each demonstrated action: +1
    for the demonstrated one, ``wrong_reward`` for every other."""
    env = scripted(wrong_reward=-0.5)
    seeds = seeds_by_action(env)
    for shown, seed in seeds.items():
        for done in ACTIONS:
            rec = episode(env, ImitationController(action=done), seed)
            assert rec["response"] == ACTIONS.index(done), (shown, done, rec)
            assert rec["return"] == (1.0 if done == shown else -0.5), (shown, done, rec)
            assert rec["is_success"] == (done == shown)


class Acts:
    """A policy for the learner from a function env -> action."""

    def __init__(self, fn):
        self.fn = fn

    def act(self, env, agent, obs):
        return self.fn(env)


def test_random_and_zero_actions_fail():
    env = scripted()
    zero = records(env, Acts(lambda e: np.zeros(16, np.float32)), 4, seed=100)
    assert all(r["response"] == -1 and r["return"] == 0.0 for r in zero)
    env.action_space("infant_0").seed(0)
    rand = records(env, Acts(lambda e: e.action_space("infant_0").sample()), 8, seed=100)
    assert sum(r["is_success"] for r in rand) <= 2


def test_reward_free_keeps_the_measures_and_summary_counts():
    env = scripted(reward_free=True)
    recs = records(env, ImitationController(), 4, seed=0)
    assert all(r["is_success"] and r["return"] == 0.0 for r in recs)
    s = summary(recs)
    assert s["all"]["episodes"] == 4 and s["all"]["success"] == 1.0
    for action, row in s.items():
        if action != "all":
            assert row["responses"][action] == row["episodes"]


def test_two_learners_the_demonstrator_is_rewarded_for_its_instruction():
    env = imitation_v0.parallel_env(per_agent=[BLIND, BLIND])
    obs, _ = env.reset(seed=3)
    demo = Demonstrator()
    demo.reset(env, "caregiver_0", np.random.default_rng(0))
    total = {"infant_0": 0.0, "caregiver_0": 0.0}
    while env.agents:
        act = {"infant_0": np.zeros(16, np.float32),
               "caregiver_0": demo.act(env, "caregiver_0", obs["caregiver_0"])}
        obs, rew, term, trunc, info = env.step(act)
        for a in rew:
            total[a] += rew[a]
    assert total == {"infant_0": 0.0, "caregiver_0": 1.0}
    assert info["caregiver_0"]["is_success"] and not info["infant_0"]["is_success"]


def test_every_action_has_a_pose():
    assert set(ACTION_POSES) == set(ACTIONS)


def test_a_push_during_the_demonstration_is_no_act():
    """The learner's box is put back when its turn begins: a learner that pushes it while the
    demonstration runs (here: the demonstrator's own script on the learner's arms) and then
    holds still has made no act."""
    env = scripted(actions=["push_box"])
    obs, _ = env.reset(seed=0)
    inner = env.unwrapped
    early = Demonstrator()
    early.reset(inner, "infant_0", np.random.default_rng(0))
    slid = []
    while env.agents:
        obs, rew, term, trunc, info = env.step({"infant_0": early.act(inner, "infant_0", None)})
        slid.append(info["infant_0"]["outcomes"] if info else 0)
    assert max(slid[:inner.task.demo_steps]) == 1 << ACTIONS.index("push_box")   # pushed
    assert info["infant_0"]["response"] == -1 and rew["infant_0"] == 0.0


def test_the_demonstration_reaches_the_learners_eyes():
    """While the demonstrator holds each act (1.5 s in), the learner's eye image differs from
    its first one and from every other act's in many pixels (a channel changed by over 30)."""
    def changed(a, b):
        return int((np.abs(a.astype(int) - b.astype(int)).max(-1) > 30).sum())

    seen = {}
    for action in ACTIONS:
        env = imitation_v0.scripted_env(task_options={"actions": [action]})
        obs, _ = env.reset(seed=0)
        start = obs["infant_0"]["eye_left"]
        for _ in range(150):
            obs, *_ = env.step({"infant_0": np.zeros(16, np.float32)})
        seen[action] = obs["infant_0"]["eye_left"]
        assert changed(seen[action], start) > 100, action
    for i, a in enumerate(ACTIONS):
        for b in ACTIONS[i + 1:]:
            assert changed(seen[a], seen[b]) > 100, (a, b)


class Watched:
    """The scripted learner's arm angles (its proprioception's first values) at every step of
    one episode, and its last info."""

    def __init__(self, controller):
        self.c, self.arms, self.outcomes = controller, [], []

    def reset(self, env, agent, rng):
        self.c.reset(env, agent, rng)

    def act(self, env, agent, obs):
        self.arms.append(np.asarray(obs["proprioception"][:16], float).copy())
        return self.c.act(env, agent, obs)


@pytest.mark.parametrize("prepare", [0.3, 0.5, 0.7])
def test_a_prepared_act_keeps_what_was_seen_in_the_posture(prepare):
    """``prepare``: the scripted learner goes part of the way to the shown act while it watches
    (no outcome of its own in the demonstration), holds still before the demonstrator's arm has
    reached its pose (nothing there tells the acts apart), and still succeeds in its turn; at the
    turn's first step its posture differs between the acts (what it saw is in its body), and
    without ``prepare`` it does not."""
    env = scripted()
    seeds = seeds_by_action(env)
    at_turn = {}
    for shown, seed in seeds.items():
        for p in (0.0, prepare):
            w = Watched(ImitationController(prepare=p))
            [rec] = records(env, w, 1, seed=seed)
            demo = env.unwrapped.task.demo_steps
            assert rec["is_success"] and rec["response"] == ACTIONS.index(shown), (p, shown, rec)
            early = int(round(0.8 / env.unwrapped.dt)) - 1      # prepare_at_s: 0.8
            assert np.abs(w.arms[early] - w.arms[0]).max() < 0.02, (p, shown)
            at_turn[shown, p] = w.arms[demo]
    for p in (0.0, prepare):
        arms = [at_turn[a, p] for a in ACTIONS]
        gaps = [np.abs(arms[i] - arms[j]).max() for i in range(4) for j in range(i + 1, 4)]
        if p == 0.0:
            assert max(gaps) < 0.02, gaps
        else:
            assert min(gaps) > 0.1 * prepare, gaps


def test_a_prepared_act_makes_no_outcome_while_the_demonstration_runs():
    """Every act prepared at 0.7 (the most allowed: at 0.9 the raised palm is already over the
    head) makes no outcome of the learner's in the demonstration: ``outcomes`` stays 0 until its
    turn."""
    env = scripted()
    for shown, seed in seeds_by_action(env).items():
        c = ImitationController(prepare=0.7)
        obs, _ = env.reset(seed=seed)
        inner = env.unwrapped
        c.reset(inner, "infant_0", np.random.default_rng(0))
        while env.agents and not inner.task.turn:
            obs, rew, term, trunc, info = env.step({"infant_0": c.act(inner, "infant_0", obs)})
            assert info["infant_0"]["outcomes"] == 0, (shown, inner.task.step_count)


@pytest.mark.parametrize("kw", [{"prepare": -0.1}, {"prepare": 0.75}, {"prepare": "half"},
                                {"prepare_at_s": -1.0}])
def test_bad_prepare_settings_raise(kw):
    with pytest.raises(Exception, match="ImitationController"):
        ImitationController(**kw)
