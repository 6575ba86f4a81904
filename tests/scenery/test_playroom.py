"""The play room (``scene="playroom"``): every task builds, resets and steps in it, the scripted
controllers still succeed, toys are felt by the skin and seen by the eyes, the bare floor stays
the default (unchanged), bad values are refused, and an env in the room is deterministic and
continues identically after pickling."""

from __future__ import annotations

import pickle

import mujoco
import numpy as np
import pytest

from mimo_social.core.world import World
from mimo_social.envs import free_play_v0, high_five_v0
from mimo_social.envs.catalog import CATALOG, entry
from mimo_social.scenery import SCENES
from mimo_social.scenery.playroom import ROOM_HALF, WALL_HEIGHT
from mimo_social.scenery.toys import TOYS
from mimo_social.util.checks import ConfigError

pytestmark = pytest.mark.text_infos   # these tests read the text infos (info_text=True)

ADULT = [{}, {"body": "adult", "posture": "kneeling"}]


def zero_actions(env, agents=None):
    out = {}
    for a in (agents or env.agents):
        sp = env.action_space(a)
        if hasattr(sp, "spaces"):
            out[a] = {"motors": np.zeros(sp["motors"].shape, np.float32), "expression": 0}
            _voice(out[a], sp, 0)
        else:
            out[a] = np.zeros(sp.shape, np.float32)
    return out


def random_actions(env, rng):
    out = {}
    for a in env.agents:
        sp = env.action_space(a)
        box = sp["motors"] if hasattr(sp, "spaces") else sp
        u = rng.uniform(box.low, box.high).astype(np.float32)
        out[a] = {"motors": u, "expression": int(rng.integers(7))} if hasattr(sp, "spaces") else u
        if hasattr(sp, "spaces") and "voice" in sp.spaces:
            _voice(out[a], sp, int(rng.integers(sp["voice"].n)))
    return out


def _voice(action, space, kind):
    """An action of a Dict space with the voice (issue 33): its keys as the space's (the
    expression only where the space has it), ``kind`` at loudness 0.5."""
    if "voice" in space.spaces:
        action.update(voice=kind, loudness=np.full(1, 0.5, np.float32))
    if "expression" not in space.spaces:
        action.pop("expression", None)


def saved_model(model) -> bytes:
    buf = np.empty(mujoco.mj_sizeModel(model), np.uint8)
    mujoco.mj_saveModel(model, None, buf)
    return buf.tobytes()


def toy_qpos(world, toy: str) -> int:
    m = world.model
    return int(m.jnt_qposadr[m.body_jntadr[m.body(f"playroom/{toy}").id]])


# -- the bare floor stays the default ----------------------------------------------------------
def test_the_floor_is_the_default_and_unchanged(monkeypatch):
    import mimo_social.core.world as world_module

    def no_room(*args, **kwargs):
        raise AssertionError("the floor scene built a play room")
    monkeypatch.setattr(world_module, "add_playroom", no_room)
    default = free_play_v0.parallel_env()
    floor = free_play_v0.parallel_env(scene="floor")
    assert default.scene == "floor" and floor.scene == "floor" and default.world.room is None
    assert saved_model(default.world.model) == saved_model(floor.world.model)
    m = default.world.model
    names = [m.geom(g).name for g in range(m.ngeom)] + [m.body(b).name for b in range(m.nbody)]
    assert "floor" in names and not any(n.startswith("playroom/") for n in names)
    assert m.nlight == 2
    for env in (default, floor):
        env.reset(seed=3)
    rng1, rng2 = np.random.default_rng(0), np.random.default_rng(0)
    for _ in range(5):
        default.step(random_actions(default, rng1))
        floor.step(random_actions(floor, rng2))
    assert np.array_equal(default.state(), floor.state())


def test_bad_scene_is_a_config_error_naming_it():
    with pytest.raises(ConfigError) as e:
        free_play_v0.parallel_env(scene="garden")
    text = str(e.value)
    assert "scene" in text and "garden" in text and all(s in text for s in SCENES)
    with pytest.raises(ConfigError, match="scene"):
        high_five_v0.scripted_env(scene=["playroom"])


