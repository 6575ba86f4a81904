"""The voice action: its space, the sounds it makes (env.sounds, infos) and its errors."""

import pickle

import numpy as np
import pytest
from gymnasium import spaces

from mimo_social.core.config import ConfigError
from mimo_social.envs import free_play_v0
from mimo_social.expressions.voice import SOUNDS, VOICE_TABLE, level_db, level_ranges


@pytest.fixture(scope="module")
def env():
    e = free_play_v0.parallel_env(n_agents=2, voice=True, max_steps=50)
    e.reset(seed=0)
    return e


def act(env, voice=(0, 0), loudness=(0.5, 0.5)):
    return {a: {"motors": np.zeros(44, np.float32), "expression": 0, "voice": voice[k],
                "loudness": np.array([loudness[k]], np.float32)}
            for k, a in enumerate(env.possible_agents)}


def test_action_space_has_voice_and_loudness(env):
    space = env.action_space("infant_0")
    assert set(space.spaces) == {"motors", "expression", "voice", "loudness"}
    assert space["voice"] == spaces.Discrete(len(SOUNDS))
    assert space["loudness"] == spaces.Box(0.0, 1.0, (1,), np.float32)
    assert space.contains(space.sample())


def test_voice_without_expressions():
    e = free_play_v0.parallel_env(n_agents=1, voice=True, expressions=False)
    assert set(e.action_space("infant_0").spaces) == {"motors", "voice", "loudness"}
    e.reset(seed=0)
    e.step({"infant_0": {"motors": np.zeros(44), "voice": 3, "loudness": 1.0}})
    assert tuple(e.sounds[0]) == (3.0, VOICE_TABLE[3].infant_db[1])


def test_sounds_last_one_step_and_map_loudness_to_db(env):
    env.reset(seed=0)
    assert not env.sounds.any()
    env.step(act(env, voice=(SOUNDS.index("cry"), 0), loudness=(1.0, 0.0)))
    lo, hi = level_ranges(adult=False)[SOUNDS.index("cry")]
    assert tuple(env.sounds[0]) == (3.0, hi) and tuple(env.sounds[1]) == (0.0, 0.0)
    env.step(act(env, voice=(1, 5), loudness=(0.0, 0.5)))
    assert tuple(env.sounds[0]) == (1.0, level_ranges(False)[1][0])
    assert env.sounds[1, 1] == pytest.approx(level_db(5, 0.5))
    env.step(act(env))
    assert tuple(env.sounds[:, 0]) == (0.0, 0.0)


def test_sounds_are_read_only(env):
    with pytest.raises(ValueError):
        env.sounds[0, 0] = 2.0


def test_numeric_infos_have_the_voice_kind(env):
    _, infos = env.reset(seed=0)
    assert infos["infant_0"]["voice"] == 0.0
    assert tuple(env.info_keys("infant_0")) == tuple(infos["infant_0"])
    _, _, _, _, infos = env.step(act(env, voice=(4, 2)))
    assert (infos["infant_0"]["voice"], infos["infant_1"]["voice"]) == (4.0, 2.0)
    assert tuple(infos["infant_0"]) == env.info_keys("infant_0")


def test_voice_off_has_no_voice_key():
    e = free_play_v0.parallel_env(n_agents=1)
    _, infos = e.reset(seed=0)
    assert "voice" not in infos["infant_0"]
    assert set(e.action_space("infant_0").spaces) == {"motors", "expression"}


@pytest.mark.parametrize("field, value, match", [
    ("voice", 6, r"infant_1: voice=6 not allowed; allowed: an integer 0\.\.5: 0=silence"),
    ("voice", -1, r"infant_1: voice=-1 not allowed"),
    ("voice", 1.5, r"infant_1: voice=1\.5 not allowed"),
    ("loudness", 1.5, r"infant_1: loudness=1\.5 not allowed; allowed: one number in \[0, 1\]"),
    ("loudness", np.nan, r"infant_1: loudness=nan not allowed"),
    ("loudness", [0.1, 0.2], r"infant_1: loudness=.* not allowed"),
    ("loudness", "loud", r"infant_1: action field 'loudness'"),
])
def test_bad_voice_values_are_refused(env, field, value, match):
    env.reset(seed=0)
    a = act(env)
    a["infant_1"][field] = value
    with pytest.raises(ValueError, match=match):
        env.step(a)
    assert not env.sounds.any()   # nothing applied


