"""The vocal turn-taking paradigm: the caregiver's scheduling, the measures, the infant's rule."""

from __future__ import annotations

import numpy as np
import pytest

from mimo_social.tasks.turn_taking.infant import VocalInfant
from mimo_social.tasks.turn_taking.schedule import (ContingentSchedule, Latency, TimedSchedule,
                                                    poisson_onsets, yoked_onsets)
from mimo_social.tasks.turn_taking.turns import TurnMeasures, measure
from mimo_social.util.checks import ConfigError

DT = 0.01


def _ks(draws, cdf) -> float:
    """The Kolmogorov-Smirnov distance of ``draws`` from ``cdf``."""
    x = np.sort(np.asarray(draws, float))
    n = len(x)
    f = cdf(x)
    return float(max(np.max(np.arange(1, n + 1) / n - f), np.max(f - np.arange(n) / n)))


def _babbling(n_voc: int, on: int = 30, off: int = 220) -> list[bool]:
    """An infant that vocalises ``on`` steps then is silent ``off`` steps, ``n_voc`` times."""
    return ([True] * on + [False] * off) * n_voc


def test_the_latency_draws_follow_the_configured_lognormal():
    lat = Latency(0.7, 0.3)
    draws = lat.draw(np.random.default_rng(0), 20000)
    assert abs(draws.mean() - 0.7) < 0.01 and abs(draws.std() - 0.3) < 0.01
    assert _ks(draws, lat.cdf) < 1.36 / np.sqrt(len(draws))    # KS at 5 %
    assert Latency(0.5, 0.0).draw(np.random.default_rng(0)) == 0.5


def test_the_contingent_answers_have_the_configured_latency_and_probability():
    lat, p = Latency(0.8, 0.25), 0.7
    sched = ContingentSchedule(lat, p, 100, DT)
    sched.reset(np.random.default_rng(1))
    infant = _babbling(3000, off=400)     # 4 s of silence: every offset finds the caregiver free
    speaks = [sched.step(v) for v in infant]
    events = sched.events
    assert len(events) == 3000              # every offset eligible
    answered = [e for e in events if e["answered"]]
    share = len(answered) / len(events)
    assert abs(share - p) < 3 * np.sqrt(p * (1 - p) / len(events))
    # the latency of each answer is the drawn one, rounded to steps, from the offset step
    assert sched.onsets == [e["step"] + e["latency_steps"] for e in answered]
    delays = np.array([e["latency_steps"] for e in events]) * DT
    # rounding to 10 ms moves the distribution by at most half a step
    assert _ks(delays + DT / 2, lat.cdf) < 1.36 / np.sqrt(len(delays)) + 0.02
    assert abs(delays.mean() - 0.8) < 0.02
    # each answer lasts its utterance
    assert sum(speaks) == 100 * len(answered)


def test_a_noncontingent_schedule_does_not_depend_on_the_infant():
    onsets = yoked_onsets(12, 3000, 100, np.random.default_rng(3))
    assert len(onsets) == 12 and all(b - a > 100 for a, b in zip(onsets, onsets[1:]))
    runs = []
    for infant in ([False] * 3000, _babbling(12), list(np.random.default_rng(4).random(3000) < .5)):
        s = TimedSchedule(onsets, 100)
        s.reset()
        runs.append([s.step(v) for v in infant])
    assert runs[0] == runs[1] == runs[2]
    assert sum(runs[0]) == 1200
    # Poisson onsets: about the rate, drawn from the generator alone
    many = poisson_onsets(0.5, 100_000, DT, 100, np.random.default_rng(5))
    assert many == poisson_onsets(0.5, 100_000, DT, 100, np.random.default_rng(5))
    # rate per second of silence: 1000 s, of which the utterances take n * 1 s
    assert abs(len(many) / (1000 - len(many)) - 0.5) < 0.05
    with pytest.raises(ConfigError, match="do not fit"):
        yoked_onsets(40, 3000, 100, np.random.default_rng(0))


