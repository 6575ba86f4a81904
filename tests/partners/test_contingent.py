"""ContingentCaregiver answers the learner's cues with the configured delay and probability;
still and non-contingent modes; ReplayCaregiver plays a stream back bit for bit, whatever the
learner does (issue 19)."""

from dataclasses import dataclass

import mujoco
import numpy as np
import pytest

from mimo_social.body.actuation.positional import positional_controls
from mimo_social.body.joint_groups import GAZE_JOINTS, RIGHT_SHOULDER_ELBOW, both_arms_joints, \
    held_posture
from mimo_social.body.postures import posture_joints
from mimo_social.core.env import MimoParallelEnv
from mimo_social.core.kinematics import LookAt, reach_sites
from mimo_social.core.task import Task, TaskOptions
from mimo_social.core.world import AgentSetup
from mimo_social.envs import mirror_v0
from mimo_social.partners import (ContingentCaregiver, ReplayCaregiver, ScriptedPartners,
                                  learner_cues, load_stream, save_stream)
from mimo_social.partners.base import zero_action
from mimo_social.partners.contingent import look_at_point
from mimo_social.partners.cues import HAPPY, NEUTRAL
from mimo_social.tasks.common import face_to_face
from mimo_social.tasks.dyad import clear_distance, held_angles, tables_of
from mimo_social.tasks.social_touch.task import SITTING_DEG
from mimo_social.util.checks import ConfigError

ADULT = {"body": "adult", "posture": "kneeling"}
ADULT_POS = dict(ADULT, actuation="positional")


# -- a small face-to-face test task: both agents' heads, eyes and arms have motors -------------
@dataclass(frozen=True)
class FaceOptions(TaskOptions):
    task = "face_test"
    distance: float = 0.45
    lean: float = 0.0


class FaceTask(Task):
    """The learner sits (positional motors on head, eyes and arms); the caregiver (infant
    sitting, adult kneeling, leaning ``lean`` degrees) faces it ``distance`` m away, with
    motors on head, eyes and arms; expressions on, no senses but proprioception."""

    name = "face_test"
    n_agents_range = (2, 2)
    default_max_steps = 5000
    Options = FaceOptions

    def agent_defaults(self, i, settings):
        return {"posture": "sitting", "expressions": True, "vestibular": False, "vision": False}

    def _keep(self, config):
        return GAZE_JOINTS + both_arms_joints(tables_of(config))

    def _held(self, config):
        angles = held_angles(config, "sitting", posture_joints("sitting", config.body))
        if config.body != "adult":   # cross-legged (social touch's legs): the feet stay clear
            angles.update(SITTING_DEG)
        if config.body == "adult":
            angles["lower_trunk_bend"] = self.options.lean
        return held_posture(tables_of(config), keep=self._keep(config), angles=angles)

    def setup(self, i, config):
        # moved out where the two would start inside each other (sitting legs, the adult's
        # thighs): the env refuses such a start
        dist = clear_distance(self.configs, [self._held(c) for c in self.configs],
                              self.options.distance)
        pos, facing = face_to_face(i, dist)
        return AgentSetup(config, position=pos, facing=facing, frozen=self._held(config),
                          base="fixed", actuated=self._keep(config))


def face_env(partner, caregiver=None, distance=0.45, lean=0.0):
    per_agent = [{"actuation": "positional"}, dict(caregiver or {})]
    task = FaceTask(2, {"distance": distance, "lean": lean})
    penv = MimoParallelEnv(task, per_agent=per_agent)
    # the caregiver: caregiver_0 for an adult body, infant_1 for an infant
    return ScriptedPartners(penv, {penv.possible_agents[1]: partner})


class Learner:
    """Scripted learner moves: its face, where its head and eyes look, its right arm."""

    def __init__(self, env):
        self.env = env
        self.inner = env.unwrapped
        w = self.inner.world
        self.look = LookAt(w, 0)
        self.names = [w.agents[0].joint_names[j] for j in self.look.joints]
        self.scratch = mujoco.MjData(w.model)
        self.action = zero_action(env.action_space("infant_0"))

    def looking_at(self, point, face=NEUTRAL, arm=None):
        w = self.inner.world
        q = look_at_point(self.look, w.model, self.scratch, w.data.qpos, point)
        pose = dict(zip(self.names, q), **(arm or {}))
        return {"motors": positional_controls(self.inner, "infant_0", pose),
                "expression": np.int64(face)}

    def at_face(self, face=NEUTRAL, arm=None):
        w = self.inner.world
        return self.looking_at(w.data.site_xpos[w.agents[1].head_site], face, arm)

    def face_only(self, face):
        return dict(self.action, expression=np.int64(face))