def test_missing_voice_keys_are_refused(env):
    a = act(env)
    del a["infant_0"]["loudness"]
    with pytest.raises(ValueError, match=r"infant_0: action must be a dict with keys 'motors', "
                                         r"'expression', 'voice' and 'loudness'"):
        env.step(a)


def test_bad_voice_config_is_refused():
    with pytest.raises(ConfigError, match="voice"):
        free_play_v0.parallel_env(n_agents=1, voice="yes")


def test_pickled_env_keeps_its_sounds(env):
    env.reset(seed=0)
    env.step(act(env, voice=(2, 3)))
    copy = pickle.loads(pickle.dumps(env))
    assert np.array_equal(copy.sounds, env.sounds)
    copy.step(act(copy, voice=(5, 0)))
    assert copy.sounds[0, 0] == 5.0 and env.sounds[0, 0] == 2.0


def test_random_actions_and_the_flat_action_carry_the_voice(env):
    from mimo_social.core.random_actions import random_action_block
    from mimo_social.core.wrappers import ActionDecoder, FlattenParallel

    block = random_action_block(env, 200, seed=1)
    space = env.action_space("infant_0")
    assert all(space.contains({k: np.asarray(v) if k != "voice" and k != "expression" else v
                               for k, v in a["infant_0"].items()}) for a in block[:5])
    assert len({a["infant_0"]["voice"] for a in block}) > 1
    plain = free_play_v0.parallel_env(n_agents=2)
    same = random_action_block(plain, 200, seed=1)      # the voice leaves motors and faces as
    assert all(np.array_equal(a["infant_1"]["motors"], b["infant_1"]["motors"])
               and a["infant_1"]["expression"] == b["infant_1"]["expression"]
               for a, b in zip(block, same))
    decode = ActionDecoder(space)
    assert decode.space.shape == (44 + 7 + len(SOUNDS) + 1,)
    flat = decode.encode(block[7]["infant_0"])
    back = decode(flat)
    assert (back["voice"], back["expression"]) == (block[7]["infant_0"]["voice"],
                                                   block[7]["infant_0"]["expression"])
    assert back["loudness"] == pytest.approx(block[7]["infant_0"]["loudness"])
    flat[-1] = 3.0                                      # loudness clipped into [0, 1]
    assert decode(flat)["loudness"][0] == 1.0
    flat[-2] = np.nan
    with pytest.raises(ValueError, match="infant_0: action field 'voice logits and loudness'"):
        decode(flat, "infant_0")
    wrapped = FlattenParallel(free_play_v0.parallel_env(n_agents=2, voice=True, audition=True))
    wrapped.reset(seed=0)
    wrapped.step({a: wrapped.action_space(a).sample() for a in wrapped.agents})


def test_a_voice_only_agent_takes_its_sound_id():
    """No motors, no face: the flat action is the sound id (Discrete), at a fixed loudness;
    the SB3 env of the turn-taking learner with its gaze held is such an agent."""
    from gymnasium import spaces

    from mimo_social.core.action_decoder import VOICE_ONLY_LOUDNESS, ActionDecoder
    from mimo_social.train.envs import make_sb3_single

    space = spaces.Dict({"motors": spaces.Box(-1, 1, (0,), np.float32),
                         "voice": spaces.Discrete(len(SOUNDS)),
                         "loudness": spaces.Box(0, 1, (1,), np.float32)})
    decode = ActionDecoder(space)
    assert decode.space == spaces.Discrete(len(SOUNDS))
    action = decode(3)
    assert action["voice"] == 3 and action["loudness"][0] == VOICE_ONLY_LOUDNESS
    assert space.contains(action)
    assert decode.encode(action) == 3
    for bad in (1.5, "coo", [1, 2]):
        with pytest.raises(ValueError, match="infant_0: action field 'voice'"):
            decode(bad, "infant_0")
    env = make_sb3_single("mimo_social/TurnTaking-v0", task_options={"gaze_free": False})
    assert env.action_space == spaces.Discrete(len(SOUNDS))
    env.reset(seed=0)
    info = env.step(2)[-1]
    assert info["infant_sound"] == 2
    env.close()