def test_a_replayed_schedule_reproduces_the_contingent_session():
    sched = ContingentSchedule(Latency(), 0.8, 100, DT)
    sched.reset(np.random.default_rng(2))
    infant = _babbling(20)
    live = [sched.step(v) for v in infant]
    replay = TimedSchedule(sched.onsets, 100)
    replay.reset()
    assert [replay.step(False) for _ in infant] == live


def test_the_measures_on_sound_arrays():
    # infant: 0.3 s vocal at 1.0 s and 3.5 s; the caregiver answers the first 0.5 s after its
    # offset and speaks 1 s; the infant's second comes 0.7 s after the caregiver's offset
    n = 600
    infant, care = np.zeros(n, int), np.zeros(n, int)
    infant[100:130] = 2            # babble, offset at step 130
    infant[350:380] = 1            # coo, never answered
    care[180:280] = 5              # speech: onset 50 steps (0.5 s) after the offset
    info, lat = measure(infant, care, DT, 1.0)
    assert info["infant_vocalisations"] == 2 and info["caregiver_utterances"] == 1
    assert lat == pytest.approx([0.5])
    assert info["answered_fraction"] == 0.5 and info["turns"] == 2   # the infant replies too
    assert info["infant_turns"] == 1 and info["mean_turn_gap_s"] == pytest.approx(0.6)
    assert info["speech_like_fraction"] == 0.5
    assert info["infant_rate_per_min"] == pytest.approx(2 / 0.1)


def test_the_scripted_infant_vocalises_more_and_babbles_more_when_answered():
    def session(contingent: bool, seed: int):
        inf = VocalInfant(DT)
        inf.reset(np.random.default_rng([seed, 0]))
        if contingent:
            care = ContingentSchedule(Latency(), 0.8, 100, DT)
        else:
            care = TimedSchedule(yoked_onsets(16, 6000, 100, np.random.default_rng(seed)), 100)
        care.reset(np.random.default_rng([seed, 1]))
        m, speaking = TurnMeasures(DT), False
        for _ in range(6000):
            kind = inf.step(speaking)
            speaking = care.step(kind != 0)
            m.update(kind, 5 if speaking else 0)
        return m.infos()
    c = [session(True, s) for s in range(20)]
    y = [session(False, s) for s in range(20)]
    mean = lambda rows, k: float(np.mean([r[k] for r in rows]))  # noqa: E731
    assert mean(c, "infant_rate_per_min") > mean(y, "infant_rate_per_min")
    assert mean(c, "speech_like_fraction") > mean(y, "speech_like_fraction") + 0.1
    assert mean(c, "answered_fraction") > mean(y, "answered_fraction") + 0.3


def test_bad_settings_are_refused_naming_the_field():
    with pytest.raises(ConfigError, match="latency_mean_s=-1 not allowed; allowed"):
        Latency(-1)
    with pytest.raises(ConfigError, match="response_probability=1.5"):
        ContingentSchedule(Latency(), 1.5, 100, DT)
    with pytest.raises(ConfigError, match="duration_s="):
        VocalInfant(duration_s=(0.8, 0.3))
    with pytest.raises(RuntimeError, match="before reset"):
        VocalInfant().step(False)


# -- the env ----------------------------------------------------------------------------------
from mimo_social.envs import turn_taking_v0  # noqa: E402
from mimo_social.partners.base import zero_action  # noqa: E402
from mimo_social.tasks.turn_taking import TurnTakingInfantController  # noqa: E402
from mimo_social.tasks.turn_taking.measures import effects  # noqa: E402

STEPS = 1500


class Silent:
    """The zero action: silence, head and eyes at rest."""

    def reset(self, env, agent, rng):
        self.action = zero_action(env.action_space(agent))

    def act(self, env, agent, obs):
        return self.action


