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
