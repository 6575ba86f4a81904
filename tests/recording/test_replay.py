"""Rerun recordings (`mimo_social.recording`), checked by reading the .rrd files back with Rerun's
own reader (`rerun.chunk.RrdReader`); the demo's recording: tests/recording/test_demo.py."""

import shutil
import subprocess
import warnings
from collections import defaultdict

import mujoco
import numpy as np
import pyarrow as pa
import pytest
import rerun.blueprint as rrb
from rerun.chunk import RrdReader

from mimo_social.envs import free_play_v0
from mimo_social.expressions.faces import EXPRESSIONS, face_image
from mimo_social.recording import HIDDEN_GEOM_GROUP, Recorder, force_radii, record_episode
from mimo_social.recording.geometry import EYE_PARTS, EYE_SCALE
from mimo_social.recording.summary import summarize
from mimo_social.recording.torn import salvage

N_STEPS = 50
CHANGE_STEP = 20          # infant_1 turns happy at this step (1-based env.step count)
HAPPY = EXPRESSIONS.index("happy")


# -- reading recordings back -----------------------------------------------------------------------

def read_rrd(path) -> dict[str, list[pa.RecordBatch]]:
    """Entity path -> the record batches of its chunks, for the recording store of ``path``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # a file still being written has no footer yet
        chunks = RrdReader(path).stream().to_chunks()
    out = defaultdict(list)
    for chunk in chunks:
        out[chunk.entity_path].append(chunk.to_record_batch())
    return dict(out)


def rows(data, path: str, component: str) -> list[tuple]:
    """(step, sim_time in ns, value) of every non-null ``component`` row at ``path``, by step.

    Static rows have step and time None.
    """
    out = []
    for batch in data.get(path, []):
        names = batch.schema.names
        if component not in names:
            continue
        values = batch.column(component).to_pylist()
        steps = batch.column("step").to_pylist() if "step" in names else [None] * len(values)
        times = (batch.column("sim_time").cast(pa.int64()).to_pylist() if "sim_time" in names
                 else [None] * len(values))
        out += [(s, t, v) for s, t, v in zip(steps, times, values) if v is not None]
    return sorted(out, key=lambda r: -1 if r[0] is None else r[0])


def static_value(data, path: str, component: str):
    found = [v for s, _, v in rows(data, path, component) if s is None]
    assert len(found) == 1, f"{path} {component}: {len(found)} static rows"
    return np.asarray(found[0], dtype=np.float64)


def rotate_xyzw(q, v):
    """Rotate vector ``v`` by the unit quaternion ``q`` given as (x, y, z, w)."""
    w = q[3]
    u = np.asarray(q[:3])
    return v + 2.0 * np.cross(u, np.cross(u, v) + w * v)


# -- a recorded episode ----------------------------------------------------------------------------

@pytest.fixture(scope="module")
def env():
    e = free_play_v0.parallel_env(n_agents=2, task_options={"props": True})
    yield e
    e.close()


@pytest.fixture(scope="module")
def episode(env, tmp_path_factory):
    """50 steps of 2 infants (+ props) with out-of-range motor commands, made-up rewards and one
    expression change, recorded and read back."""
    path = tmp_path_factory.mktemp("rec") / "episode.rrd"
    rng = np.random.default_rng(1)
    sent = []
    env.reset(seed=0)
    with Recorder(env, path) as rec:
        rec.log_reset()
        for k in range(1, N_STEPS + 1):
            actions = {a: {"motors": rng.uniform(-1.3, 1.3, 44).astype(np.float32),
                           "expression": HAPPY if (a == "infant_1" and k >= CHANGE_STEP) else 0}
                       for a in env.agents}
            env.step(actions)
            rewards = {a: 0.5 * k + i for i, a in enumerate(env.agents)}
            rec.log_step(actions, rewards)
            sent.append((actions, rewards))
    final = {"geom_xpos": env.world.data.geom_xpos.copy()}
    return {"path": path, "data": read_rrd(path), "sent": sent, "final": final, "rec": rec}


def _visible_bodies(world, agent_index):
    m = world.model
    a = world.agents[agent_index]
    return [int(b) for b in a.body_ids
            if np.any((m.geom_bodyid == b) & (m.geom_group != HIDDEN_GEOM_GROUP))]


def test_every_body_of_every_agent_has_one_pose_row_per_logged_step(env, episode):
    data, world = episode["data"], env.world
    dt_ns = round(env.dt * 1e9)
    assert episode["rec"].rows == N_STEPS + 1
    for i, agent in enumerate(env.possible_agents):
        bodies = _visible_bodies(world, i)
        assert len(bodies) > 15
        for b in bodies:
            path = f"/world/{agent}/{world.model.body(b).name.removeprefix(agent + '/')}"
            for component in ("Transform3D:translation", "Transform3D:quaternion"):
                r = rows(data, path, component)
                assert [s for s, _, _ in r] == list(range(N_STEPS + 1)), (path, component)
                times = np.array([t for _, t, _ in r])
                np.testing.assert_allclose(times, np.arange(N_STEPS + 1) * dt_ns, atol=1000)
        # the eyeballs are drawn (they show where each agent looks): a body entity each
        assert f"/world/{agent}/right_eye" in data
    for prop in ("ball", "cube"):
        assert len(rows(data, f"/world/props/{prop}", "Transform3D:translation")) == N_STEPS + 1
    assert rows(data, "/world/scene/floor", "Boxes3D:half_sizes")


@pytest.mark.skipif(shutil.which("rerun") is None, reason="the rerun command is not installed")
def test_rerun_itself_verifies_the_file(episode):
    done = subprocess.run(["rerun", "rrd", "verify", str(episode["path"])], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr


def test_static_geometry_has_the_right_shapes_and_colours(env, episode):
    data, m = episode["data"], env.world.model
    for agent in env.possible_agents:
        assert rows(data, f"/world/{agent}/hip/hip", "Capsules3D:lengths")
        assert rows(data, f"/world/{agent}/right_hand/right_palm", "Boxes3D:half_sizes")
        assert rows(data, f"/world/{agent}/head/head", "Mesh3D:vertex_texcoords")
        assert not any(p.startswith(f"/world/{agent}/head/right_eye") for p in data)
        colour = static_value(data, f"/world/{agent}/hip/hip", "Capsules3D:colors")
        expected = np.round(m.geom_rgba[m.geom(f"{agent}/hip").id] * 255)
        rgba = [(int(colour[0]) >> s) & 0xFF for s in (24, 16, 8, 0)]
        np.testing.assert_allclose(rgba, expected, atol=1)   # 0..1 floats to bytes
    radius = static_value(data, "/world/props/ball/ball", "Ellipsoids3D:half_sizes")
    np.testing.assert_allclose(radius[0], [0.04] * 3, rtol=1e-6)


def test_recorded_poses_put_every_geom_where_mujoco_has_it(env, episode):
    """Last pose row of each body composed with the static geom placement == data.geom_xpos."""
    data, m = episode["data"], env.world.model
    geom_xpos = episode["final"]["geom_xpos"]
    checked = 0
    for g in range(m.ngeom):
        b = int(m.geom_bodyid[g])
        if b == 0 or m.geom_group[g] == HIDDEN_GEOM_GROUP:
            continue
        body, geom = m.body(b).name, m.geom(g).name
        agent = body.split("/")[0] if "/" in body else None
        base = f"/world/{agent}/{body.split('/', 1)[1]}" if agent else f"/world/props/{body}"
        path = f"{base}/{geom.split('/', 1)[1] if agent else geom}"
        t = np.asarray(rows(data, base, "Transform3D:translation")[-1][2][0])
        q = np.asarray(rows(data, base, "Transform3D:quaternion")[-1][2][0])
        kind = int(m.geom_type[g])
        if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
            start = static_value(data, path, "Capsules3D:translations")[0]
            gq = static_value(data, path, "Capsules3D:quaternions")[0]
            half = static_value(data, path, "Capsules3D:lengths")[0] / 2
            local = start + rotate_xyzw(gq, np.array([0.0, 0.0, half]))
        elif kind == mujoco.mjtGeom.mjGEOM_BOX:
            local = static_value(data, path, "Boxes3D:centers")[0]
        elif kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
            local = static_value(data, path, "Cylinders3D:centers")[0]
        elif kind == mujoco.mjtGeom.mjGEOM_SPHERE and path.endswith("/head"):
            local = static_value(data, path, "Mesh3D:vertex_positions").mean(axis=0)
        elif kind in (mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_ELLIPSOID):
            local = static_value(data, path, "Ellipsoids3D:centers")[0]
        else:
            continue
        world_centre = t + rotate_xyzw(q, local)
        expected = geom_xpos[g]
        if agent and path.endswith(EYE_PARTS):   # eyeballs drawn larger about the eye's centre
            expected = t + EYE_SCALE * (expected - t)
        np.testing.assert_allclose(world_centre, expected, atol=2e-5, err_msg=path)
        checked += 1
    assert checked > 60


def test_expression_change_appears_at_its_step_and_time(env, episode):
    data = episode["data"]
    dt_ns = round(env.dt * 1e9)
    changed = rows(data, "/agents/infant_1/expression", "TextLog:text")
    assert [(s, v) for s, _, v in changed] == [(0, ["neutral"]), (CHANGE_STEP, ["happy"])]
    assert abs(changed[1][1] - CHANGE_STEP * dt_ns) <= 1000
    same = rows(data, "/agents/infant_0/expression", "TextLog:text")
    assert [(s, v) for s, _, v in same] == [(0, ["neutral"])]
    faces = rows(data, "/agents/infant_1/face", "Image:buffer")
    assert [s for s, _, _ in faces] == [0, CHANGE_STEP]
    assert bytes(faces[1][2][0]) == face_image("happy", 64).tobytes()
    textures = rows(data, "/world/infant_1/head/head", "Mesh3D:albedo_texture_buffer")
    assert [s for s, _, _ in textures] == [0, CHANGE_STEP]


def test_every_change_is_in_the_text_log_but_only_held_faces_get_images(env, tmp_path):
    path = tmp_path / "flicker.rrd"
    names = ["happy", "sad", "happy"] + ["angry"] * 10 + ["scared"]   # the last one at the end
    env.reset(seed=0)
    with Recorder(env, path) as rec:                                  # face_hold_s=0.05: 5 steps
        rec.log_reset()
        for name in names:
            actions = {a: {"motors": np.zeros(44, np.float32),
                           "expression": EXPRESSIONS.index(name)} for a in env.possible_agents}
            env.step(actions)
            rec.log_step(actions)
    data = read_rrd(path)
    text = rows(data, "/agents/infant_0/expression", "TextLog:text")
    assert [(s, v[0]) for s, _, v in text] == [(0, "neutral"), (1, "happy"), (2, "sad"),
                                               (3, "happy"), (4, "angry"), (14, "scared")]
    faces = rows(data, "/agents/infant_0/face", "Image:buffer")
    assert [s for s, _, _ in faces] == [0, 4, 14]          # the flicker gets no images
    assert bytes(faces[1][2][0]) == face_image("angry", 64).tobytes()


def test_rewards_and_action_norms(env, episode):
    data, sent = episode["data"], episode["sent"]
    for i, agent in enumerate(env.possible_agents):
        reward = rows(data, f"/agents/{agent}/reward", "Scalars:scalars")
        assert [s for s, _, _ in reward] == list(range(1, N_STEPS + 1))   # none at the reset row
        np.testing.assert_allclose([v[0] for _, _, v in reward], [r[agent] for _, r in sent])
        norm = rows(data, f"/agents/{agent}/action_norm", "Scalars:scalars")
        expected = [np.linalg.norm(np.clip(a[agent]["motors"], -1, 1)) for a, _ in sent]
        np.testing.assert_allclose([v[0] for _, _, v in norm], expected, rtol=1e-6)


def test_every_k_steps_sums_rewards_and_later_episodes_continue_the_timeline(env, tmp_path):
    path = tmp_path / "k5.rrd"
    zero = {a: {"motors": np.zeros(44, np.float32), "expression": 0} for a in env.possible_agents}
    with Recorder(env, path, every_k_steps=5) as rec:
        for _ in range(2):
            env.reset(seed=0)
            rec.log_reset()
            for _ in range(10):
                env.step(zero)
                rec.log_step(zero, {"infant_0": 1.0, "infant_1": 2.0})
    data = read_rrd(path)
    hip = rows(data, "/world/infant_0/hip", "Transform3D:translation")
    assert [s for s, _, _ in hip] == [0, 5, 10, 11, 16, 21]
    times = [t for _, t, _ in hip]
    assert all(b > a for a, b in zip(times, times[1:]))
    assert times[3] == pytest.approx(times[2] + env.dt * 1e9, abs=1000)
    reward = rows(data, "/agents/infant_1/reward", "Scalars:scalars")
    assert [(s, v[0]) for s, _, v in reward] == [(5, 10.0), (10, 10.0), (16, 10.0), (21, 10.0)]


def test_flushed_rows_are_in_the_file_before_close(env, tmp_path):
    """A crash loses at most the rows buffered since the last flush (here 0.25 s = 25 rows)."""
    path = tmp_path / "open.rrd"
    zero = {a: {"motors": np.zeros(44, np.float32), "expression": 0} for a in env.possible_agents}
    env.reset(seed=0)
    rec = Recorder(env, path, flush_every_s=0.25)
    rec.log_reset()
    for _ in range(60):
        env.step(zero)
        rec.log_step(zero)
    before = rows(read_rrd(path), "/world/infant_1/head", "Transform3D:translation")
    assert [s for s, _, _ in before] == list(range(50))
    rec.close()
    after = rows(read_rrd(path), "/world/infant_1/head", "Transform3D:translation")
    assert [s for s, _, _ in after] == list(range(61))
    for late_call in (rec.log_reset, lambda: rec.log_step(zero)):
        with pytest.raises(RuntimeError, match="closed"):
            late_call()


def test_record_episode_helper(env, tmp_path):
    summary = record_episode(env, tmp_path / "helper.rrd", seed=3, max_steps=5)
    assert (summary["steps"], summary["rows"]) == (5, 6)
    hip = rows(read_rrd(summary["path"]), "/world/infant_0/hip", "Transform3D:translation")
    assert [s for s, _, _ in hip] == list(range(6))


def test_misuse_is_reported(env, tmp_path):
    with Recorder(env, tmp_path / "x.rrd") as rec:
        with pytest.raises(RuntimeError, match="log_reset"):
            rec.log_step({})
    with pytest.raises(ValueError, match="every_k_steps"):
        Recorder(env, tmp_path / "y.rrd", every_k_steps=0)
    with pytest.raises(TypeError, match="MimoParallelEnv"):
        Recorder(object(), tmp_path / "z.rrd")


def test_malformed_actions_are_refused_naming_agent_field_and_value(env, tmp_path):
    """log_step checks the actions as env.step does: an unknown agent, a wrong shape, NaN, a bad
    expression or no dict at all is a ValueError naming the agent, the field, the value and what
    is allowed, and adds no row; a missing agent (done or scripted) is allowed."""
    u = np.zeros(44, np.float32)
    bad = [({"infant_9": {"motors": u, "expression": 0}}, ["infant_9", "unknown", "infant_1"]),
           ({"infant_0": {"motors": np.zeros(3), "expression": 0}},
            ["infant_0", "'motors'", "shape (3,)", "(44,)"]),
           ({"infant_1": {"motors": np.full(44, np.nan), "expression": 0}},
            ["infant_1", "'motors'", "NaN", "finite"]),
           ({"infant_0": {"motors": u, "expression": 9}}, ["infant_0", "expression=9", "0..6"]),
           ({"infant_0": u}, ["infant_0", "'motors' and 'expression'"]),
           ("zeros", ["actions='zeros'", "dict agent -> action"])]
    path = tmp_path / "checked.rrd"
    with Recorder(env, path) as rec:
        env.reset(seed=0)
        rec.log_reset()
        for actions, words in bad:
            with pytest.raises(ValueError) as err:
                rec.log_step(actions)
            for word in ["Recorder.log_step", *words]:
                assert word in str(err.value), f"{word!r} not in {str(err.value)!r}"
        rec.log_step({"infant_1": {"motors": u + 0.5, "expression": 0}})   # infant_0 done
    norm = rows(read_rrd(path), "/agents/infant_1/action_norm", "Scalars:scalars")
    assert [(s, round(v[0], 6)) for s, _, v in norm] == [(1, round(0.5 * 44 ** 0.5, 6))]
    assert rows(read_rrd(path), "/agents/infant_0/action_norm", "Scalars:scalars") == []


def test_single_agent_adapter(tmp_path):
    import gymnasium as gym

    genv = gym.make("mimo_social/Reach-v0").unwrapped
    path = tmp_path / "single.rrd"
    with Recorder(genv, path) as rec:
        genv.reset(seed=0)
        rec.log_reset()
        sent = []
        for _ in range(10):
            action = genv.action_space.sample()
            _, reward, *_ = genv.step(action)
            rec.log_step(action, reward)
            sent.append(reward)
    genv.close()
    data = read_rrd(path)
    agent = genv.agent
    assert len(rows(data, f"/world/{agent}/hip", "Transform3D:translation")) == 11
    reward = rows(data, f"/agents/{agent}/reward", "Scalars:scalars")
    np.testing.assert_allclose([v[0] for _, _, v in reward], sent)


# -- eyes, skin, contacts, chosen scalars ----------------------------------------------------------

def decode_png(data: bytes) -> np.ndarray:
    """A small PNG reader (8-bit RGB or grey, any row filter) to check the stored eye images."""
    import struct
    import zlib

    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,), kind = struct.unpack(">I", data[pos:pos + 4]), data[pos + 4:pos + 8]
        payload = data[pos + 8:pos + 8 + length]
        assert struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])[0] == \
            zlib.crc32(kind + payload) & 0xFFFFFFFF
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", payload)
        elif kind == b"IDAT":
            idat += payload
        pos += 12 + length
    w, h, depth, colour = header[:4]
    assert depth == 8 and colour in (0, 2)
    ch = 3 if colour == 2 else 1
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(h, 1 + w * ch)
    out = np.zeros((h, w * ch), np.int64)
    for r in range(h):
        f, line = raw[r, 0], raw[r, 1:].astype(np.int64)
        up = out[r - 1] if r else np.zeros(w * ch, np.int64)
        row = np.zeros(w * ch, np.int64)
        for x in range(w * ch):
            a = row[x - ch] if x >= ch else 0
            b, c = up[x], (up[x - ch] if x >= ch else 0)
            pred = {0: 0, 1: a, 2: b, 3: (a + b) // 2}.get(int(f))
            if pred is None:   # Paeth
                p = a + b - c
                pa_, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa_ <= pb and pa_ <= pc else (b if pb <= pc else c)
            row[x] = (line[x] + pred) % 256
        out[r] = row
    return out.astype(np.uint8).reshape(h, w, ch) if ch == 3 else out.astype(np.uint8)


def zero_actions(env, expression=0):
    out = {}
    for a in env.agents:
        space = env.action_space(a)
        motors = np.zeros(space["motors"].shape if hasattr(space, "spaces") else space.shape,
                          np.float32)
        out[a] = {"motors": motors, "expression": expression} if hasattr(space, "spaces") \
            else motors
    return out


def test_png_encoder_round_trips_every_byte():
    from mimo_social.render.png import encode_png

    rng = np.random.default_rng(0)
    for shape in ((5, 7, 3), (64, 64, 3), (3, 4)):
        img = rng.integers(0, 256, shape, dtype=np.uint8)
        np.testing.assert_array_equal(decode_png(encode_png(img)), img)
    with pytest.raises(ValueError, match="uint8"):
        encode_png(np.zeros((4, 4, 3)))


def test_no_eyes_skin_or_touch_entities_when_those_senses_are_off(env, episode):
    data = episode["data"]
    for agent in env.possible_agents:
        assert not [p for p in data if p.startswith(f"/agents/{agent}/eyes")]
        assert f"/world/{agent}/skin" not in data
        assert f"/agents/{agent}/touch_total" not in data
    assert episode["rec"].eye_frames == 0


@pytest.fixture(scope="module")
def vision_env():
    try:
        import mimo_social.senses.vision  # noqa: F401
    except ImportError as e:
        pytest.skip(f"mimo_social.senses.vision cannot be imported yet: {e}")
    try:
        e = free_play_v0.parallel_env(n_agents=2, vision={"width": 64, "height": 64})
        obs, _ = e.reset(seed=0)
    except Exception as exc:   # no GL here, or vision not finished
        pytest.skip(f"vision does not build here: {type(exc).__name__}: {exc}")
    if "eye_left" not in obs["infant_0"]:
        pytest.skip("vision builds but gives no eye_left observation yet")
    yield e
    e.close()


def test_eye_images_of_every_agent_at_every_step_lossless(vision_env, tmp_path):
    env, path = vision_env, tmp_path / "eyes.rrd"
    obs, _ = env.reset(seed=0)
    seen = [obs]
    rng = np.random.default_rng(0)
    with Recorder(env, path, eye_every_k_steps=1) as rec:     # every frame (default: 25 Hz)
        rec.log_reset(obs)
        for _ in range(8):
            actions = {a: {"motors": rng.uniform(-1, 1, 44).astype(np.float32), "expression": 0}
                       for a in env.agents}
            obs, rewards, *_ = env.step(actions)
            rec.log_step(actions, rewards, obs)
            seen.append(obs)
    assert rec.eye_frames == 2 * 9
    data = read_rrd(path)
    for agent in env.possible_agents:
        for eye in ("left", "right"):
            blobs = rows(data, f"/agents/{agent}/eyes/{eye}", "EncodedImage:blob")
            assert [s for s, _, _ in blobs] == list(range(9))
            media = rows(data, f"/agents/{agent}/eyes/{eye}", "EncodedImage:media_type")
            assert {v[0] for _, _, v in media} == {"image/png"}
            for step, _, blob in blobs:
                np.testing.assert_array_equal(decode_png(bytes(blob[0])),
                                              seen[step][agent][f"eye_{eye}"])
    # the images change as the infants move
    assert not np.array_equal(seen[0]["infant_0"]["eye_left"], seen[-1]["infant_0"]["eye_left"])
    if shutil.which("rerun"):
        done = subprocess.run(["rerun", "rrd", "verify", str(path)], capture_output=True,
                              text=True, timeout=120)
        assert done.returncode == 0, done.stdout + done.stderr


def test_eye_images_every_k_steps_raw_and_only_when_rendered_anew(tmp_path):
    try:
        import mimo_social.senses.vision  # noqa: F401
        env = free_play_v0.parallel_env(n_agents=2, per_agent=[
            {"vision": {"width": 32, "height": 24}}, {"vision": {"width": 32, "height": 24,
                                                                "every": 2}}])
        env.reset(seed=0)
    except Exception as exc:
        pytest.skip(f"vision does not build here: {type(exc).__name__}: {exc}")
    path = tmp_path / "raw.rrd"
    zero = zero_actions(env)
    with Recorder(env, path, eye_format="raw", eye_every_k_steps=1) as rec:
        obs, _ = env.reset(seed=0)
        rec.log_reset()                       # no observations: read from the vision system
        last = None
        for _ in range(6):
            obs, *_ = env.step(zero)
            rec.log_step(zero, None, obs)
            last = obs
    data = read_rrd(path)
    buf0 = rows(data, "/agents/infant_0/eyes/left", "Image:buffer")
    assert [s for s, _, _ in buf0] == list(range(7))
    buf1 = rows(data, "/agents/infant_1/eyes/right", "Image:buffer")
    assert [s for s, _, _ in buf1] == [0, 2, 4, 6]   # rendered at reset, then every 2nd step
    fmt = rows(data, "/agents/infant_0/eyes/left", "Image:format")[0][2][0]
    assert (fmt["width"], fmt["height"]) == (32, 24)
    np.testing.assert_array_equal(
        np.frombuffer(bytes(buf0[-1][2][0]), np.uint8).reshape(24, 32, 3),
        last["infant_0"]["eye_left"])
    env.close()
    with pytest.raises(ValueError, match="eye_format"):
        Recorder(env, tmp_path / "bad.rrd", eye_format="gif")


def test_eye_images_as_jpeg_or_left_out(vision_env, tmp_path):
    env = vision_env
    zero = zero_actions(env)
    for options in ({"eye_format": "jpeg"}, {"eyes": False}):
        if options.get("eye_format") == "jpeg":
            pytest.importorskip("PIL", reason="eye_format='jpeg' needs Pillow")
        path = tmp_path / f"{len(options)}{list(options.values())[0]}.rrd"
        obs, _ = env.reset(seed=0)
        with Recorder(env, path, eye_every_k_steps=1, **options) as rec:
            rec.log_reset(obs)
            for _ in range(2):
                obs, *_ = env.step(zero)
                rec.log_step(zero, None, obs)
        data = read_rrd(path)
        blobs = rows(data, "/agents/infant_1/eyes/right", "EncodedImage:blob")
        if options.get("eyes") is False:
            assert blobs == [] and rec.eye_frames == 0
            continue
        from PIL import Image as PILImage
        import io
        assert [s for s, _, _ in blobs] == [0, 1, 2]
        media = rows(data, "/agents/infant_1/eyes/right", "EncodedImage:media_type")
        assert {v[0] for _, _, v in media} == {"image/jpeg"}
        img = np.asarray(PILImage.open(io.BytesIO(bytes(blobs[-1][2][0]))))
        assert img.shape == (64, 64, 3)
        assert np.abs(img.astype(int) - obs["infant_1"]["eye_right"]).mean() < 8   # lossy


def blueprint_nodes(node):
    """Every container and view of a blueprint tree."""
    yield node
    for child in getattr(node, "contents", None) or []:
        yield from blueprint_nodes(child)


def test_blueprint_puts_each_agents_eyes_side_by_side(vision_env, tmp_path):
    with Recorder(vision_env, tmp_path / "bp.rrd") as rec:
        nodes = list(blueprint_nodes(rec.blueprint().root_container))
    for agent in vision_env.possible_agents:
        eyes = [n for n in nodes if isinstance(n, rrb.Horizontal)
                and [getattr(c, "origin", None) for c in n.contents]
                == [f"/agents/{agent}/eyes/left", f"/agents/{agent}/eyes/right"]]
        assert len(eyes) == 1, f"no Horizontal with {agent}'s left and right eye side by side"
    views = {n.name: n for n in nodes if isinstance(n, (rrb.Spatial3DView, rrb.TimeSeriesView))}
    assert views["world"].origin == "/world"
    assert isinstance(views["head_height (m)"], rrb.TimeSeriesView)   # free play: no reward


def test_blueprint_without_vision_has_no_eyes_but_touch_totals(tmp_path):
    env = free_play_v0.parallel_env(n_agents=2, touch=True)
    with Recorder(env, tmp_path / "bp.rrd") as rec:
        nodes = list(blueprint_nodes(rec.blueprint().root_container))
    assert not [n for n in nodes if "eyes" in str(getattr(n, "origin", ""))]
    names = {n.name for n in nodes if isinstance(n, rrb.TimeSeriesView)}
    assert {"touch totals (N)", "action norms"} <= names
    assert any(isinstance(n, rrb.TextLogView) and n.origin == "/events/contacts" for n in nodes)


def test_blueprint_starts_with_the_selection_panel_collapsed(tmp_path):
    env = free_play_v0.parallel_env(n_agents=1)
    with Recorder(env, tmp_path / "sel.rrd") as rec:
        panel = rec.blueprint().selection_panel
    assert panel is not None and str(panel.state) == "collapsed"


@pytest.fixture(scope="module")
def touch_episode(tmp_path_factory):
    env = free_play_v0.parallel_env(n_agents=2, touch=True)
    path = tmp_path_factory.mktemp("touch") / "touch.rrd"
    zero = zero_actions(env)
    obs, _ = env.reset(seed=0)
    with Recorder(env, path, flush_every_s=0.1) as rec:
        rec.log_reset(obs)
        for _ in range(30):
            obs, rewards, *_ = env.step(zero)
            rec.log_step(zero, rewards, obs)
    system = env.system("touch")
    views = {a: system.view(a) for a in env.possible_agents}
    yield {"env": env, "data": read_rrd(path), "views": views}
    env.close()


def test_skin_points_with_force_every_step_in_world_coordinates(touch_episode):
    from mimo_social.recording import force_colors

    data, views = touch_episode["data"], touch_episode["views"]
    for agent, view in views.items():
        pts = rows(data, f"/world/{agent}/skin", "Points3D:positions")
        assert [s for s, _, _ in pts] == list(range(31))       # every row, empty or not
        final = np.array(pts[-1][2], dtype=np.float64)
        on = [(v["points"][k], np.linalg.norm(v["forces"][k]), v["normal_force"][k])
              for v in view.values() for k in np.flatnonzero(v["normal_force"])]
        assert len(on) > 5 and len(final) == len(on)         # standing: the soles feel the floor
        expected = np.array([p for p, _, _ in on])
        gap = np.linalg.norm(expected[:, None, :] - final[None, :, :], axis=2)
        assert gap.min(axis=1).max() < 1e-5 and gap.min(axis=0).max() < 1e-5   # the same points
        assert len(set(gap.argmin(axis=1).tolist())) == len(on)
        assert final[:, 2].min() < 0.03                       # the soles, on the floor
        colors = rows(data, f"/world/{agent}/skin", "Points3D:colors")[-1][2]
        want = force_colors(np.array([f for _, f, _ in on]))
        assert sorted(colors) == sorted(want.tolist())
        assert len(set(colors)) > 3                           # the forces differ
        radii = rows(data, f"/world/{agent}/skin", "Points3D:radii")[-1][2]   # grow with force
        assert sorted(radii) == sorted(force_radii(np.array([f for _, f, _ in on])).tolist())
        total = rows(data, f"/agents/{agent}/touch_total", "Scalars:scalars")
        assert [s for s, _, _ in total] == list(range(31))
        assert total[-1][2][0] == pytest.approx(sum(n for _, _, n in on), rel=1e-9)
        assert total[-1][2][0] > 50        # about the infant's weight (~10 kg) on the floor


def test_force_colours_go_from_yellow_to_dark_red():
    from mimo_social.recording import force_colors

    colors = force_colors(np.array([0.0, 0.1, 1.0, 100.0]))
    rgb = [[(int(c) >> s) & 0xFF for s in (24, 16, 8, 0)] for c in colors]
    assert rgb[0][:2] == [255, 235] and rgb[-1][0] < 150 and rgb[-1][1] == 0
    assert all(np.diff([g for _, g, _, _ in rgb]) < 0) and {a for *_, a in rgb} == {255}


def contact_pairs(env) -> set[tuple[str, str]]:
    """Body parts of two different agents in contact, with a plain loop over the contacts."""
    m, d, w = env.world.model, env.world.data, env.world
    out = set()
    for k in range(d.ncon):
        c = d.contact[k]
        g1, g2 = int(c.geom1), int(c.geom2)
        a1, a2 = int(w.geom_agent[g1]), int(w.geom_agent[g2])
        if a1 < 0 or a2 < 0 or a1 == a2 or c.dist > 0:
            continue
        ends = sorted([(a1, m.body(int(m.geom_bodyid[g1])).name),
                       (a2, m.body(int(m.geom_bodyid[g2])).name)])
        out.add(tuple(f"infant_{a} {name.split('/', 1)[1]}" for a, name in ends))
    return out


@pytest.fixture(scope="module")
def high_five(tmp_path_factory):
    """High five with the infants 0.3 m apart, both right arms swinging forward until the right
    hands meet (the task's reward bonus says when), recorded with a chosen scalar."""
    from mimo_social.envs import high_five_v0

    env = high_five_v0.parallel_env(task_options={"end_on_touch": False, "distance": 0.3,
                                                  "success": "touch"},   # any touch of the hands
                                    touch=True)
    path = tmp_path_factory.mktemp("hf") / "high_five.rrd"
    u = np.zeros(8, np.float32)
    u[:2] = -1.0
    expected, touching, distance, active = [], [], [], set()
    obs, _ = env.reset(seed=0)
    scalars = {"task/hand_distance": lambda e: e.task._distance if e.task._steps_seen else np.nan}
    env.task._steps_seen = False
    with Recorder(env, path, scalars=scalars) as rec:
        rec.log_reset(obs)
        for k in range(1, 91):
            actions = {a: {"motors": u, "expression": 0} for a in env.agents}
            obs, rewards, _, _, infos = env.step(actions)
            env.task._steps_seen = True
            rec.log_step(actions, rewards, obs)
            now = contact_pairs(env)
            expected += [(k, f"{a} touches {b}") for a, b in sorted(now - active)]
            active = now
            touching.append(infos["infant_0"]["hands_touching"])
            distance.append(infos["infant_0"]["hand_distance"])
    yield {"env": env, "data": read_rrd(path), "expected": expected, "touching": touching,
           "distance": distance, "rec": rec, "path": path}
    env.close()


def test_contact_between_agents_is_one_event_when_it_starts(high_five):
    data, expected = high_five["data"], high_five["expected"]
    touch_step = high_five["touching"].index(True) + 1          # the right hands meet here
    assert touch_step > 20
    events = [(s, v[0]) for s, _, v in rows(data, "/events/contacts", "TextLog:text")]
    starts = [(s, t.rsplit(" (", 1)[0]) for s, t in events if " stops touching " not in t]
    assert starts == expected                  # each with its force (N); the ends: test_contacts_*
    assert high_five["rec"].contact_events == len(events)
    hands = [(s, text) for s, text in starts if s == touch_step]
    assert hands, f"no contact event at step {touch_step}: {events}"
    assert all(text.startswith("infant_0 right_") and " touches infant_1 right_" in text
               for _, text in hands)
    # the hands stay together for the rest of the episode: no event repeats every step
    assert sum(high_five["touching"]) > 5 and len(events) < 10
    assert not any(e[0] < touch_step for e in events)


@pytest.mark.skipif(shutil.which("rerun") is None, reason="the rerun command is not installed")
def test_rerun_verifies_a_file_with_skin_contacts_and_scalars(high_five):
    done = subprocess.run(["rerun", "rrd", "verify", str(high_five["path"])],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr


def test_chosen_scalars_and_touch_totals_of_high_five(high_five):
    data = high_five["data"]
    hd = rows(data, "/scalars/task/hand_distance", "Scalars:scalars")
    assert [s for s, _, _ in hd] == list(range(1, 91))        # NaN (none) at the reset row
    np.testing.assert_allclose([v[0] for _, _, v in hd], high_five["distance"])
    for agent in ("infant_0", "infant_1"):
        assert len(rows(data, f"/agents/{agent}/touch_total", "Scalars:scalars")) == 91
    with pytest.raises(ValueError, match="scalars"):
        Recorder(high_five["env"], high_five["path"].with_name("x.rrd"), scalars={"a": 3})


def test_scalar_that_fails_names_itself(env, tmp_path):
    env.reset(seed=0)
    with Recorder(env, tmp_path / "fail.rrd", scalars={"broken": lambda e: 1 / 0}) as rec:
        with pytest.raises(RuntimeError, match="broken.*ZeroDivisionError"):
            rec.log_reset()


# -- recording during training ---------------------------------------------------------------------

def complete(path) -> bool:
    """Whether the file was closed properly (Rerun warns when the footer is missing)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        RrdReader(path).stream().to_chunks()
    return not any("footer" in str(w.message) for w in caught)


def hip_steps(path) -> list[int]:
    return [s for s, _, _ in rows(read_rrd(path), "/world/infant_0/hip", "Transform3D:translation")]


def test_recording_wrapper_records_every_kth_episode_and_pickles(tmp_path):
    import pickle

    from mimo_social.recording import RecordingParallelEnv

    env = RecordingParallelEnv(free_play_v0.parallel_env(n_agents=2, max_steps=4),
                               tmp_path / "ep{episode:02d}.rrd", every_k_episodes=2)
    assert env.possible_agents == ["infant_0", "infant_1"]
    copies = []
    for episode in range(5):
        obs, _ = env.reset(seed=episode)
        assert set(obs) == set(env.agents)
        steps = 0
        while env.agents:
            env.step(zero_actions(env))
            steps += 1
            if episode == 2 and steps == 2:    # pickled while recording: the copy has no file
                copies.append(pickle.loads(pickle.dumps(env)))
        assert env.recorder is None            # closed when the episode ended
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ep00.rrd", "ep02.rrd", "ep04.rrd"]
    for name in ("ep00.rrd", "ep02.rrd", "ep04.rrd"):
        assert hip_steps(tmp_path / name) == list(range(5))   # reset + 4 steps
        assert complete(tmp_path / name)
    copy = copies[0]
    assert copy.recorder is None and copy.episode == 2
    copy.step(zero_actions(copy))       # carries on unrecorded; its next chosen episode records
    copy.reset(seed=0)                  # episode 3: not recorded
    copy.reset(seed=0)                  # episode 4: records again, to the same pattern
    assert copy.recorder is not None
    copy.close()
    env.close()
    with pytest.raises(ValueError, match="every_k_episodes"):
        RecordingParallelEnv(env.env, tmp_path / "x{episode}.rrd", every_k_episodes=0)
    with pytest.raises(ValueError, match="path_pattern"):
        RecordingParallelEnv(env.env, tmp_path / "x{world}.rrd")


def _high_five_short():
    from mimo_social.envs import high_five_v0
    return high_five_v0.parallel_env(max_steps=3)


@pytest.mark.parametrize("n_cpus", [0, 2])
def test_vector_env_records_every_kth_episode_of_sub_env_0_only(tmp_path, n_cpus):
    pytest.importorskip("stable_baselines3")
    pytest.importorskip("supersuit")
    from mimo_social.train.vector import sb3_vec_env
    from mimo_social.recording import recording_env_fn

    env_fn = recording_env_fn(_high_five_short, str(tmp_path / "ep{episode:03d}.rrd"),
                              every_k_episodes=2)
    venv = sb3_vec_env(env_fn, n_envs=2, n_cpus=n_cpus)
    try:
        venv.seed(0)
        venv.reset()
        rng = np.random.default_rng(0)
        low, high = venv.action_space.low, venv.action_space.high
        for _ in range(15):            # 5 episodes of 3 steps in each world
            venv.step(rng.uniform(low, high, (venv.num_envs,) + low.shape).astype(np.float32))
    finally:
        venv.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ep000.rrd", "ep002.rrd", "ep004.rrd"]
    for name in ("ep000.rrd", "ep002.rrd", "ep004.rrd"):
        data = read_rrd(tmp_path / name)
        hip = rows(data, "/world/infant_1/hip", "Transform3D:translation")
        assert [s for s, _, _ in hip] == [0, 1, 2, 3]
        norms = rows(data, "/agents/infant_0/action_norm", "Scalars:scalars")
        assert len(norms) == 3 and all(v[0] > 0 for _, _, v in norms)
        assert complete(tmp_path / name)


CRASH_SCRIPT = """
import os, signal, sys
import numpy as np
import mimo_social
from mimo_social.envs import free_play_v0
from mimo_social.recording import Recorder

env = free_play_v0.parallel_env(n_agents=2, max_steps=10**9)
obs, _ = env.reset(seed=0)
rec = Recorder(env, sys.argv[1], flush_every_s=0.25)
rec.log_reset(obs)
rng = np.random.default_rng(0)
while True:
    actions = {a: {"motors": rng.uniform(-1, 1, 44).astype(np.float32), "expression": 2}
               for a in env.agents}
    obs, rewards, *_ = env.step(actions)
    rec.log_step(actions, rewards, obs)
    if rec.flushed_rows >= int(sys.argv[2]):
        print(rec.flushed_rows, rec.flushed_step, rec.rows, flush=True)
        os.kill(os.getpid(), signal.SIGKILL)       # no close(), no footer, rows in the buffer
"""


@pytest.mark.parametrize("confirmed", [50, 75])
def test_recording_of_a_killed_run_is_readable_up_to_the_last_flushed_step(tmp_path, confirmed):
    import sys

    path = tmp_path / "killed.rrd"
    done = subprocess.run([sys.executable, "-c", CRASH_SCRIPT, str(path), str(confirmed)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == -9, done.stderr
    flushed_rows, flushed_step, logged = map(int, done.stdout.split())
    assert flushed_rows >= confirmed and logged > flushed_rows   # some rows died in the buffer
    whole = tmp_path / "whole.rrd"        # a kill while Rerun writes tears the last frame (rarely)
    torn = salvage(path, whole)
    assert not complete(whole)
    data = read_rrd(whole)
    summary = summarize(path)                    # the project's reader takes the file as it is
    assert not summary["complete"] and summary["torn_bytes"] == torn
    assert summary["step_range"][1] >= flushed_step
    for agent in ("infant_0", "infant_1"):
        steps = [s for s, _, _ in rows(data, f"/world/{agent}/head", "Transform3D:translation")]
        assert steps == list(range(len(steps)))            # a gapless prefix ...
        assert steps[-1] >= flushed_step                   # ... up to the last flushed step
        faces = rows(data, f"/agents/{agent}/expression", "TextLog:text")
        assert [(s, v[0]) for s, _, v in faces][:2] == [(0, "neutral"), (1, "sad")]
