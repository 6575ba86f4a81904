"""Hearing: who hears what, where from (ILD, ITD), how loud (distance), delays, pickling."""

import pickle

import numpy as np
import pytest

from mimo_social.core.config import ConfigError
from mimo_social.envs import free_play_v0
from mimo_social.expressions.voice import SOUNDS, level_db
from mimo_social.senses.audition import FEATURES, SPEED_OF_SOUND, woodworth_itd

K = len(SOUNDS)
LEFT, RIGHT, ILD, ITD = (K + FEATURES.index(f) for f in FEATURES)
CRY, SILENCE = SOUNDS.index("cry"), 0


def pair(speaker_at, listener=None, speaker=None, **settings):
    """infant_0 at the origin facing +x (the listener), infant_1 at ``speaker_at`` facing it."""
    listener = dict(listener or {}, position=(0.0, 0.0), facing=(1.0, 0.0))
    speaker = dict(speaker or {}, position=tuple(speaker_at), facing=(0.0, 0.0))
    settings.setdefault("voice", True)
    settings.setdefault("audition", True)
    e = free_play_v0.parallel_env(n_agents=2, per_agent=[listener, speaker], max_steps=100,
                                  **settings)
    e.reset(seed=0)
    return e


def say(env, kinds=(SILENCE, CRY), loudness=1.0):
    action = {}
    for a, kind in zip(env.possible_agents, kinds):
        space = env.action_space(a)
        action[a] = {"motors": np.zeros(space["motors"].shape, np.float32), "expression": 0,
                     "voice": kind, "loudness": [loudness]}
    obs, *_ = env.step(action)
    return obs


def heard(env, at, kinds=(SILENCE, CRY)):
    """The listener's (agent 0) row for the speaker (agent 1, source 1)."""
    return say(env, kinds)[env.possible_agents[0]]["audition"][1]


@pytest.mark.parametrize("where, sign", [((0.0, 1.5), 1), ((0.0, -1.5), -1), ((1.5, 0.0), 0)])
def test_ild_and_itd_point_to_the_source(where, sign):
    env = pair(where)
    row = heard(env, where)
    r = float(env.world.model.geom_size[env.world.agents[0].head_geom, 0])
    assert row[CRY] == 1.0 and row[:K].sum() == 1.0
    if sign == 0:    # in front: both ears alike
        assert abs(row[ILD]) < 0.5 and abs(row[ITD]) < 0.02
    else:            # at the side: about the full head shadow (8 dB) and Woodworth's 90 degrees
        assert sign * row[ILD] == pytest.approx(8.0, abs=1.0)
        full = 1000.0 * r / SPEED_OF_SOUND * (np.pi / 2 + 1)
        assert sign * row[ITD] == pytest.approx(full, rel=0.1)
        assert sign * (row[LEFT] - row[RIGHT]) > 6.0


def test_woodworth_itd_of_an_adult_head_at_90_degrees():
    assert 1000 * woodworth_itd(0.0875, np.pi / 2) == pytest.approx(0.655, abs=0.005)
    assert woodworth_itd(0.0875, 0.0) == 0.0
    assert woodworth_itd(0.0875, -0.3) == -woodworth_itd(0.0875, 0.3)


def test_level_falls_by_6_db_per_doubling_of_distance():
    levels = []
    for d in (1.0, 2.0, 4.0):
        levels.append(heard(pair((d, 0.0)), d)[LEFT])
    assert levels[0] - levels[1] == pytest.approx(6.02, abs=0.5)
    assert levels[1] - levels[2] == pytest.approx(6.02, abs=0.2)
    # the level at 2 m: the cry's loudest less 20 log10(2), within the head's size
    assert levels[1] == pytest.approx(level_db(CRY, 1.0) - 6.02, abs=0.6)


def test_a_vocalisation_is_heard_by_the_partner_and_by_the_speaker():
    env = pair((1.0, 0.0))
    obs = say(env)
    partner, own = obs["infant_0"]["audition"][1], obs["infant_1"]["audition"][1]
    assert partner[CRY] == 1.0 and own[CRY] == 1.0
    assert own[LEFT] > partner[LEFT] + 15.0        # the own mouth is ~10 cm from the ears
    assert abs(own[ILD]) < 1e-3 and abs(own[ITD]) < 1e-4
    assert obs["infant_0"]["audition"].shape == (2, K + 4)
    assert env.observation_space("infant_0")["audition"].contains(obs["infant_0"]["audition"])


def test_silence_is_heard_as_nothing():
    env = pair((1.0, 0.0))
    a = say(env, (SILENCE, SILENCE))["infant_0"]["audition"]
    assert np.array_equal(a, np.tile(np.eye(1, K + 4, 0, dtype=np.float32), (2, 1)))


