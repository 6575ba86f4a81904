"""Face perception (``faces``): where the other agents' faces are, where they are turned and where
they look, read in the agent's head frame only while a face is in view, turned towards it and
not hidden; zeros otherwise. Bad settings are refused by name; a pickled copy goes on alike."""

from __future__ import annotations

import pickle

import mujoco
import numpy as np
import pytest

from mimo_social.envs import free_play_v0, joint_attention_v0
from mimo_social.senses.delays import developmental_delays
from mimo_social.senses.faces import COMPONENTS, FacesConfig
from mimo_social.util.checks import ConfigError


def make(faces=True, partner_faces=True, **kw):
    return joint_attention_v0.parallel_env(vision=False, per_agent=[
        {"faces": faces}, {"faces": partner_faces}], **kw)


def sense_of(env, i=0):
    return next(s for s in env.unwrapped.senses[i] if s.name == "faces")


def set_joints(env, agent, angles: dict):
    w = env.unwrapped.world
    a = w.agents[agent]
    for name, value in angles.items():
        w.data.qpos[a.qpos_adr[a.joint_names.index(name)]] = value
    mujoco.mj_forward(w.model, w.data)


def read(env, i=0):
    w = env.unwrapped.world
    return sense_of(env, i).read(w.model, w.data)


def angle(u, v):
    return float(np.arccos(np.clip(np.dot(u, v) / np.linalg.norm(u) / np.linalg.norm(v), -1, 1)))


def test_a_face_opposite_is_seen_where_it_is_and_turned_and_looking_back():
    env = make()
    obs, _ = env.reset(seed=0)
    f = obs["infant_0"]["faces"]
    assert env.observation_space("infant_0")["faces"].shape == (10,)
    assert env.observation_space("infant_0").contains(obs["infant_0"])
    seen, pos, head, gaze = f[0], f[1:4], f[4:7], f[7:10]
    assert seen == 1.0
    assert 0.3 < pos[0] < 0.8 and abs(pos[1]) < 0.02     # ahead, on the line between them
    assert head[0] < -0.8 and gaze[0] < -0.8                # turned to the viewer, looking back
    assert np.isclose(np.linalg.norm(head), 1, atol=1e-5)
    assert np.isclose(np.linalg.norm(gaze), 1, atol=1e-5)
    # both see each other
    assert obs["infant_1"]["faces"][0] == 1.0


def test_the_partner_s_head_turn_and_eye_turn_are_read_apart():
    env = make()
    env.reset(seed=0)
    before = read(env)
    set_joints(env, 1, {"head_swivel": 0.5})
    turned = read(env)
    assert turned[0] == 1.0
    assert angle(before[4:7], turned[4:7]) == pytest.approx(0.5, abs=0.03)
    assert np.allclose(turned[1:4], before[1:4], atol=0.03)   # the head centre hardly moves
    # the eyes' horizontal joints turn mirrored: opposite angles turn both the same way
    set_joints(env, 1, {"head_swivel": 0.0, "right_eye_horizontal": -0.3,
                        "left_eye_horizontal": 0.3})
    eyes = read(env)
    assert np.allclose(eyes[4:7], before[4:7], atol=1e-6)      # the head did not turn
    assert angle(before[7:10], eyes[7:10]) == pytest.approx(0.3, abs=0.03)


def test_the_reading_is_in_the_viewer_s_head_frame():
    env = make(faces={"field_of_view": 160})
    env.reset(seed=0)
    before = read(env)
    set_joints(env, 0, {"head_swivel": 0.4})
    after = read(env)
    assert after[0] == 1.0
    # the viewer turned its head: the partner's face is now off to the side by about as much
    bearing = np.arctan2(after[2], after[1]) - np.arctan2(before[2], before[1])
    assert abs(abs(bearing) - 0.4) < 0.08