def run(env, policy, steps, seed=0, after=None):
    """Steps the env with ``policy(k, learner)``; per step the learner's and the caregiver's
    faces (the world's) and the caregiver's joint angles."""
    env.reset(seed=seed)
    learner = Learner(env)
    w = env.unwrapped.world
    a1 = w.agents[1]
    faces, qs = [], []
    for k in range(steps):
        if after is not None:
            after(k)
        env.step({"infant_0": policy(k, learner)})
        faces.append((w.expression_of(0), w.expression_of(1)))
        qs.append(w.data.qpos[a1.qpos_adr].copy())
    return np.array(faces), np.array(qs)


# -- delay and probability -----------------------------------------------------------------------
def test_smile_back_follows_the_delay_and_the_probability():
    """200 smile onsets (5 steps smiling, 15 neutral): the share answered lies within the
    binomial 99.9 % interval of p = 0.6 (+-3.3 sd); each answered smile shows on the
    caregiver's face delay_steps + 1 steps after the learner's (the caregiver sees the state
    the learner's action left: one step of perception), unanswered ones never."""
    p = ContingentCaregiver(cues=("expression",), delay_s=0.1, probability=0.6,
                            duration_s=0.05)
    env = face_env(p, ADULT_POS)
    period, n = 20, 200
    faces, _ = run(env, lambda k, lr: lr.face_only(HAPPY if k % period < 5 else NEUTRAL),
                   period * n)
    assert p.delay_steps == 10 and p.duration_steps == 5
    assert [e["step"] for e in p.events] == [period * k + 1 for k in range(n)]
    answered = np.array([e["answered"] for e in p.events])
    sd = np.sqrt(0.6 * 0.4 / n)
    assert abs(answered.mean() - 0.6) < 3.3 * sd, answered.mean()
    smile_on = np.flatnonzero((faces[1:, 1] == HAPPY) & (faces[:-1, 1] != HAPPY)) + 1
    learner_on = np.arange(n) * period
    latency = smile_on - learner_on[answered]
    assert len(smile_on) == answered.sum()
    assert np.all(latency == p.delay_steps + 1), np.unique(latency)
    assert [r["event_step"] for r in p.responses] == [e["step"] for e in p.events
                                                      if e["answered"]]


def test_jitter_spreads_the_delay_and_refractory_ignores_events_while_answering():
    """delay_jitter_s: each answered smile shows delay_steps + 1 + a draw of 0..jitter_steps
    after the learner's, the draws spread over that range; refractory: a smile onset while an
    answer is pending or shown is logged ignored and not answered (without it, every one is)."""
    p = ContingentCaregiver(cues=("expression",), delay_s=0.1, delay_jitter_s=0.2,
                            probability=1.0, duration_s=0.05)
    faces, _ = run(face_env(p, ADULT_POS), lambda k, lr: lr.face_only(
        HAPPY if k % 50 < 5 else NEUTRAL), 50 * 40)
    assert p.jitter_steps == 20 and len(p.responses) == 40
    latency = np.array([e["due"] - e["step"] for e in p.events])
    assert latency.min() >= 10 and latency.max() <= 30 and len(np.unique(latency)) > 8
    smile_on = np.flatnonzero((faces[1:, 1] == HAPPY) & (faces[:-1, 1] != HAPPY)) + 1
    assert np.array_equal(smile_on - 50 * np.arange(40), latency + 1)
    counts = {}
    for refractory in (False, True):
        p = ContingentCaregiver(cues=("expression",), delay_s=0.1, probability=1.0,
                                duration_s=0.3, refractory=refractory)
        run(face_env(p, ADULT_POS), lambda k, lr: lr.face_only(HAPPY if k % 4 < 2 else 0), 400)
        counts[refractory] = (len(p.events), len(p.responses),
                              sum(bool(e.get("ignored")) for e in p.events))
    # without: every onset answered (the last ones' answers due after the run)
    assert counts[False][0] == 100 and counts[False][1] >= 97 and counts[False][2] == 0
    events, responses, ignored = counts[True]
    assert events == 100 and responses + ignored == 100 and responses <= 400 // 40 + 1