def test_a_sound_below_the_threshold_is_not_heard():
    env = pair((4.0, 0.0), audition={"threshold_db": 95.0})
    row = heard(env, None)
    assert row[SILENCE] == 1.0 and not row[K:].any()


def test_a_caregiver_has_bigger_ears_and_hears_too():
    env = pair((0.0, 1.5), listener={"body": "adult"})
    row = heard(env, None)
    r = float(env.world.model.geom_size[env.world.agents[0].head_geom, 0])
    assert r > 0.08 and row[CRY] == 1.0
    # the infant's mouth ~0.85 m below the adult's ears, 1.43 m to the left: about 60 degrees
    lateral = np.arcsin(1.43 / np.hypot(1.43, 0.85))
    assert row[ITD] == pytest.approx(1000.0 * woodworth_itd(r, lateral), rel=0.1)
    assert row[ITD] > 1000.0 * woodworth_itd(0.0735, lateral)    # more than an infant's


def test_delays_delay_hearing():
    env = pair((1.0, 0.0), delays={"audition": 30.0})
    assert env.delay_steps("infant_0")["audition"] == 3
    rows = [heard(env, None, kinds=(SILENCE, CRY if t == 0 else SILENCE)) for t in range(5)]
    assert [int(np.argmax(r[:K])) for r in rows] == [SILENCE, SILENCE, SILENCE, CRY, SILENCE]


def test_pickled_env_continues_identically_and_seeds_repeat():
    env = pair((1.0, 0.5))
    say(env)
    copy = pickle.loads(pickle.dumps(env))
    for kinds in [(1, 3), (5, 0), (2, 4)]:
        a, b = say(env, kinds), say(copy, kinds)
        for agent in a:
            assert np.array_equal(a[agent]["audition"], b[agent]["audition"])
    other = pair((1.0, 0.5))
    again = pair((1.0, 0.5))
    assert np.array_equal(say(other)["infant_0"]["audition"],
                          say(again)["infant_0"]["audition"])


def test_bad_audition_config_is_refused():
    with pytest.raises(ConfigError, match=r"audition: unknown setting\(s\) \['ears'\]"):
        free_play_v0.parallel_env(n_agents=1, audition={"ears": 3})
    with pytest.raises(ConfigError, match="threshold_db"):
        free_play_v0.parallel_env(n_agents=1, audition={"threshold_db": "loud"})
    with pytest.raises(ConfigError, match="head_shadow_db"):
        free_play_v0.parallel_env(n_agents=1, audition={"head_shadow_db": -1.0})


def test_without_voices_there_is_nothing_to_hear():
    env = free_play_v0.parallel_env(n_agents=2, audition=True)
    obs, _ = env.reset(seed=0)
    assert "audition" not in obs["infant_0"]


def test_hearing_and_voice_leave_the_world_unchanged():
    """Voice and audition change no physics: the bodies move bit for bit as without them."""
    plain = free_play_v0.parallel_env(n_agents=2, max_steps=100)
    heard_env = free_play_v0.parallel_env(n_agents=2, max_steps=100, voice=True, audition=True)
    o1, _ = plain.reset(seed=3)
    o2, _ = heard_env.reset(seed=3)
    rng = np.random.default_rng(0)
    for _ in range(5):
        motors = {a: rng.uniform(-1, 1, 44).astype(np.float32) for a in plain.agents}
        o1, *_ = plain.step({a: {"motors": m, "expression": 1} for a, m in motors.items()})
        o2, *_ = heard_env.step({a: {"motors": m, "expression": 1, "voice": 2, "loudness": [1]}
                                 for a, m in motors.items()})
    assert np.array_equal(plain.world.data.qpos, heard_env.world.data.qpos)
    for a in o1:
        assert set(o2[a]) - set(o1[a]) == {"audition"}
        for key in o1[a]:
            assert np.array_equal(o1[a][key], o2[a][key])


def test_some_listeners_and_some_voices():
    """Ears on one agent only, a voice on the other only: one source row, heard by agent 0."""
    env = pair((0.0, 1.5), listener={"voice": False, "audition": True},
               speaker={"voice": True, "audition": False})
    listener, speaker = env.possible_agents
    assert "audition" not in env.observation_space(speaker).spaces
    assert env.observation_space(listener)["audition"].shape == (1, K + 4)
    motors = {a: np.zeros(env.action_space(a)["motors"].shape, np.float32)
              for a in env.possible_agents}
    obs, *_ = env.step({listener: {"motors": motors[listener], "expression": 0},
                        speaker: {"motors": motors[speaker], "expression": 0, "voice": CRY,
                                  "loudness": [1.0]}})
    row = obs[listener]["audition"][0]
    assert row[CRY] == 1.0 and row[ILD] > 6.0 and row[ITD] > 0.4