def _episode(env, learner, condition, seed=0):
    """Per step the infant's and the caregiver's sound kinds, and the last info."""
    env.unwrapped.task.set_condition(condition)
    env.reset(seed=seed)
    learner.reset(env.unwrapped, "infant_0", np.random.default_rng(seed))
    infant, care = [], []
    for _ in range(STEPS):
        *_, infos = env.step({"infant_0": learner.act(env.unwrapped, "infant_0", None)})
        info = infos["infant_0"]
        infant.append(int(info["infant_sound"]))
        care.append(int(info["caregiver_sound"]))
    return np.array(infant), np.array(care), info


def test_the_scripted_env_answers_within_the_latency_and_measures_what_happened():
    env = turn_taking_v0.scripted_env(max_steps=STEPS)
    assert env.action_space("infant_0")["voice"].n == 6
    infant, care, info = _episode(env, TurnTakingInfantController(), "contingent")
    events = env.partners["caregiver_0"].events
    answered = [e for e in events if e["answered"]]
    assert answered and info["answers"] >= 1 and info["condition"] == 0
    # each answer starts its latency after the offset, plus the step in which it is heard
    onsets = np.flatnonzero(np.diff(np.r_[0, care != 0].astype(int)) == 1)
    offsets = np.flatnonzero(np.diff(np.r_[0, infant != 0].astype(int)) == -1)
    for e in answered:
        offset = offsets[offsets < e["step"]][-1]
        assert e["step"] == offset + 1
        assert offset + 1 + e["latency_steps"] in onsets
    # the infos are the measures of the logged sounds
    got, _ = measure(infant, care, env.unwrapped.dt, 1.0)
    for k, v in got.items():
        assert info[k] == pytest.approx(v), k
    assert set(care[care != 0]) == {5}      # speech


def test_noncontingent_and_replay_do_not_depend_on_the_infant():
    env = turn_taking_v0.scripted_env(max_steps=STEPS)
    # before any contingent episode: a Poisson timer, the same whatever the infant does
    a = _episode(env, TurnTakingInfantController(), "noncontingent", seed=3)[1]
    b = _episode(env, Silent(), "noncontingent", seed=3)[1]
    assert np.array_equal(a, b) and a.any()
    # the replay of a contingent session is that session's caregiver, for any infant
    live = _episode(env, TurnTakingInfantController(), "contingent", seed=5)[1]
    recorded = env.partners["caregiver_0"].recorded
    for learner in (Silent(), TurnTakingInfantController()):
        replay, info = _episode(env, learner, "replay", seed=7)[1:]
        assert np.array_equal(replay, live) and info["condition"] == 2
    # yoked: as many utterances as the contingent session, the same for any infant
    c = _episode(env, Silent(), "noncontingent", seed=8)[1]
    d = _episode(env, TurnTakingInfantController(), "noncontingent", seed=8)[1]
    assert np.array_equal(c, d)
    count = lambda s: int(np.sum(np.diff(np.r_[0, s != 0].astype(int)) == 1))  # noqa: E731
    assert count(c) == count(live) == len(recorded)
    # onsets given to a new env
    other = turn_taking_v0.scripted_env(max_steps=STEPS, onsets=recorded,
                                        task_options={"condition": "replay"})
    assert np.array_equal(_episode(other, Silent(), "replay")[1], live)


def test_a_pickled_copy_continues_exactly_and_seeds_repeat():
    env = turn_taking_v0.scripted_env(max_steps=STEPS)
    first = _episode(env, TurnTakingInfantController(), "contingent", seed=2)
    again = _episode(env, TurnTakingInfantController(), "contingent", seed=2)
    assert np.array_equal(first[0], again[0]) and np.array_equal(first[1], again[1])
    from learner_episodes import pickled_twin_runs
    _, outs = pickled_twin_runs(env, TurnTakingInfantController(), 4, 300, 400)
    assert outs[0] == outs[1] and len(outs[0]) == 400