def test_a_face_out_of_view_or_turned_away_or_hidden_reads_zeros():
    env = make(faces={"field_of_view": 30})
    env.reset(seed=0)
    assert read(env)[0] == 1.0
    set_joints(env, 0, {"head_swivel": 0.6})            # 34 degrees: out of a 30-degree view
    assert not read(env).any()
    wide = make(faces={"field_of_view": 120})
    wide.reset(seed=0)
    set_joints(wide, 0, {"head_swivel": 0.6})
    assert read(wide)[0] == 1.0
    # turned away: beyond turn_deg
    strict = make(faces={"turn_deg": 30})
    strict.reset(seed=0)
    set_joints(strict, 1, {"head_swivel": 0.8})         # 46 degrees away
    assert not read(strict).any()
    loose = make()
    loose.reset(seed=0)
    set_joints(loose, 1, {"head_swivel": 0.8})
    assert read(loose)[0] == 1.0


@pytest.mark.parametrize("occlusion", [True, False])
def test_a_toy_between_the_faces_hides_one_from_the_other(occlusion):
    env = make(faces={"occlusion": occlusion})
    env.reset(seed=0)
    w = env.unwrapped.world
    s = sense_of(env)
    eyes = w.data.cam_xpos[s.cams].mean(axis=0)
    face = w.data.site_xpos[s.sites[0]]
    q = w.prop_qpos["toy_0"]
    w.data.qpos[q:q + 3] = (eyes + face) / 2
    mujoco.mj_forward(w.model, w.data)
    assert read(env)[0] == (0.0 if occlusion else 1.0)


def test_components_choose_the_layout_and_each_other_agent_has_a_block():
    env = make(faces={"components": ["gaze", "seen"]})
    obs, _ = env.reset(seed=0)
    f = obs["infant_0"]["faces"]
    full = make()
    g = full.reset(seed=0)[0]["infant_0"]["faces"]
    assert f.shape == (4,) and f[0] == 1.0 and np.allclose(f[1:], g[7:10])
    three = free_play_v0.parallel_env(n_agents=3, faces=True)
    obs, _ = three.reset(seed=0)
    assert obs["infant_0"]["faces"].shape == (2 * 10,)
    assert three.observation_space("infant_0")["faces"].shape == (20,)


def test_a_pickled_copy_goes_on_alike():
    env = make()
    env.reset(seed=3)
    copy = pickle.loads(pickle.dumps(env))
    rng = np.random.default_rng(0)
    for _ in range(5):
        act = {a: rng.uniform(-1, 1, env.action_space(a).shape).astype(np.float32)
               for a in env.agents}
        a, b = env.step(act)[0], copy.step(act)[0]
        assert np.array_equal(a["infant_0"]["faces"], b["infant_0"]["faces"])


def test_the_developmental_delay_is_the_face_potential_s():
    assert developmental_delays(12.0)["faces"] == 290.0
    assert developmental_delays(None)["faces"] == 170.0
    env = make(delays={"faces": 50})
    obs, _ = env.reset(seed=0)
    first = obs["infant_0"]["faces"].copy()
    zero = {a: np.zeros(env.action_space(a).shape, np.float32) for a in env.agents}
    set_joints(env, 1, {"head_swivel": 0.5})
    for _ in range(4):          # 50 ms = 5 control steps: the turn is not seen yet
        assert np.allclose(env.step(zero)[0]["infant_0"]["faces"][4:7], first[4:7], atol=0.05)


@pytest.mark.parametrize("value, words", [
    ({"field_of_view": 5}, ["faces", "field_of_view=5", "10 to 170"]),
    ({"components": ["smile"]}, ["faces", "smile", str(list(COMPONENTS))]),
    ({"turn_deg": -1}, ["faces", "turn_deg=-1", "0 to 180"]),
    ({"occlusion": "yes"}, ["faces", "occlusion='yes'", "True or False"]),
    ({"colour": 1}, ["unknown", "colour"]),
])
def test_bad_settings_are_refused_by_name(value, words):
    with pytest.raises(ConfigError) as e:
        make(faces=value)
    for w in words:
        assert w in str(e.value), (w, str(e.value))
    with pytest.raises(ConfigError):
        FacesConfig(**{k: v for k, v in value.items() if k != "colour"} or {"turn_deg": 200})