def test_without_head_shadow_the_near_ear_is_louder_by_the_distance_law():
    env = pair((0.0, 0.5), audition={"head_shadow_db": 0.0})
    row = heard(env, None)
    w = env.world
    ears = w.data.geom_xpos[w.agents[0].head_geom] + np.outer(
        [1, -1], w.data.geom_xmat[w.agents[0].head_geom].reshape(3, 3)[:, 1]
        * w.model.geom_size[w.agents[0].head_geom, 0])
    h = w.agents[1].head_geom
    mouth = w.data.geom_xpos[h] + w.data.geom_xmat[h].reshape(3, 3)[:, 0] * w.model.geom_size[h, 0]
    d = np.linalg.norm(mouth - ears, axis=1)
    assert row[ILD] == pytest.approx(20 * np.log10(d[1] / d[0]), abs=1e-3)
    assert row[ILD] > 1.5
    assert row[LEFT] == pytest.approx(level_db(CRY, 1.0) - 20 * np.log10(d[0]), abs=1e-3)


@pytest.mark.parametrize("side", [1, -1])
def test_the_binaural_frame_carries_level_and_itd(side):
    from mimo_social.senses.waveform import SAMPLE_RATE

    env = pair((0.0, side * 1.0), audition={"waveform": True})
    listener = env.possible_agents[0]
    assert env.observation_space(listener)["audition_waveform"].shape == (2, 160)
    obs = say(env)[listener]
    w, row = obs["audition_waveform"].astype(float), obs["audition"][1]
    assert env.observation_space(listener)["audition_waveform"].contains(
        obs["audition_waveform"])
    rms_db = 20 * np.log10(np.sqrt((w ** 2).mean(1)) / 20e-6)
    assert rms_db == pytest.approx(row[[LEFT, RIGHT]], abs=1.0)
    lag = np.argmax(np.correlate(w[1], w[0], "full")) - (w.shape[1] - 1)
    assert lag == pytest.approx(row[ITD] * 1e-3 * SAMPLE_RATE, abs=1.0)
    assert side * lag >= 7
    silent = say(env, (SILENCE, SILENCE))[listener]["audition_waveform"]
    assert not silent.any()


def test_no_waveform_by_default():
    env = pair((1.0, 0.0))
    assert "audition_waveform" not in env.observation_space(env.possible_agents[0]).spaces


def _random_steps(env, steps, seed):
    """``steps`` steps of random motors and random sounds; yields after each."""
    rng = np.random.default_rng(seed)
    for _ in range(steps):
        action = {}
        for a in env.possible_agents:
            space = env.action_space(a)
            action[a] = {"motors": rng.uniform(-1, 1, space["motors"].shape).astype(np.float32),
                         "expression": 0}
            if "voice" in space.spaces:
                action[a].update(voice=int(rng.integers(len(SOUNDS))),
                                 loudness=[float(rng.uniform())])
        env.step(action)
        yield


@pytest.mark.parametrize("settings", [
    dict(n_agents=2),
    dict(n_agents=3, per_agent=[{"body": "adult"}, {"audition": False}, {"voice": False}]),
    dict(n_agents=2, audition={"threshold_db": 60.0, "head_shadow_db": 15.0}),
])
def test_python_floats_and_numpy_arrays_hear_the_same(settings):
    """The two ways of computing the rows (few pairs: Python floats, many: numpy) agree."""
    settings = {"voice": True, "audition": True, **settings}
    env = free_play_v0.parallel_env(max_steps=10 ** 6, **settings)
    env.reset(seed=2)
    system, w = env.unwrapped.systems["audition"], env.world
    assert system.scalar             # a few pairs: the floats by default
    for _ in _random_steps(env, 60, 1):
        system.update(w.model, w.data)
        floats = system.features.copy()
        system.scalar = False
        system.update(w.model, w.data)
        system.scalar = True
        arrays = system.features
        assert np.array_equal(floats[..., :K], arrays[..., :K])
        np.testing.assert_allclose(floats, arrays, rtol=1e-6, atol=1e-5)


