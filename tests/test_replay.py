"""Rerun recordings (`mimo_social.replay`) and the `demo` subcommand, checked by reading the .rrd
files back with Rerun's own reader (`rerun.chunk.RrdReader`)."""

import argparse
import importlib.util
import shutil
import subprocess
import warnings
from collections import defaultdict

import mujoco
import numpy as np
import pyarrow as pa
import pytest
from rerun.chunk import RrdReader

from mimo_social import demo
from mimo_social.envs import free_play_v0
from mimo_social.expressions.faces import EXPRESSIONS, face_image
from mimo_social.replay import HIDDEN_GEOM_GROUP, Recorder, record_episode

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
        # the eye spheres (group 3) are hidden: no body entity for them
        assert f"/world/{agent}/right_eye" not in data
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
        np.testing.assert_allclose(world_centre, geom_xpos[g], atol=2e-5, err_msg=path)
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


def test_single_agent_adapter(tmp_path):
    from mimo_social.envs.single import make_reach

    genv = make_reach()
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


# -- the demo --------------------------------------------------------------------------------------

def test_demo_parser_defaults():
    parser = argparse.ArgumentParser()
    demo.add_parser(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["demo"])
    assert (args.record, args.seconds, args.n_agents, args.seed) == (
        "recordings/demo.rrd", 10.0, 2, 0)
    assert args.func is demo.run


def test_demo_noise_is_smooth_and_seeded():
    a = demo.SmoothNoise(44, 0.01, np.random.default_rng(3))
    b = demo.SmoothNoise(44, 0.01, np.random.default_rng(3))
    xs = np.array([a() for _ in range(2000)])
    np.testing.assert_array_equal(xs[-1], [b() for _ in range(2000)][-1])
    assert 0.25 < xs[500:].std() < 0.6                      # moves over the whole range ...
    steps = np.abs(np.diff(xs, axis=0))
    assert steps.mean() < 0.02 and steps.max() < 0.1        # ... without jumping


def test_demo_subcommand_writes_a_readable_recording(tmp_path, capsys):
    if importlib.util.find_spec("mimo_social.bench") is None:
        pytest.skip("mimo_social.cli also needs mimo_social.bench, which is not there yet")
    from mimo_social.cli import main

    path = tmp_path / "sub" / "demo.rrd"
    assert main(["demo", "--seconds", "1", "--record", str(path), "--seed", "4"]) == 0
    out = capsys.readouterr().out
    assert str(path) in out and "rerun" in out
    data = read_rrd(path)
    for agent in ("infant_0", "infant_1"):
        hip = rows(data, f"/world/{agent}/hip", "Transform3D:translation")
        assert [s for s, _, _ in hip] == list(range(101))
        assert rows(data, f"/agents/{agent}/expression", "TextLog:text")[0][2] == ["neutral"]
        assert len(rows(data, f"/agents/{agent}/action_norm", "Scalars:scalars")) == 100
    assert path.stat().st_size < 1_000_000