def test_probability_zero_and_one():
    for prob, expected in ((0.0, 0), (1.0, 10)):
        p = ContingentCaregiver(cues=("expression",), delay_s=0.0, probability=prob,
                                duration_s=0.05)
        faces, _ = run(face_env(p), lambda k, lr: lr.face_only(HAPPY if k % 20 < 5 else 0), 200)
        assert len(p.events) == 10 and len(p.responses) == expected
        assert (faces[:, 1] == HAPPY).any() == bool(expected)


def test_copy_face_copies_the_learners_expression():
    p = ContingentCaregiver(cues=("expression",), face="copy", delay_s=0.0, duration_s=0.1)
    shown = [2, 3, 5]
    faces, _ = run(face_env(p), lambda k, lr: lr.face_only(shown[k // 30 % 3] if k % 30 < 10
                                                           else NEUTRAL), 90)
    for j, face in enumerate(shown):
        assert faces[30 * j + 1, 1] == face, faces[30 * j: 30 * j + 3]


# -- gaze and touch --------------------------------------------------------------------------------
@pytest.mark.parametrize("caregiver", [ADULT, ADULT_POS, {}], ids=["adult_pd", "adult_pos",
                                                                      "infant"])
def test_caregiver_looks_where_the_learner_looks_then_back_at_its_face(caregiver):
    """The learner looks at the caregiver's face, then at a floor point beside it (steps
    100-250): after the delay the caregiver's own line of sight meets the floor within 5 cm of
    the learner's point; between responses it looks at the learner's face (within the 10-degree
    cue threshold)."""
    floor = np.array([0.3, 0.25, 0.0])
    p = ContingentCaregiver(cues=("gaze",), delay_s=0.2, duration_s=1.5)
    env = face_env(p, caregiver)
    seen = {}

    def policy(k, lr):
        if 100 <= k < 250:
            return lr.looking_at(floor)
        return lr.at_face()

    def after(k):
        inner = env.unwrapped
        care = inner.possible_agents[1]
        seen[k] = (learner_cues(inner, care, "infant_0"),
                   learner_cues(inner, "infant_0", care))

    run(env, policy, 300, after=after)
    assert len(p.events) == 1 and p.events[0]["cue"] == "gaze"
    ev = p.events[0]["step"]
    assert p.responses[0]["step"] == ev + p.delay_steps
    assert seen[95][0].gaze_on_face, seen[95][0].gaze_angle_deg      # mutual gaze before
    cg, lr = seen[240]
    assert cg.gaze_point is not None and lr.gaze_point is not None
    assert np.linalg.norm(cg.gaze_point[:2] - lr.gaze_point[:2]) < 0.05, (cg.gaze_point,
                                                                          lr.gaze_point)


def _reach_pose(env, target_geom, depth=0.04):
    """The learner's right shoulder and elbow angles that bring its palm toward the point
    ``depth`` m inside ``target_geom`` from its surface point nearest the palm (aimed at the
    geom's centre, an adult's thigh is out of an infant's reach)."""
    w = env.unwrapped.world
    m, d = w.model, w.data
    a0 = w.agents[0]
    idx = [a0.joint_names.index(n) for n in RIGHT_SHOULDER_ELBOW]
    g = m.geom(target_geom).id
    ends = np.zeros(6)
    mujoco.mj_geomDistance(m, d, g, m.geom("infant_0/right_palm").id, 1.0, ends)
    inward = d.geom_xpos[g] - ends[:3]
    point = ends[:3] + depth * inward / np.linalg.norm(inward)
    s = mujoco.MjData(m)
    s.qpos[:] = d.qpos
    reach_sites(m, s, a0.qpos_adr[idx], a0.dof_adr[idx], *a0.joint_range[idx].T,
                int(a0.palm_sites[0]), point)
    return {n: float(s.qpos[a0.qpos_adr[k]]) for n, k in zip(RIGHT_SHOULDER_ELBOW, idx)}


def test_touch_is_answered_with_a_pat_toward_the_touching_arm():
    """The learner reaches for the kneeling adult's thigh (asked 0.3 m apart, moved out to 0.33 m
    where the learner's shin would start inside the thigh; the adult leaning 15 degrees): the
    touch onset is an event, answered after the delay with a pat whose palm comes at least 15
    cm nearer the learner's touching arm than it starts."""
    p = ContingentCaregiver(cues=("touch",), delay_s=0.2, duration_s=1.0)
    env = face_env(p, ADULT_POS, distance=0.3, lean=15.0)
    env.reset(seed=0)
    reach = _reach_pose(env, "caregiver_0/left_upper_leg")
    w = env.unwrapped.world
    arm_geom = w.model.geom("infant_0/right_lower_arm").id
    dist = []

    def policy(k, lr):
        return lr.at_face(arm=reach if 50 <= k < 200 else None)

    def after(k):
        palms = w.data.site_xpos[w.agents[1].palm_sites]
        dist.append(np.linalg.norm(palms - w.data.geom_xpos[arm_geom], axis=1).min())

    run(env, policy, 220, after=after)
    touches = [e for e in p.events if e["cue"] == "touch"]
    assert touches, "no touch onset"
    first = p.responses[0]
    assert first["cue"] == "touch" and first["step"] == touches[0]["step"] + p.delay_steps
    start = first["step"]
    assert min(dist[start:start + p.duration_steps]) < dist[start] - 0.15, \
        (dist[start], min(dist[start:start + p.duration_steps]), p.pat_misses)


# -- replay -------------------------------------------------------------------------------------
def _smile_and_look(k, lr):
    face = HAPPY if k % 40 < 10 else NEUTRAL
    if 60 <= k < 120:
        return lr.looking_at(np.array([0.3, -0.2, 0.0]), face)
    return lr.at_face(face)


def _other_learner(k, lr):
    face = HAPPY if k % 25 < 3 else 4
    if 30 <= k < 70:
        return lr.looking_at(np.array([0.25, 0.3, 0.0]), face)
    return lr.at_face(face)


@pytest.mark.parametrize("caregiver", [ADULT, ADULT_POS], ids=["adult_pd", "adult_pos"])
def test_replay_reproduces_the_stream_whatever_the_learner_does(caregiver, tmp_path):
    steps = 150
    live = ContingentCaregiver(delay_s=0.1, probability=0.8, duration_s=0.4)
    _, q_live = run(face_env(live, caregiver), _smile_and_look, steps, seed=3)
    stream = live.stream
    assert stream["motors"].shape[0] == steps and stream["motors"].dtype == np.float32
    assert len(live.responses) >= 3
    path = save_stream(tmp_path / "caregiver", stream)
    loaded = load_stream(path)
    for key in ("motors", "expression"):
        np.testing.assert_array_equal(loaded[key], stream[key])
    # the same learner: the same actions and the same caregiver trajectory, bit for bit
    replay = ReplayCaregiver(path)
    _, q_same = run(face_env(replay, caregiver), _smile_and_look, steps, seed=11)
    np.testing.assert_array_equal(q_same, q_live)
    # another learner: the live caregiver would act otherwise, the replay does not
    other_live = ContingentCaregiver(delay_s=0.1, probability=0.8, duration_s=0.4)
    run(face_env(other_live, caregiver), _other_learner, steps, seed=3)
    assert not np.array_equal(other_live.stream["motors"], stream["motors"])
    got = []

    class Tap(ReplayCaregiver):
        def act(self, env, agent, observation):
            a = super().act(env, agent, observation)
            got.append(a)
            return a

    run(face_env(Tap(stream), caregiver), _other_learner, steps)
    np.testing.assert_array_equal(np.stack([a["motors"] for a in got]), stream["motors"])
    np.testing.assert_array_equal([a["expression"] for a in got], stream["expression"])


# -- still and non-contingent -----------------------------------------------------------------------
@pytest.mark.parametrize("caregiver", [ADULT, ADULT_POS, {}], ids=["adult_pd", "adult_pos",
                                                                      "infant"])
def test_still_face_neutral_and_motionless(caregiver):
    """Interactive (the learner smiles and looks at the floor for 0.6 s, then at the caregiver
    for 0.6 s), switched to still 5 steps into the caregiver's first gaze response (its head
    turning) while the learner goes on: the caregiver's face is neutral from the switch on,
    nothing is answered, and from 0.5 s after the switch (the turn under way stops: up to 5
    degrees on) its joints move less than 0.5 degree (measured 0.03-0.12)."""
    p = ContingentCaregiver(delay_s=0.1, duration_s=0.5)
    env = face_env(p, caregiver)
    switched = []

    def after(k):
        if not switched and any(r["cue"] == "gaze" and k == r["step"] + 5 for r in p.responses):
            switched.append(k)
            p.set_mode("still")

    def policy(k, lr):
        face = HAPPY if k % 30 < 10 else NEUTRAL
        if k % 120 < 60:
            return lr.looking_at(np.array([0.3, 0.25, 0.0]), face)
        return lr.at_face(face)

    faces, qs = run(env, policy, 300, after=after)
    switch = switched[0]
    assert p.modes == [(0, "interactive"), (switch, "still")]
    assert (faces[:switch, 1] == HAPPY).any()
    assert np.all(faces[switch:, 1] == NEUTRAL)
    assert all(r["step"] < switch for r in p.responses)
    moved = np.degrees(np.abs(qs[switch:] - qs[switch]).max())
    held = qs[switch + 50:]
    drift = np.degrees(np.abs(held - held[0]).max())
    assert moved > 0.5 and drift < 0.5, (moved, drift)
    if caregiver.get("actuation") == "positional":      # constant targets
        still = p.stream["motors"][switch:]
        np.testing.assert_array_equal(still, np.broadcast_to(still[0], still.shape))


def test_non_contingent_keeps_the_measured_rate():
    """An interactive period (20 s, a smile every 0.5 s answered with p = 0.5) measures the
    response rate; the non-contingent responses that follow (20 s, the learner still smiling)
    keep that rate (within the Poisson 99.9 % interval) and answer no event."""
    p = ContingentCaregiver(cues=("expression",), delay_s=0.0, probability=0.5,
                            duration_s=0.05)
    switch = 2000
    run(face_env(p), lambda k, lr: lr.face_only(HAPPY if k % 50 < 5 else NEUTRAL), 2 * switch,
        after=lambda k: k == switch and p.set_mode("non_contingent"))
    answered = sum(r["step"] < switch for r in p.responses)
    assert p.measured_rates["expression"] == pytest.approx(answered / 20.0)
    during = [r for r in p.responses if r["step"] >= switch]
    assert all(r["event_step"] is None and r["mode"] == "non_contingent" for r in during)
    assert all(e["step"] < switch for e in p.events)
    expected = answered   # the same rate over as long a period
    assert abs(len(during) - expected) < 3.3 * np.sqrt(expected), (len(during), expected)


def test_non_contingent_timer_ignores_the_learner():
    """With a given rate, two learners (one smiling and looking about, one still) get the
    caregiver's responses at the same steps."""
    runs = []
    for policy in (_smile_and_look, lambda k, lr: lr.at_face()):
        p = ContingentCaregiver(cues=("expression", "gaze"), mode="non_contingent",
                                rate_hz=2.0, duration_s=0.2)
        run(face_env(p, ADULT_POS), policy, 300, seed=5)
        runs.append([(r["step"], r["cue"]) for r in p.responses])
        assert not p.events
    assert runs[0] == runs[1] and len(runs[0]) > 5


# -- settings and bodies -------------------------------------------------------------------------
@pytest.mark.parametrize("kwargs, words", [
    ({"cues": ("smell",)}, "cues"), ({"cues": "gaze"}, "cues"), ({"cues": ()}, "cues"),
    ({"delay_s": -1}, "delay_s"), ({"probability": 1.5}, "probability"),
    ({"duration_s": 0}, "duration_s"), ({"face": "frown"}, "face"),
    ({"rest_face": "grumpy"}, "rest_face"), ({"mode": "sleepy"}, "mode"),
    ({"rate_hz": -2}, "rate_hz"), ({"rate_hz": {"smell": 1}}, "rate_hz"),
    ({"learner": 3}, "learner"), ({"delay_jitter_s": -0.1}, "delay_jitter_s"),
    ({"refractory": "yes"}, "refractory")])
def test_bad_settings_are_named(kwargs, words):
    with pytest.raises(ConfigError, match=words):
        ContingentCaregiver(**kwargs)


def test_bad_uses_are_named():
    p = ContingentCaregiver()
    with pytest.raises(ConfigError, match="mode"):
        p.set_mode("asleep")
    # the mirror task holds every joint: no gaze or touch response is possible
    env = mirror_v0.scripted_env(partner=ContingentCaregiver(cues=("gaze",)),
                                 per_agent=[{"vision": False}, ADULT])
    with pytest.raises(ValueError, match="head_swivel"):
        env.reset(seed=0)
    env = face_env(ContingentCaregiver(mode="non_contingent"))
    with pytest.raises(ValueError, match="rate_hz"):
        env.reset(seed=0)
    with pytest.raises(ConfigError, match="stream"):
        ReplayCaregiver({"motors": np.zeros((3, 2))})
    bad = {"motors": np.zeros((3, 2), np.float32), "expression": np.zeros(3, np.int64)}
    with pytest.raises(ValueError, match="motors"):
        face_env(ReplayCaregiver(bad)).reset(seed=0)
    with pytest.raises(RuntimeError, match="reset"):
        ContingentCaregiver().act(None, "caregiver_0", None)


def test_expression_only_in_the_mirror_task_with_the_adult():
    """In a task that holds every joint (mirror, the kneeling adult) the caregiver still
    answers smiles with its face; its stream has no motors."""
    p = ContingentCaregiver(cues=("expression",), delay_s=0.05, duration_s=0.1)
    env = mirror_v0.scripted_env(partner=p, per_agent=[{"vision": False}, ADULT])
    env.reset(seed=0)
    for k in range(40):
        env.step({"infant_0": {"motors": np.zeros(0, np.float32),
                               "expression": np.int64(HAPPY if k >= 10 else NEUTRAL)}})
    assert [r["event_step"] for r in p.responses] == [11]
    assert p.stream["motors"].shape == (40, 0)
    assert p.stream["expression"][16] == HAPPY and p.stream["expression"][15] == NEUTRAL


def test_pickled_mid_episode_continues_exactly():
    import pickle
    p = ContingentCaregiver(delay_s=0.1, probability=0.7, duration_s=0.3)
    env = face_env(p, ADULT)
    env.reset(seed=2)
    lr = Learner(env)
    for k in range(60):
        env.step({"infant_0": _smile_and_look(k, lr)})
    copy = pickle.loads(pickle.dumps(env))
    streams = []
    for e in (env, copy):
        lr = Learner(e)
        for k in range(60, 140):
            e.step({"infant_0": _smile_and_look(k, lr)})
        streams.append(e.partners["caregiver_0"].stream["motors"])
    np.testing.assert_array_equal(streams[0], streams[1])


def test_replay_offset_and_end():
    stream = {"motors": np.arange(12, dtype=np.float32).reshape(3, 4) / 10,
              "expression": np.array([0, 1, 2]), "dt": 0.01}
    env = mirror_v0.scripted_env(partner=ReplayCaregiver(dict(stream, motors=np.zeros((3, 0))),
                                                         offset=1),
                                 per_agent=[{"vision": False}, ADULT])
    env.reset(seed=0)
    shown = []
    for _ in range(4):
        env.step({"infant_0": {"motors": np.zeros(0, np.float32), "expression": np.int64(0)}})
        shown.append(env.unwrapped.world.expression_of(1))
    assert shown == [1, 2, 2, 2]              # from row 1; past the end the last row holds
    strict = ReplayCaregiver(dict(stream, motors=np.zeros((3, 0))), past_end="error")
    env = mirror_v0.scripted_env(partner=strict, per_agent=[{"vision": False}, ADULT])
    env.reset(seed=0)
    with pytest.raises(RuntimeError, match="past_end"):
        for _ in range(4):
            env.step({"infant_0": {"motors": np.zeros(0, np.float32),
                                   "expression": np.int64(0)}})
    with pytest.raises(ConfigError, match="offset"):
        ReplayCaregiver(stream, offset=3)
    assert ReplayCaregiver.load_stream is load_stream