# -- every task in the room ---------------------------------------------------------------------
@pytest.mark.parametrize("e", CATALOG, ids=lambda e: e.name)
def test_every_task_builds_resets_and_steps_in_the_playroom(e):
    env = e.scripted_env(scene="playroom")
    inner = env.unwrapped
    assert inner.scene == "playroom"
    w = inner.world
    assert set(w.room.toys) == {f"playroom/{t}" for t in TOYS}
    obs, _ = env.reset(seed=0)
    for _ in range(3):
        if not env.agents:
            break
        obs, *_ = env.step(zero_actions(env))
    # the scene camera is inside the room, below the ceiling
    cam = inner.scene_camera()
    az, el = np.deg2rad(cam.azimuth), np.deg2rad(cam.elevation)
    eye = np.array(cam.lookat) - cam.distance * np.array(
        [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    assert np.all(np.abs(eye[:2] - w.room.centre) < ROOM_HALF) and 0 < eye[2] < WALL_HEIGHT
    # the room's furniture is in the model, the agents start clear of it
    assert any(n.startswith("playroom/crib/") for n in w.room.furniture)
    env.close()


def test_gym_form_takes_the_scene():
    g = entry("reach").gym_env(scene="playroom")
    g.reset(seed=0)
    g.step(np.zeros(g.action_space.shape, np.float32))
    assert g.parallel.scene == "playroom"


@pytest.mark.parametrize("task, per_agent", [("high_five", None), ("handover", ADULT),
                                             ("joint_attention", None)])
def test_scripted_controllers_still_succeed_in_the_playroom(task, per_agent):
    e = entry(task)
    kw = {"scene": "playroom"} | ({"per_agent": per_agent} if per_agent else {})
    env = e.scripted_env(**kw)
    inner = env.unwrapped
    obs, _ = env.reset(seed=0)
    ctrl = e.controller()
    ctrl.reset(inner, "infant_0", np.random.default_rng(0))
    while True:
        obs, _, term, trunc, info = env.step(
            {"infant_0": ctrl.act(inner, "infant_0", obs["infant_0"])})
        if term["infant_0"] or trunc["infant_0"]:
            break
    assert info["infant_0"]["is_success"] and "instability" not in info["infant_0"]


def test_agents_placed_in_the_furniture_are_refused():
    with pytest.raises(ConfigError) as e:
        free_play_v0.parallel_env(scene="playroom", per_agent=[
            {"position": (-1.85, 0.0)}, {"position": (1.85, 0.0)}])
    text = str(e.value)
    assert "infant_" in text and "playroom" in text and "position" in text
    free_play_v0.parallel_env(per_agent=[{"position": (-1.85, 0.0)}, {"position": (1.85, 0.0)}])


# -- toys: felt by the skin, seen by the eyes ---------------------------------------------------
def test_a_toy_on_an_infant_is_felt_by_its_skin():
    env = free_play_v0.parallel_env(n_agents=1, posture="lying", scene="playroom",
                                    touch={"normal_only": True})
    w, m, d = env.world, env.world.model, env.world.data
    env.reset(seed=0)
    for _ in range(30):
        obs, *_ = env.step(zero_actions(env))
    before = float(obs["infant_0"]["touch"].sum())
    q = toy_qpos(w, "teddy")
    chest = d.xpos[m.body("infant_0/upper_body").id]
    d.qpos[q:q + 3] = chest + (0.0, 0.0, 0.16)
    d.qvel[:] = 0.0
    mujoco.mj_forward(m, d)
    for _ in range(25):
        obs, _, _, _, infos = env.step(zero_actions(env))
    after = float(obs["infant_0"]["touch"].sum())
    weight = TOYS["teddy"].mass * 9.81
    assert d.qpos[q + 2] > 0.1                       # the teddy lies on the infant
    # felt where it lies, and again on the back, which the mat now pushes harder: up to twice
    assert 0.5 * weight < after - before < 2.5 * weight
    touched = infos["infant_0"]["touch"]
    assert any(v["object"] for v in touched.values())
    toy_geoms = set(np.flatnonzero(m.geom_bodyid == m.body("playroom/teddy").id))
    pairs = {(int(g1), int(g2)) for g1, g2 in zip(d.contact.geom1[:d.ncon], d.contact.geom2[:d.ncon])}
    assert any((a in toy_geoms and w.geom_agent[b] == 0) or (b in toy_geoms and w.geom_agent[a] == 0)
               for a, b in pairs)


def test_a_toy_in_front_of_the_eyes_is_seen():
    env = free_play_v0.parallel_env(n_agents=1, scene="playroom",
                                    vision={"width": 64, "height": 64})
    w, m, d = env.world, env.world.model, env.world.data
    env.reset(seed=0)
    obs, *_ = env.step(zero_actions(env))
    plain = obs["infant_0"]["eye_left"].astype(int)
    cam = int(w.agents[0].eye_cameras[1])             # the left eye
    ahead = d.cam_xpos[cam] - 0.3 * d.cam_xmat[cam].reshape(3, 3)[:, 2]
    q = toy_qpos(w, "ball_blue")
    d.qpos[q:q + 3] = ahead
    mujoco.mj_forward(m, d)
    obs, *_ = env.step(zero_actions(env))
    seen = obs["infant_0"]["eye_left"].astype(int)
    changed = np.any(np.abs(seen - plain) > 30, axis=-1)
    blue = (seen[..., 2] > seen[..., 0] + 60) & (seen[..., 2] > 120)
    assert changed.sum() > 100 and (blue & changed).sum() > 80
    ys, xs = np.nonzero(blue & changed)
    assert abs(xs.mean() - 31.5) < 12 and abs(ys.mean() - 31.5) < 16   # where the ball is


# -- determinism and pickling -------------------------------------------------------------------
def _run(env, seed, n):
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    for _ in range(n):
        env.step(random_actions(env, rng))
    return env.state()


def test_the_playroom_is_deterministic_under_a_seed():
    kw = dict(n_agents=2, scene="playroom", touch=True)
    a = _run(free_play_v0.parallel_env(**kw), 5, 15)
    b = _run(free_play_v0.parallel_env(**kw), 5, 15)
    assert np.array_equal(a, b)


@pytest.mark.parametrize("sleep", [False, True], ids=["awake", "toys_asleep"])
def test_a_pickled_env_in_the_playroom_continues_identically(sleep, monkeypatch):
    """Also with the toys asleep (``World.ROOM_SLEEP``, off by default): MuJoCo 4.0.0's pickle
    of MjData drops the awake counters, which the world carries itself."""
    monkeypatch.setattr(World, "ROOM_SLEEP", sleep)
    env = high_five_v0.scripted_env(scene="playroom", per_agent=ADULT,
                                    task_options={"end_on_touch": False})
    inner = env.unwrapped
    obs, _ = env.reset(seed=2)
    rng = np.random.default_rng(0)
    for _ in range(60):
        env.step(random_actions(env, rng))
    assert np.any(inner.world.data.tree_asleep >= 0) == sleep   # resting toys asleep
    copy = pickle.loads(pickle.dumps(env))
    assert copy.unwrapped.world.room == inner.world.room
    for _ in range(10):
        a = random_actions(env, rng)
        o1, r1, *_ = env.step(a)
        o2, r2, *_ = copy.step(a)
        assert r1 == r2
    assert np.array_equal(inner.state(), copy.unwrapped.state())


@pytest.mark.parametrize("task,steps", [("reach", 40), ("high_five", 12)])
def test_agents_move_as_on_the_floor_until_they_touch_the_room(task, steps):
    """The room adds bodies and geoms, not forces: a scripted episode's agents follow the same
    trajectory in the play room as on the floor (the toys on the mat lie out of their reach).
    High five for 12 control steps: the sparse Jacobian factors the room's larger system (its
    toys' contacts) in another order, and from the step the hands meet the scripted controller's
    feedback amplifies the rounding (the largest joint difference 6e-17 at step 12, 3e-4 at
    step 16, 5e-2 at step 24); with the dense Jacobian the two agree to 1e-9 over 40 steps."""
    e = entry(task)
    out, start = {}, {}
    for scene in ("floor", "playroom"):
        env = e.scripted_env(scene=scene)
        inner = env.unwrapped
        obs, _ = env.reset(seed=0)
        w = inner.world
        start[scene] = np.concatenate([w.data.qpos[a.qpos_adr] for a in w.agents])
        ctrl = e.controller()
        ctrl.reset(inner, "infant_0", np.random.default_rng(0))
        for _ in range(steps):
            obs, _, term, trunc, _ = env.step(
                {"infant_0": ctrl.act(inner, "infant_0", obs["infant_0"])})
            if term["infant_0"] or trunc["infant_0"]:
                break
        out[scene] = np.concatenate([w.data.qpos[a.qpos_adr] for a in w.agents])
    assert np.abs(out["floor"] - start["floor"]).max() > 0.01   # the arm did move
    np.testing.assert_allclose(out["playroom"], out["floor"], atol=1e-9)


@pytest.mark.parametrize("posture", ["standing", "lying"])
def test_eight_infants_fit_and_crowded_toys_go_to_their_spare_places(posture):
    """Free play's circle of 8 infants fits inside the furniture; the mat's toys in its way
    start on the furniture instead, and stay there."""
    env = free_play_v0.parallel_env(n_agents=8, posture=posture, scene="playroom")
    w = env.world
    moved = w.toys_moved
    assert moved and set(moved) <= set(w.room.spares)
    env.reset(seed=0)
    for _ in range(30):
        env.step(zero_actions(env))
    for body in moved:
        xyz = w.data.xpos[w.model.body(body).id]
        spare = np.array(w.room.spares[body])
        assert np.linalg.norm(xyz[:2] - spare[:2]) < 0.05, body
        assert abs(xyz[2] - spare[2]) < 0.02, body     # on the furniture, not fallen off
