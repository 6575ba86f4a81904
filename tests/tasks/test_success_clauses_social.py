"""One test per clause of the success definitions of social_touch, joint_attention, still_face,
contingency and imitation (each task's `success` and `termination` rows, docs/tasks.md), for
the clauses that the tasks' own test files let through: each was removed (or altered) from the
task's code in a scratch copy and the tests run (issue 30). "existing" names a test of the
task's own files that fails with the clause removed; the tests here are named after the clause
they guard and fail without it. States are physical (postures by IK, scripted gazes, faces and
arm poses, recorded acts) and judged through the env's step or the task's own hooks.

social_touch (the first contact of the toucher's right arm with the partner decides):
  - the first contact decides, later ones never change it: existing (test_social_touch.py, the
    sweep over a wrong part); success stays true: existing (the same test);
  - the contact of the right arm, upper arm to fingertips, decides (a forearm contact too):
    ``test_social_touch_the_forearm_on_the_target_is_a_wrong_touch``;
  - it must be the hand: the same test (the forearm on the target, its contact normal within
    120 deg of the forearm's -y, is wrong);
  - on the target part: existing (the wrong first touch); a hand target includes its fingers:
    ``test_social_touch_a_touch_of_the_fingers_alone_is_a_touch_of_the_hand``;
  - not the back of the hand: existing (test_the_back_of_the_hand_does_not_count);
  - parts touched in the same step as the target do not spoil it:
    ``test_social_touch_another_part_touched_with_the_target_does_not_spoil_it``;
  - only contacts with the partner count: existing (test_zero_and_random_actions_fail: the
    arm's other contacts then break the task's lookup of the partner's parts);
  - termination on the deciding contact, success or wrong, with ``end_on_touch``: existing.
  (Contacts at a positive distance cannot be told apart: every geom margin is 0, so MuJoCo
  reports none; dropping the task's ``dist <= 0`` filter changes nothing.)

joint_attention (per agent: the share of the steps with a target on which its gaze was on it,
after at least 1 s of such steps):
  - at least 1 s of steps with a target: existing (test_success_needs_the_share_...) for the
    second, ``test_joint_attention_only_steps_with_a_target_count_for_the_second_and_the_share``
    for its counting only steps with a target;
  - the share >= ``success_share``: existing (the same test and random/zero); the share over
    the steps with a target only: the ``..._for_the_second_and_the_share`` test;
  - gaze on the target = the toy looked at is the target: existing; a toy is looked at within
    ``margin_deg`` of its edge:
    ``test_joint_attention_a_gaze_within_the_margin_of_the_toy_is_on_it``;
  - the follower's target is the toy the other looks at, the leader's its instruction:
    existing (test_shared_reward_..., test_two_learners_leader_mode_...);
  - no termination: existing (the env runs to its truncation in the scripted tests).

still_face (the engaged steps reach ``success_fraction`` of the interaction and reunion steps):
  - an engaged step needs the learner's gaze on the face, its smile and the caregiver's smile:
    ``test_still_face_engagement_needs_the_gaze_the_smile_and_the_caregivers_smile`` (one run
    per clause);
  - the still phase does not count: its steps are never engaged because the task holds the
    caregiver's face neutral (existing: test_still_phase_caregiver_face_neutral_...; removing
    the task's ``phase != 1`` clauses changes nothing while that holds); the denominator is the
    interactive steps: existing (the scripted infant's run) and
    ``test_still_face_success_is_the_engaged_share_of_the_interactive_steps``;
  - ``success_fraction`` and "reach" (>=, from that step on): the same share test;
  - no termination: existing (every scripted run lasts its phases).

contingency (the shared-smile steps reach ``success_fraction`` of ``max_steps`` and at least
``success_match`` of the learner's smiling steps):
  - a shared step needs the learner's smile (existing: the detector's live run) and the
    caregiver's: ``test_contingency_a_shared_smile_needs_both_faces_happy``;
  - and the learner's gaze on the face (``gaze_free``, the default):
    ``test_contingency_a_shared_smile_needs_the_learners_gaze_on_the_face``;
  - ``success_fraction`` of ``max_steps``, "reach":
    ``test_contingency_success_is_the_shared_share_of_max_steps``;
  - ``success_match`` of the smiling steps shared:
    ``test_contingency_success_needs_the_learners_smiles_shared``;
  - no termination: existing. The gaze measure of a learner that looks differs from one that
    does not: test_issue30_paradigms.py (test_contingency_gaze_measure_follows_...).

imitation (the learner's act in its turn is the demonstrated action; the act ends the episode):
  - in its turn only, the box presented anew: existing (test_a_push_during_the_demonstration_...);
  - its first act is its answer: ``test_imitation_several_outcomes_at_once_...`` (a later act
    changes nothing) and ``test_imitation_the_learners_act_ends_the_episode``;
  - the act is the demonstrated action: existing (test_reward_is_highest_for_the_demonstrated_...);
  - several outcomes at once are an act of none:
    ``test_imitation_several_outcomes_at_once_are_no_act_even_with_the_demonstrated_one``;
  - only the env's actions count: existing (test_each_outcome_fires_...);
  - the outcomes: push_box slid ``PUSH`` arm lengths away from the agent:
    ``test_imitation_push_box_is_the_box_slid_push_arm_lengths_away``; hand_raise over the head
    by the margin, not touching it:
    ``test_imitation_hand_raise_is_the_palm_over_the_head_by_the_margin_not_touching_it``;
    head_touch and clap: existing (each scripted act makes its outcome alone);
  - the act ends the episode: ``test_imitation_the_learners_act_ends_the_episode``;
  - the demonstrator's success: its first act in the demonstration phase (existing: the two
    learners' test) is its instruction:
    ``test_imitation_the_demonstrators_success_is_its_first_act_being_its_instruction``.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from mimo_social.core.kinematics import reach_sites
from mimo_social.envs import (contingency_v0, imitation_v0, joint_attention_v0, social_touch_v0,
                              still_face_v0)
from mimo_social.expressions.faces import EXPRESSIONS
from mimo_social.partners import Partner, Still
from mimo_social.partners.base import motor_action, zero_action
from mimo_social.partners.gaze import GazeAtTarget, look_angles
from mimo_social.tasks.imitation import ACTIONS
from mimo_social.tasks.imitation.controller import ImitationController
from mimo_social.tasks.imitation.demonstrator import PoseScript
from mimo_social.tasks.imitation.task import PUSH, RAISE_MARGIN
from mimo_social.tasks.social_touch.controller import reach_posture

pytestmark = pytest.mark.text_infos   # these tests read the text infos (info_text=True)

HAPPY = EXPRESSIONS.index("happy")
NO_EYES = [{"vision": False}, {}]        # no policy here reads the learner's eyes
FIXED_START = {"start_spread": 0.0, "partner_spread": 0.0, "distance_spread": 0.0}


def _zero(env):
    return {a: np.zeros(env.action_space(a).shape, np.float32) for a in env.agents}


# -- social touch ---------------------------------------------------------------------------------
#: the toucher's right arm with the elbow pointing at the partner and the hand drawn back beside
#: its face (deg: shoulder horizontal, abduction, rotation, elbow, wrist rotation, flexion,
#: ulnar, fingers): its forearm and upper arm are the part of it nearest the partner
ELBOW_FORWARD_DEG = (111.0, 130.0, -91.0, -138.0, -20.0, 0.0, 0.0, -40.0)


def _arm(agent, side):
    k = [j for j in agent.actuated_joint_idx if agent.joint_names[j].startswith(side)]
    return agent.qpos_adr[k], agent.dof_adr[k], agent.joint_range[k, 0], agent.joint_range[k, 1]


def _across(world):
    """The pairs (toucher's body, partner's body) in contact now (names without the agent)."""
    m, d = world.model, world.data
    mujoco.mj_kinematics(m, d)
    mujoco.mj_collision(m, d)
    out = set()
    for c in d.contact[:d.ncon]:
        a1, a2 = world.geom_agent[c.geom1], world.geom_agent[c.geom2]
        if {int(a1), int(a2)} == {0, 1}:
            b = [m.body(int(m.geom_bodyid[g])).name.split("/", 1) for g in (c.geom1, c.geom2)]
            b.sort()
            out.add((b[0][1], b[1][1]))
    return out


def _touch_step(env, q=None):
    """The toucher's right arm at angles ``q`` (None: as it is), held still, then one step with
    zero commands: (reward, terminated, the toucher's info)."""
    w = env.world
    if q is not None:
        a = w.agents[0]
        w.data.qpos[a.qpos_adr[a.actuated_joint_idx]] = q
    w.data.qvel[:] = 0.0
    mujoco.mj_forward(w.model, w.data)
    _, r, term, _, info = env.step(_zero(env))
    return r["infant_0"], term["infant_0"], info["infant_0"]


@pytest.mark.parametrize("approach", [(0.0, -1.0, 0.0), (1.0, -0.5, 0.0)])
def test_social_touch_the_forearm_on_the_target_is_a_wrong_touch(approach):
    """Clauses 'the hand' and 'the right arm decides': the toucher's elbow held out at the
    partner, its hand back by its face; the partner's left hand brought (IK, 1 mm steps) onto
    the toucher's forearm from ``approach`` until they touch. That first contact is the target
    (left_hand) but made by the forearm (and the elbow's end of the upper arm), not the hand: a
    wrong touch, no success, the episode over. From the front-side the contact normal lies
    within 120 deg of the forearm's own -y (the axis that is the palm's normal on the hand):
    the back-of-the-hand rule alone would let that contact count."""
    env = social_touch_v0.parallel_env(task_options={**FIXED_START, "target": "left_hand"})
    env.reset(seed=0)
    w = env.world
    m, d = w.model, w.data
    toucher, partner = w.agents
    q, _, lo, hi = _arm(toucher, "right")
    d.qpos[q] = np.clip(np.deg2rad(ELBOW_FORWARD_DEG), lo, hi)
    assert not _across(w)
    forearm = d.xipos[m.body("infant_0/right_lower_arm").id].copy()
    hand = d.xpos[m.body("infant_0/right_hand").id]
    assert hand[0] < forearm[0] - 0.02                # the hand is drawn back, behind the forearm
    start = d.qpos.copy()
    direction = np.array(approach) / np.linalg.norm(approach)
    for off in np.arange(0.15, -0.02, -0.001):
        d.qpos[:] = start
        err = reach_sites(m, d, *_arm(partner, "left")[:4], int(partner.palm_sites[1]),
                          forearm + off * direction, 300)
        touching = _across(w)
        if touching:
            break
    assert err < 1e-3
    assert touching and {mine for mine, _ in touching} <= {"right_lower_arm", "right_upper_arm"}
    assert {theirs for _, theirs in touching} <= {"left_hand", "left_fingers"}
    r, term, info = _touch_step(env)
    assert info["first_touch"] and set(info["first_touch"]) <= {"left_hand", "left_fingers"}
    assert info["wrong_touch"] and not info["is_success"] and term
    assert r < 0.0


def test_social_touch_a_touch_of_the_fingers_alone_is_a_touch_of_the_hand():
    """Clause 'a hand target includes its fingers': the toucher's finger pads on the partner's
    fingers alone (target left_hand) are a success."""
    env = social_touch_v0.parallel_env(task_options={"target": "left_hand"})
    env.reset(seed=0)
    q, dist, worst = reach_posture(env.world, 0, 1, "left_fingers", depth=0.004)
    assert dist < 0.0 and worst < 1e-3
    r, term, info = _touch_step(env, q)
    assert info["first_touch"] == ["left_fingers"] == info["touched_parts"]
    assert info["is_success"] and not info["wrong_touch"] and term and r > 90.0


def test_social_touch_another_part_touched_with_the_target_does_not_spoil_it():
    """Clause 'parts touched in the same step as the target do not spoil it': the toucher's hand
    pressed onto the partner's shin where it lies against the thigh touches both in one step:
    a success when the shin is the target."""
    env = social_touch_v0.parallel_env(task_options={"target": "left_lower_leg"})
    env.reset(seed=0)
    q, dist, _ = reach_posture(env.world, 0, 1, "left_lower_leg", depth=0.005)
    assert dist < 0.0
    r, term, info = _touch_step(env, q)
    assert info["first_touch"] == ["left_lower_leg", "left_upper_leg"]
    assert info["is_success"] and not info["wrong_touch"] and term and r > 90.0


# -- joint attention ------------------------------------------------------------------------------
JA_STILL = np.zeros(9, np.float32)


def test_joint_attention_only_steps_with_a_target_count_for_the_second_and_the_share():
    """Clauses 'after at least 1 s of steps with a target' and 'the share of the steps on which
    it had one': two learners ("shared": each one's target is the toy the other looks at) look
    at each other for 2 s (no toy, no target), then both at toy 2. Success comes on the 100th
    step with a target (1 s), not before, though the episode is then 3 s old; and it comes at
    all, though the on-target steps are then under a third of the episode's."""
    env = joint_attention_v0.parallel_env(vision=False, task_options={"two_learners": "shared"})
    env.reset(seed=3)
    inner = env.unwrapped
    for _ in range(200):
        _, _, _, _, info = env.step({a: JA_STILL for a in env.agents})
        assert all(i["target"] == -1 and not i["is_success"] for i in info.values())
    gazers = {a: GazeAtTarget(hold_s=(99, 99), head_share=1.0) for a in env.possible_agents}
    for a, g in gazers.items():
        g.reset(inner, a, np.random.default_rng(0))
        g.target = 2
    with_target = {a: 0 for a in env.possible_agents}
    verdicts = []
    for _ in range(150):
        _, _, term, _, info = env.step({a: g.act(inner, a, None) for a, g in gazers.items()})
        for a, i in info.items():
            with_target[a] += i["target"] >= 0
            if with_target[a] < 100:
                assert not i["is_success"], (a, with_target[a])
            verdicts.append((a, with_target[a], i["is_success"], i["on_target_fraction"]))
        assert not any(term.values())
    for a, i in info.items():
        assert with_target[a] >= 100 and i["target"] == 2 == i["looked_at"]
        assert i["is_success"] and i["on_target_fraction"] > 0.8
        first = min(n for b, n, ok, _ in verdicts if b == a and ok)
        assert first == 100, (a, first)


def _look_at(env, agent, body, swivel_deg=0.0):
    """Set ``agent``'s head and eye joints to look at ``body``, its head then turned
    ``swivel_deg`` further (to its left)."""
    w = env.world
    a = w.agents[env.possible_agents.index(agent)]
    angles = look_angles(env, agent, "body", int(body))
    angles["head_swivel"] += np.deg2rad(swivel_deg)
    for name, value in angles.items():
        w.data.qpos[a.qpos_adr[a.joint_names.index(name)]] = value
    w.data.qvel[:] = 0.0
    mujoco.mj_forward(w.model, w.data)


def _gaze_verdict(env):
    """The task's verdict on the world as it is (one step's hooks, nothing moves): infant_0's
    info."""
    env.task.rewards(env)
    return env.task.terminations(env)[1][0]


def test_joint_attention_a_gaze_within_the_margin_of_the_toy_is_on_it():
    """Clause 'gaze on its target' (a toy counts as looked at within ``margin_deg`` of its
    edge): infant_1 looks at toy 2; infant_0's head is turned off toy 2 until, with margin 0,
    it no longer looks at it: with the default margin (5 deg) the same gaze is on it, shared;
    3 deg further still, and 6 deg further not."""
    envs = {}
    for margin in (0.0, 5.0):
        env = joint_attention_v0.parallel_env(vision=False, task_options={
            "two_learners": "shared", "margin_deg": margin})
        env.reset(seed=3)
        envs[margin] = env
    assert joint_attention_v0.parallel_env().task.options.margin_deg == 5.0
    toy = envs[0.0].task.toy_bodies[2]
    for swivel in np.arange(0.0, 20.0, 0.25):
        for env in envs.values():
            _look_at(env, "infant_1", toy)
            _look_at(env, "infant_0", toy, swivel)
        if _gaze_verdict(envs[0.0])["looked_at"] != 2:
            break
    edge = _gaze_verdict(envs[5.0])
    assert edge["looked_at"] == 2 and edge["target"] == 2 and edge["shared"]
    assert _gaze_verdict(envs[0.0])["looked_at"] == -1
    for extra, on in ((3.0, True), (6.0, False)):
        _look_at(envs[5.0], "infant_0", toy, swivel + extra)
        assert (_gaze_verdict(envs[5.0])["looked_at"] == 2) is on, extra


# -- still face and contingency: scripted faces and gazes ----------------------------------------
class Looks(GazeAtTarget):
    """Turns its head and eyes to ``target`` (a body or site name) with its own motors and keeps
    them there; shows ``face(env)`` (an expression id; default: happy)."""

    def __init__(self, target: str, face=lambda env: HAPPY):
        super().__init__(targets=[target], hold_s=(3600.0, 3600.0), head_share=1.0)
        self.face = face

    def act(self, env, agent, observation):
        return dict(super().act(env, agent, observation), expression=np.int64(self.face(env)))


class Smiles(Partner):
    """A caregiver that keeps its body still and smiles all the time (where the task lets it)."""

    def act(self, env, agent, observation):
        return dict(zero_action(env.action_space(agent)), expression=np.int64(HAPPY))


def _episode(env, learner, record=lambda inner, info: info):
    """One episode of a one-learner env (seed 0), ``infant_0`` driven by ``learner``: per step,
    ``record(inner env, the learner's info)`` (by default the info itself)."""
    obs, _ = env.reset(seed=0)
    inner = env.unwrapped
    learner.reset(inner, "infant_0", np.random.default_rng(0))
    out = []
    while env.agents:
        obs, _, _, _, info = env.step({"infant_0": learner.act(inner, "infant_0", obs["infant_0"])})
        out.append(record(inner, info["infant_0"]))
    return out


# -- still face -----------------------------------------------------------------------------------
#: 50 interaction, 30 still-face and 50 reunion steps: 100 interactive steps of 130
SF_PHASES = (0.5, 0.3, 0.5)
FACE = "caregiver_0/head_centre"


def _still_face(learner, caregiver=None, **options):
    env = still_face_v0.scripted_env(caregiver if caregiver is not None else Smiles(),
                                     task_options={"phases_s": SF_PHASES, "phase_jitter": 0.0,
                                                   **options},
                                     per_agent=NO_EYES)
    return _episode(env, learner)


def test_still_face_engagement_needs_the_gaze_the_smile_and_the_caregivers_smile():
    """Clauses of an engaged step: the learner looks at the caregiver's face, the learner
    smiles, the caregiver smiles. Against a caregiver that smiles whenever the task lets it: a
    learner that looks at its face and smiles is engaged on most interactive steps and
    succeeds; one that looks without smiling, one that smiles at its own hand, and the looking,
    smiling one in front of a caregiver that never smiles are never engaged and fail (the
    clause on the share of the learner's smiling engaged off here: its own test)."""
    both = _still_face(Looks(FACE), success_match=0.0)
    last = both[-1]
    assert last["interactive_steps"] == 100 and last["engaged_steps"] >= 60 and last["is_success"]
    assert not any(i["engaged"] for i in both if i["phase"] == 1)   # the still face is neutral
    runs = {"no smile": _still_face(Looks(FACE, face=lambda env: 0), success_match=0.0),
            "looks away": _still_face(Looks("infant_0/right_hand"), success_match=0.0),
            "caregiver neutral": _still_face(Looks(FACE), caregiver=Still(), success_match=0.0)}
    for name, steps in runs.items():
        last = steps[-1]
        assert last["engaged_steps"] == 0 and not any(i["is_success"] for i in steps), name
    assert runs["no smile"][-1]["gaze_interaction"] >= 0.5
    assert runs["looks away"][-1]["smile_interaction"] == 1.0
    assert runs["looks away"][-1]["gaze_interaction"] == 0.0
    neutral = runs["caregiver neutral"][-1]
    assert neutral["smile_interaction"] == 1.0 and neutral["gaze_interaction"] >= 0.5


@pytest.mark.parametrize("fraction", [0.3, 0.5])
def test_still_face_success_is_the_engaged_share_of_the_interactive_steps(fraction):
    """Clause 'the engaged steps reach success_fraction of the interaction and reunion steps'
    (100 here; the 30 still-face steps not counted): ``is_success`` turns True on the step on
    which the engaged steps reach ceil(fraction x 100), not one step before (the clause on the
    share of the learner's smiling engaged off here: its own test)."""
    steps = _still_face(Looks(FACE), success_fraction=fraction, success_match=0.0)
    need = math.ceil(fraction * 100)
    assert steps[-1]["engaged_steps"] > need + 10
    for i in steps:
        assert i["is_success"] == (i["engaged_steps"] >= need), (i["engaged_steps"], need)


def test_still_face_success_needs_the_learners_smiles_engaged():
    """Clause 'at least success_match of the learner's smiling steps engaged': a learner that
    looks and smiles through the still face (30 steps smiling at a neutral face) fails at 0.7,
    one that stops smiling while the face is still (what it would see) succeeds with about the
    same engaged steps (its smile restarts a step late in reunion); the verdict is both clauses'
    on every step."""
    sober = Looks(FACE, face=lambda env: 0 if env.unwrapped.task.phase == 1 else HAPPY)
    runs = {name: _still_face(learner, success_fraction=0.5, success_match=0.7)
            for name, learner in (("smiles on", Looks(FACE)), ("sobers", sober))}
    for name, steps in runs.items():
        smiling = np.cumsum([bool(i["smiling"]) for i in steps])
        for i, n in zip(steps, smiling):
            assert i["is_success"] == (i["engaged_steps"] >= 50
                                       and i["engaged_steps"] >= 0.7 * n), name
    on, sober = runs["smiles on"][-1], runs["sobers"][-1]
    assert abs(on["engaged_steps"] - sober["engaged_steps"]) <= 2 and sober["engaged_steps"] >= 50
    assert on["smile_still"] == 1.0 and sober["smile_still"] <= 0.05   # a step late
    assert on["matched_fraction"] < 0.7 <= sober["matched_fraction"]
    assert sober["is_success"] and not on["is_success"]


# -- contingency ----------------------------------------------------------------------------------
def _returns(env):
    """A 5-step bid every 2.5 s, else the caregiver's face returned: happy while the
    caregiver's is (read from the world: a perceiving learner's face)."""
    inner = env.unwrapped
    if inner.steps % 250 < 5:
        return HAPPY
    return HAPPY if inner.world.expression_of(1) == HAPPY else 0


def _dips(env):
    """Happy but for one neutral step every 0.5 s: each dip makes a new smile onset, which the
    live caregiver answers (the reward's optimum, task table)."""
    return 0 if env.unwrapped.steps % 50 == 49 else HAPPY


class Faces(Partner):
    """A learner that shows ``face(env)``, its motors (if any) at rest; with the held gaze
    (``HELD``) it has none."""

    def __init__(self, face):
        self.face = face

    def act(self, env, agent, observation):
        return dict(zero_action(env.action_space(agent)), expression=np.int64(self.face(env)))


#: the held variant (``gaze_free=False``): the learner's head and eyes held on the face
HELD = {"gaze_free": False}


def _contingency(learner, max_steps, **options):
    """One live episode: per step, the learner's info and the two faces shown (learner,
    caregiver: happy or not)."""
    env = contingency_v0.scripted_env(max_steps=max_steps, task_options=options,
                                      per_agent=NO_EYES)
    return _episode(env, learner, lambda inner, info: (
        info, [inner.world.expression_of(i) == HAPPY for i in (0, 1)]))


def test_contingency_a_shared_smile_needs_both_faces_happy():
    """Clauses 'the learner smiles' and 'the caregiver smiles' (held gaze): a
    learner that bids with 0.2-s smiles every second shares exactly the steps on which both
    faces are happy (the caregiver's answers outlast its smiles: steps with one face happy
    alone, either one, are not shared); a learner that smiles all the time is answered once
    (1 s of 10, the caregiver answering every onset here) and fails, though it smiles on every
    step."""
    steps = _contingency(Faces(lambda env: HAPPY if env.unwrapped.steps % 100 < 20 else 0), 1000,
                         **HELD)
    shared = [i["shared"] for i, _ in steps]
    assert shared == [a and b for _, (a, b) in steps]
    assert steps[-1][0]["shared_steps"] == sum(shared) > 0
    assert any(a and not b for _, (a, b) in steps) and any(b and not a for _, (a, b) in steps)
    steps = _contingency(Faces(lambda env: HAPPY), 1000, response_probability=1.0, **HELD)
    last = steps[-1][0]
    assert all(a for _, (a, _) in steps) and last["smiling_fraction"] == 1.0
    assert 0 < last["shared_steps"] <= 110 and not last["is_success"]


def test_contingency_a_shared_smile_needs_the_learners_gaze_on_the_face():
    """Clause 'the learner's gaze on the caregiver's face' (``gaze_free``, the default: the
    learner's own head and eyes): the same bids and returned smiles, looking at the caregiver's
    face, share most of the smiling steps and succeed; looking at its own hand they share none
    and fail, though both faces are happy on many steps."""
    looks = _contingency(Looks("caregiver_0/head_centre", _returns), 500,
                         response_probability=1.0)
    assert looks[-1][0]["gaze_fraction"] > 0.8 and looks[-1][0]["matched_fraction"] > 0.85
    assert looks[-1][0]["is_success"]
    away = _contingency(Looks("infant_0/right_hand", _returns), 500, response_probability=1.0)
    assert sum(a and b for _, (a, b) in away) > 100
    assert away[-1][0]["gaze_fraction"] == 0.0 and away[-1][0]["shared_steps"] == 0
    assert not any(i["is_success"] for i, _ in away)


@pytest.mark.parametrize("max_steps, fraction", [(300, 0.1), (400, 0.2)])
def test_contingency_success_is_the_shared_share_of_max_steps(max_steps, fraction):
    """Clause 'the shared-smile steps reach success_fraction of the episode's max_steps':
    ``is_success`` turns True on the step on which they reach ceil(fraction x max_steps), not
    one step before (the learner's smiles are nearly all shared: the other clause holds)."""
    steps = _contingency(Faces(_returns), max_steps, success_fraction=fraction,
                         response_probability=1.0, **HELD)
    need = math.ceil(fraction * max_steps)
    assert steps[-1][0]["shared_steps"] > need + 10
    assert steps[-1][0]["matched_fraction"] > 0.85
    first = next(k for k, (i, _) in enumerate(steps) if i["shared_steps"] >= need)
    for k, (i, _) in enumerate(steps):
        assert i["is_success"] == (k >= first), (k, first, i["shared_steps"], need)


def test_contingency_success_needs_the_learners_smiles_shared():
    """Clause 'at least success_match of the learner's smiling steps shared': the same bids and
    returned smiles (about 0.95 of the smiling steps shared) succeed at 0.75 and fail at 0.99;
    a smile held from each bid until 0.6 s after its answer has ended shares the same steps (but
    one step an answer: the returned smile starts a step after the caregiver's), but about half its
    smiling steps are unshared: it fails at 0.75; the verdict is the clause's on every step."""
    def longer(env):
        inner = env.unwrapped
        return HAPPY if inner.steps % 250 < 192 else 0
    runs = {}
    for name, face, match in (("returns", _returns, 0.75), ("returns", _returns, 0.99),
                              ("longer", longer, 0.75)):
        steps = _contingency(Faces(face), 1000, response_probability=1.0,
                             response_jitter_s=0.0, success_match=match, **HELD)
        last = steps[-1][0]
        runs[name, match] = last
        for k, (i, _) in enumerate(steps):
            smiling = round(i["smiling_fraction"] * (k + 1))
            assert i["is_success"] == (i["shared_steps"] >= 200
                                       and i["shared_steps"] >= match * smiling), (name, k)
    assert runs["returns", 0.75]["is_success"] and not runs["returns", 0.99]["is_success"]
    assert 0.85 < runs["returns", 0.75]["matched_fraction"] < 0.99
    shared = runs["longer", 0.75]["shared_steps"], runs["returns", 0.75]["shared_steps"]
    assert min(shared) >= 200 and abs(shared[0] - shared[1]) <= 8, shared  # a step per answer
    assert runs["longer", 0.75]["matched_fraction"] < 0.75
    assert not runs["longer", 0.75]["is_success"]


# -- imitation ------------------------------------------------------------------------------------
SEVERAL = len(ACTIONS)          # the response of a step with several outcomes at once


def _imitation(demonstrated, actions=("clap", "push_box")):
    """A scripted env (the learner's eyes off) reset with the first seed that draws
    ``demonstrated``."""
    env = imitation_v0.scripted_env(per_agent=NO_EYES, task_options={"actions": list(actions)})
    for seed in range(100):
        env.reset(seed=seed)
        if env.unwrapped.task.demonstrated_action == demonstrated:
            return env
    raise AssertionError(f"{demonstrated} never drawn")


def _to_the_turn(env):
    """Zero commands through the demonstration, up to the first step of the learner's turn."""
    while not env.unwrapped.task.turn:
        _, _, term, _, info = env.step({"infant_0": np.zeros(16, np.float32)})
        assert not term["infant_0"] and info["infant_0"]["response"] == -1
    return env


def _acting(action, demonstrated, actions=("clap", "push_box")):
    """The learner (``ImitationController(action)``) in its turn, demonstrated ``demonstrated``:
    per step (learner's info, terminated) to the end of the episode, and the state (qpos) of the
    first step with the action's outcome (None: none came)."""
    env = _imitation(demonstrated, actions)
    inner = env.unwrapped
    learner = ImitationController(action=action)
    learner.reset(inner, "infant_0", np.random.default_rng(0))
    out, state = [], None
    while env.agents:
        _, _, term, _, info = env.step({"infant_0": learner.act(inner, "infant_0", None)})
        out.append((info["infant_0"], term["infant_0"]))
        if state is None and info["infant_0"]["outcomes"] >> ACTIONS.index(action) & 1:
            state = inner.world.data.qpos.copy()
    return out, state


def _judge_act(env, arms, box_shift=None):
    """The task's verdict (its hooks, nothing moves) on the learner's arms at the angles of
    state ``arms`` and its box moved ``box_shift`` (m, world x y) from where it starts its turn:
    (terminated, the learner's info)."""
    inner = env.unwrapped
    w = inner.world
    a = w.agents[0]
    k = a.qpos_adr[a.actuated_joint_idx]
    w.data.qpos[k] = arms[k]
    w.data.qvel[:] = 0.0
    if box_shift is not None:
        q = w.prop_qpos["box_0"]
        pos = w.data.qpos[q:q + 3] + (box_shift[0], box_shift[1], 0.0)
        w.place_prop("box_0", pos, w.data.qpos[q + 3:q + 7].copy())
    mujoco.mj_forward(w.model, w.data)
    inner.task.rewards(inner)
    done, infos = inner.task.terminations(inner)
    return bool(done[0]), infos[0]


def test_imitation_the_learners_act_ends_the_episode():
    """Clause 'the learner's act in its turn ends the episode' (its first act is its answer):
    the scripted learner's clap ends the episode on the step of the clap, a success."""
    steps, state = _acting("clap", "clap")
    assert state is not None
    acted = [k for k, (i, _) in enumerate(steps) if i["response"] >= 0]
    assert acted and acted[0] == len(steps) - 1            # the last step is the act
    info, term = steps[-1]
    assert term and info["response"] == ACTIONS.index("clap") and info["is_success"]
    assert not any(t for _, t in steps[:-1])
    assert 0 < info["response_step"] < 100


def test_imitation_several_outcomes_at_once_are_no_act_even_with_the_demonstrated_one():
    """Clause 'its act is the demonstrated action' with 'several outcomes on one step are an
    act of none of them': the scripted clap's hands together (recorded), judged at the start of
    the learner's turn with its box pushed away on the same step: clap and push_box at once,
    response 4, no success whether clap or push_box was demonstrated, and (clause 'the first
    act in its turn') a clap alone judged after it changes nothing; the clap alone as the first
    act is a success."""
    _, clap = _acting("clap", "clap")
    for shown in ("clap", "push_box"):
        env = _to_the_turn(_imitation(shown))
        task = env.unwrapped.task
        push = 1.5 * PUSH * task.arm[0] * task.box_forward[0]
        done, info = _judge_act(env, clap, push)
        assert info["outcomes"] == 1 << ACTIONS.index("clap") | 1 << ACTIONS.index("push_box")
        assert info["response"] == SEVERAL and not info["is_success"] and done, shown
        # its first act is its answer: the clap alone on a later step changes nothing
        done, info = _judge_act(env, clap, -push)
        assert info["outcomes"] == 1 << ACTIONS.index("clap")
        assert info["response"] == SEVERAL and not info["is_success"] and done, shown
    done, info = _judge_act(_to_the_turn(_imitation("clap")), clap)
    assert info["response"] == ACTIONS.index("clap") and info["is_success"] and done


def test_imitation_push_box_is_the_box_slid_push_arm_lengths_away():
    """Clause 'push_box: its box slid PUSH (0.15) arm lengths away from it': the learner's box,
    judged at the start of its turn (push_box demonstrated), moved 0.8 of that away, 2 of it
    sideways or 2 of it toward the learner is no act; 1.2 of it away is the act, a success."""
    env = _to_the_turn(_imitation("push_box"))
    task = env.unwrapped.task
    rest = env.unwrapped.world.data.qpos.copy()
    away, side = PUSH * task.arm[0] * task.box_forward[0], np.array([0.0, 1.0])
    side = PUSH * task.arm[0] * (side - (side @ task.box_forward[0]) * task.box_forward[0])
    for shift in (0.8 * away, 2.0 * side, -2.0 * away):
        done, info = _judge_act(env, rest, shift)
        assert info["outcomes"] == 0 and info["response"] == -1 and not done, shift
        _judge_act(env, rest, -shift)                           # back where it started
    done, info = _judge_act(env, rest, 1.2 * away)
    assert info["response"] == ACTIONS.index("push_box") and info["is_success"] and done


def _palm_over_head(env):
    """How far (m) the learner's right palm is over the top of its head (the head geom's
    bounding sphere), and the margin hand_raise asks for."""
    w = env.unwrapped.world
    m, d = w.model, w.data
    a = w.agents[0]
    top = d.geom_xpos[a.head_geom, 2] + m.geom_rbound[a.head_geom]
    return d.site_xpos[a.palm_sites[0], 2] - top, RAISE_MARGIN * m.geom_rbound[a.head_geom]


def test_imitation_hand_raise_is_the_palm_over_the_head_by_the_margin_not_touching_it():
    """Clauses of hand_raise: the right palm over the top of the head by RAISE_MARGIN head
    radii, the hand not touching the head. The scripted raise (recorded) drawn back toward the
    start of the turn until the palm is over the head's top by less than the margin is no act;
    the recorded raise is hand_raise, a success; the raise with the left hand on the head (the
    scripted head touch mirrored to the left arm) is head_touch alone."""
    actions = ("hand_raise", "head_touch")
    _, raised = _acting("hand_raise", "hand_raise", actions)
    _, touch = _acting("head_touch", "hand_raise", actions)
    env = _to_the_turn(_imitation("hand_raise", actions))
    w = env.unwrapped.world
    a = w.agents[0]
    k = a.qpos_adr[a.actuated_joint_idx]
    rest = w.data.qpos.copy()
    for t in np.linspace(1.0, 0.0, 401):
        w.data.qpos[k] = t * raised[k] + (1.0 - t) * rest[k]
        mujoco.mj_kinematics(w.model, w.data)
        over, margin = _palm_over_head(env)
        if over < 0.5 * margin:
            break
    assert 0.0 < over < margin
    done, info = _judge_act(env, w.data.qpos.copy())
    assert info["outcomes"] == 0 and info["response"] == -1 and not done
    done, info = _judge_act(env, raised)
    assert _palm_over_head(env)[0] > _palm_over_head(env)[1]
    assert info["response"] == ACTIONS.index("hand_raise") and info["is_success"] and done
    env = _to_the_turn(_imitation("hand_raise", actions))
    mirrored = raised.copy()
    for j in a.actuated_joint_idx:
        name = a.joint_names[j]
        if name.startswith("left_"):
            mirrored[a.qpos_adr[j]] = touch[a.qpos_adr[a.joint_names.index(
                name.replace("left_", "right_"))]]
    done, info = _judge_act(env, mirrored)
    assert _palm_over_head(env)[0] > _palm_over_head(env)[1]
    assert info["response"] == ACTIONS.index("head_touch") and not info["is_success"] and done


class Shows(Partner):
    """A demonstrator (the second learner) that shows ``action`` from the first step, whatever
    its instruction: the demonstrator's poses, 0.3 s each."""

    def __init__(self, action):
        self.action = action

    def reset(self, env, agent, rng):
        self.path = PoseScript(env, agent, "Shows").path(self.action)

    def act(self, env, agent, observation):
        u = PoseScript.along(self.path, env.task.step_count / 30.0)
        return motor_action(env.action_space(agent), u)


def test_imitation_the_demonstrators_success_is_its_first_act_being_its_instruction():
    """The demonstrator's clause (two learners): its first act in the demonstration phase is
    the instructed action. Instructed to clap, a clap succeeds (+1); a head touch fails
    (``wrong_reward``)."""
    results = {}
    for shown in ("clap", "head_touch"):
        env = imitation_v0.parallel_env(per_agent=[{"vision": False}, {"vision": False}],
                                        task_options={"actions": ["clap", "head_touch"],
                                                      "wrong_reward": -0.5})
        for seed in range(100):
            obs, _ = env.reset(seed=seed)
            if env.task.demonstrated_action == "clap":
                break
        assert obs["caregiver_0"]["instruction"][ACTIONS.index("clap")] == 1.0
        demo = Shows(shown)
        demo.reset(env, "caregiver_0", None)
        total = 0.0
        while env.task.step_count < env.task.demo_steps - 1:
            _, r, _, _, info = env.step({"infant_0": np.zeros(16, np.float32),
                                         "caregiver_0": demo.act(env, "caregiver_0", None)})
            total += r["caregiver_0"]
        results[shown] = (info["caregiver_0"], total)
    clap, total = results["clap"]
    assert clap["demonstration"] == ACTIONS.index("clap") and clap["is_success"] and total == 1.0
    touch, total = results["head_touch"]
    assert touch["demonstration"] == ACTIONS.index("head_touch")
    assert not touch["is_success"] and total == -0.5