@pytest.mark.parametrize("options, words", [
    ({"condition": "live"}, ["condition='live'", "contingent", "noncontingent", "replay"]),
    ({"latency_mean_s": -1}, ["latency_mean_s=-1", "allowed"]),
    ({"response_probability": 2}, ["response_probability=2", "from 0 to 1"]),
    ({"window_s": 0}, ["window_s=0", "allowed"]),
    ({"success_answers": 0.5}, ["success_answers=0.5", "integer"]),
])
def test_bad_options_are_refused_naming_field_value_and_allowed(options, words):
    with pytest.raises(ConfigError) as e:
        turn_taking_v0.scripted_env(task_options=options)
    for w in words:
        assert w in str(e.value)


def test_conditions_that_need_the_script_or_a_recording_are_refused():
    with pytest.raises(ConfigError, match="needs the scripted caregiver"):
        turn_taking_v0.parallel_env(task_options={"condition": "noncontingent"})
    with pytest.raises(ConfigError, match="condition='replay' needs a recorded caregiver"):
        turn_taking_v0.scripted_env(task_options={"condition": "replay"})
    with pytest.raises(ConfigError, match="onsets"):
        turn_taking_v0.scripted_env(onsets="abc")


@pytest.mark.slow
def test_the_scripted_infant_vocalises_more_with_the_contingent_caregiver():
    res = effects(TurnTakingInfantController(), episodes=4, seed=0)
    for other in ("noncontingent", "replay"):
        d = res[f"contingent_minus_{other}"]
        assert d["infant_rate_per_min"][0] > 0 and d["speech_like_fraction"][0] > 0.1
        assert d["answered_fraction"][0] > 0.2
    # zero and random learners do not learn from answers: the silent one is never answered
    silent = effects(Silent(), episodes=1, seed=0)["summary"]
    assert all(silent[c]["infant_rate_per_min"][0] == 0 for c in silent)


def test_the_caregiver_reaches_the_learner_only_through_its_ears():
    env = turn_taking_v0.scripted_env(max_steps=STEPS)
    assert set(env.observation_space("infant_0").spaces) == {"proprioception", "audition"}
    env.reset(seed=1)
    learner = TurnTakingInfantController()
    learner.reset(env.unwrapped, "infant_0", np.random.default_rng(1))
    heard = 0
    for _ in range(STEPS):
        obs, _, _, _, infos = env.step({"infant_0": learner.act(env.unwrapped, "infant_0",
                                                                None)})
        care = int(infos["infant_0"]["caregiver_sound"])
        row = obs["infant_0"]["audition"][1]           # the caregiver's row (sources in order)
        assert row[care] == 1.0 and row[:6].sum() == 1.0
        heard += care == 5
    assert heard > 0


def test_measures_latencies_are_the_scheduled_answers_in_control_steps():
    from mimo_social.tasks.turn_taking.measures import latencies
    got = latencies(episodes=2, seed=0, env_kwargs={"max_steps": STEPS})
    assert got and all(x >= 0 for x in got)
    assert all(abs(x / DT - round(x / DT)) < 1e-9 for x in got)


def test_the_answers_are_an_event_line_of_the_recording(tmp_path):
    """The replay shows each caregiver answer: /plots/caregiver_answer is 2 on the step an answer
    begins (1 on another utterance onset, else 0)."""
    from mimo_social.recording import Recorder, read_batches
    env = turn_taking_v0.scripted_env(max_steps=STEPS)
    learner = TurnTakingInfantController()
    obs, _ = env.reset(seed=1002)
    learner.reset(env.unwrapped, "infant_0", np.random.default_rng(1002))
    answers = []
    with Recorder(env, tmp_path / "tt.rrd", eyes=False) as rec:
        rec.log_reset(obs)
        for _ in range(STEPS):
            act = {"infant_0": learner.act(env.unwrapped, "infant_0", None)}
            obs, rewards, _, _, infos = env.step(act)
            rec.log_step(act, rewards, obs)
            if infos["infant_0"]["answer"]:
                answers.append(int(infos["infant_0"]["step"]))
    data = read_batches(tmp_path / "tt.rrd")
    logged = {}
    for batch in data["/plots/caregiver_answer"]:
        if "Scalars:scalars" in batch.schema.names:
            for k, v in zip(batch.column("step").to_pylist(),
                            batch.column("Scalars:scalars").to_pylist()):
                if v is not None:
                    logged[k] = v[0]
    assert answers and sorted(k for k, v in logged.items() if v == 2.0) == answers
    assert set(logged.values()) <= {0.0, 1.0, 2.0}