def test_hearing_follows_the_poses_the_other_senses_read():
    """Levels from the head poses after the step (not MuJoCo's sensors of the state before its
    last integration): the mouth-to-ear distances of the geoms match the ILD at every step."""
    env = pair((0.0, 0.4), audition={"head_shadow_db": 0.0})
    w, listener, speaker = env.world, env.world.agents[0], env.world.agents[1]
    rng = np.random.default_rng(4)
    for _ in range(40):
        motors = {a: rng.uniform(-1, 1, env.action_space(a)["motors"].shape).astype(np.float32)
                  for a in env.possible_agents}
        obs, *_ = env.step({a: {"motors": m, "expression": 0, "voice": CRY, "loudness": [1.0]}
                            for a, m in motors.items()})
        row = obs["infant_0"]["audition"][1]
        h, g = listener.head_geom, speaker.head_geom
        ears = w.data.geom_xpos[h] + np.outer(
            [1, -1], w.data.geom_xmat[h].reshape(3, 3)[:, 1] * w.model.geom_size[h, 0])
        mouth = w.data.geom_xpos[g] + (w.data.geom_xmat[g].reshape(3, 3)[:, 0]
                                       * w.model.geom_size[g, 0])
        d = np.linalg.norm(mouth - ears, axis=1)
        assert row[ILD] == pytest.approx(20 * np.log10(d[1] / d[0]), abs=1e-4)


def test_after_an_age_change_the_ears_hear_as_a_fresh_body():
    """The mouth and the ears move with the head at an age change without compiling."""
    grown = free_play_v0.parallel_env(n_agents=2, voice=True, audition=True, age_months=6.0,
                                      max_steps=100)
    grown.reset(seed=0)
    grown.set_age(age_months=18.0)
    fresh = free_play_v0.parallel_env(n_agents=2, voice=True, audition=True, age_months=18.0,
                                      max_steps=100)
    o1, _ = grown.reset(seed=5)
    o2, _ = fresh.reset(seed=5)
    for kinds in [(CRY, 2), (1, SILENCE), (4, 5)]:
        a, b = say(grown, kinds), say(fresh, kinds)
        for agent in a:
            np.testing.assert_allclose(a[agent]["audition"], b[agent]["audition"], atol=1e-4)
    assert say(grown)["infant_0"]["audition"][1, CRY] == 1.0


def test_echoic_memory_keeps_what_was_heard_and_moves_it_back():
    """A 30-ms cry stays in the memory's newest frame for a bin, then moves one frame back a
    bin later; silence leaves zeros; the memory is cleared at reset."""
    env = pair((1.0, 0.0), audition={"memory_s": 0.5, "memory_bin_s": 0.1})
    space = env.observation_space("infant_0")["audition_memory"]
    assert space.shape == (5, 2)
    memories = [say(env, (SILENCE, CRY if t < 3 else SILENCE))["infant_0"]["audition_memory"]
                for t in range(25)]
    assert all(space.contains(m) for m in memories)
    first = heard_level = memories[0][0, 1]
    assert heard_level > 60.0 and memories[0][0, 0] == 0.0     # the listener itself was silent
    assert [(m[:, 1] > 0).tolist() for m in (memories[9], memories[10], memories[22])] == [
        [True, False, False, False, False], [True, True, False, False, False],
        [False, False, True, False, False]]
    assert memories[22][2, 1] == pytest.approx(first, abs=0.1)   # the loudest of 3 steps
    assert env.reset(seed=1)[0]["infant_0"]["audition_memory"].sum() == 0.0


def test_echoic_memory_holds_the_loudest_level_of_each_bin_and_pickles():
    env = pair((1.0, 0.0), audition={"memory_s": 0.2, "memory_bin_s": 0.05})
    quiet = say(env, (SILENCE, CRY), loudness=0.0)["infant_0"]["audition_memory"][0, 1]
    loud = say(env, (SILENCE, CRY), loudness=1.0)["infant_0"]["audition_memory"][0, 1]
    assert loud > quiet > 0.0
    assert say(env, (SILENCE, CRY), loudness=0.0)["infant_0"]["audition_memory"][0, 1] == loud
    copy = pickle.loads(pickle.dumps(env))
    for kinds in [(1, 0), (0, 0), (2, 3), (0, 0)]:
        a, b = say(env, kinds), say(copy, kinds)
        assert np.array_equal(a["infant_0"]["audition_memory"], b["infant_0"]["audition_memory"])


def test_without_memory_there_is_no_memory_key_and_bad_memory_is_refused():
    env = pair((1.0, 0.0))
    assert "audition_memory" not in env.observation_space("infant_0").spaces
    for bad in ({"memory_s": -1.0}, {"memory_s": 11.0}, {"memory_bin_s": 0.0}):
        with pytest.raises(ConfigError, match="memory"):
            pair((1.0, 0.0), audition=bad)