class Always:
    """A hack: babble on every step (never an offset, so never answered)."""

    def reset(self, env, agent, rng):
        self.action = dict(zero_action(env.action_space(agent)), voice=np.int64(2),
                           loudness=np.full(1, 0.5, np.float32))

    def act(self, env, agent, obs):
        return self.action


class Bidder:
    """An upper bound: ``length`` steps of babble whenever both have been silent ``wait`` steps
    (it reads the sounds from the world, as the scripted infant does)."""

    def __init__(self, wait: int, length: int = 20):
        self.wait, self.length = wait, length

    def reset(self, env, agent, rng):
        self.base = dict(zero_action(env.action_space(agent)),
                         loudness=np.full(1, 0.5, np.float32))
        self.quiet = self.left = 0

    def act(self, env, agent, obs):
        s = env.sounds
        if self.left:
            self.left -= 1
            return dict(self.base, voice=np.int64(2 if self.left else 0))
        self.quiet = self.quiet + 1 if s[0, 0] == 0 and s[1, 0] == 0 else 0
        if self.quiet >= self.wait:
            self.quiet, self.left = 0, self.length
            return dict(self.base, voice=np.int64(2))
        return dict(self.base, voice=np.int64(0))


class Flicker:
    """A hack PPO found (issue 33's pilot): a voice switched on and off every few steps, so that
    some offset is always recent when an utterance begins; seeded per episode."""

    def reset(self, env, agent, rng):
        self.base = dict(zero_action(env.action_space(agent)),
                         loudness=np.full(1, 0.5, np.float32))
        self.rng = rng

    def act(self, env, agent, obs):
        return dict(self.base, voice=np.int64(2 if self.rng.random() < 0.64 else 0))


def hack_figures(episodes: int = 20, seed: int = 1000) -> dict:
    """Successes and answers (mean, sd) of the hacks and the bound, contingent condition."""
    from mimo_social.core.episodes import run_episodes
    env = turn_taking_v0.scripted_env()
    out = {}
    for name, policy in (("always babble", Always()), ("flicker", Flicker()),
                         ("bidder 1.5 s", Bidder(150)), ("bidder 0.3 s", Bidder(30)),
                         ("scripted", TurnTakingInfantController())):
        finals = [e.last_infos["infant_0"]
                  for e in run_episodes(env, {"infant_0": policy}, episodes, seed)]
        answers = np.array([f["answers"] for f in finals], float)
        out[name] = (int(sum(f["is_success"] for f in finals)), float(answers.mean()),
                     float(answers.std()))
    env.close()
    return out


@pytest.mark.slow
def test_hacks_score_less_and_the_optimum_uses_the_contingency():
    got = hack_figures(episodes=3)
    assert got["always babble"][:2] == (0, 0.0)
    assert got["flicker"][1] < got["scripted"][1] / 2
    # taking turns earns what the scripted infant earns (20 episodes: 15.25 against 13.8)
    assert got["bidder 0.3 s"][0] == 3 and got["bidder 0.3 s"][1] >= got["scripted"][1]


if __name__ == "__main__":   # the table's figures of the hacks (20 episodes, seeds 1000-1019)
    for k, (wins, mean, sd) in hack_figures().items():
        print(f"{k}: {wins} / 20 successes, answers {mean:.2f} +- {sd:.2f}")
