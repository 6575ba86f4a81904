"""Binocular vision: what the eyes see, how the images follow the eyes, spaces, scheduling,
worker processes and pickling."""

import os
import pickle
import signal
import subprocess
import sys
import textwrap

import mujoco
import numpy as np
import pytest

from mimo_social.envs import free_play_v0
from mimo_social.render import eye_renderer
from mimo_social.senses.vision import anaglyph, eye_images, render_now, save_anaglyph, vision_system

S = 64


@pytest.fixture(scope="module")
def env():
    e = free_play_v0.parallel_env(n_agents=2, vision={"width": S, "height": S},
                                  task_options={"props": True})
    e.reset(seed=0)
    yield e
    e.close()


def zero_actions(env, expressions=(0, 0)):
    return {a: {"motors": np.zeros(env.action_space(a)["motors"].shape, np.float32),
                "expression": e} for a, e in zip(env.agents, expressions)}


def camera_pixel(env, cam_id, point, width, height):
    """Column, row (from the top) and depth of a world point in an eye camera's image."""
    d = env.world.data
    R = d.cam_xmat[cam_id].reshape(3, 3)
    x, y, z = R.T @ (np.asarray(point) - d.cam_xpos[cam_id])
    f = (height / 2) / np.tan(np.deg2rad(env.world.model.cam_fovy[cam_id]) / 2)
    return width / 2 + f * x / -z, height / 2 - f * y / -z, -z, f


def image_shift(before, after, max_shift=20):
    """(dx, dy) that best maps ``before`` onto ``after``: after[r, c] ~ before[r - dy, c - dx]."""
    a, b = before.astype(float), after.astype(float)
    best, arg = np.inf, None
    h, w = a.shape[:2]
    for dy in range(-max_shift, max_shift + 1):
        for dx in range(-max_shift, max_shift + 1):
            sa = a[max(0, -dy):h - max(0, dy), max(0, -dx):w - max(0, dx)]
            sb = b[max(0, dy):h - max(0, -dy), max(0, dx):w - max(0, -dx)]
            err = np.mean(np.abs(sa - sb))
            if err < best:
                best, arg = err, (dx, dy)
    return arg


def test_infant_sees_the_partners_face_change_expression_not_its_own(env):
    env.reset(seed=0)
    w = env.world
    before = eye_images(env, 0)
    head = w.data.geom_xpos[w.agents[1].head_geom]
    radius = w.model.geom_size[w.agents[1].head_geom, 0]
    w.set_expression(1, 1)  # infant_1 smiles
    render_now(env)
    after = eye_images(env, 0)
    for eye, cam in zip(("right", "left"), w.agents[0].eye_cameras):
        changed = np.any(before[f"eye_{eye}"] != after[f"eye_{eye}"], axis=2)
        assert changed.sum() >= 5, f"{eye} eye: the partner's new expression is not visible"
        u, v, depth, f = camera_pixel(env, cam, head, S, S)
        assert 0 < u < S and 0 < v < S and 0.3 < depth < 1.0
        rows, cols = np.nonzero(changed)
        dist = np.hypot(cols + 0.5 - u, rows + 0.5 - v)
        assert dist.max() <= f * radius / depth + 1.5, "pixels outside the face changed"
        # the face is left-right symmetric: its changes centre on the head's projection
        assert abs(cols.mean() + 0.5 - u) < 1.5, (eye, cols.mean() + 0.5, u)
    w.set_expression(0, 3)  # infant_0 is surprised: its own face is behind its eyes
    render_now(env)
    own = eye_images(env, 0)
    for key in ("eye_left", "eye_right"):
        assert np.array_equal(own[key], after[key])
    w.set_expression(0, 0)
    w.set_expression(1, 0)


def test_expression_actions_reach_the_partners_eyes(env):
    env.reset(seed=0)
    obs0, *_ = env.step(zero_actions(env, (0, 0)))
    for _ in range(2):
        obs1, *_ = env.step(zero_actions(env, (0, 3)))
    diff = np.any(obs0["infant_0"]["eye_left"] != obs1["infant_0"]["eye_left"], axis=2)
    assert diff.sum() >= 5


def set_joint(env, agent, joint, value):
    a = env.world.agents[agent]
    env.world.data.qpos[a.qpos_adr[a.joint_names.index(joint)]] = value


def test_eye_joints_shift_the_image(env):
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    base = eye_images(env, 0)
    angle = 0.15  # rad
    f = (S / 2) / np.tan(np.deg2rad(30))
    expected = f * np.tan(angle)
    # positive horizontal angles turn each eye outwards: the right eye looks right, the left
    # eye left; what it sees moves the other way in its image
    set_joint(env, 0, "right_eye_horizontal", angle)
    set_joint(env, 0, "left_eye_horizontal", angle)
    mujoco.mj_forward(m, d)
    render_now(env)
    turned = eye_images(env, 0)
    dx_r, dy_r = image_shift(base["eye_right"], turned["eye_right"])
    dx_l, dy_l = image_shift(base["eye_left"], turned["eye_left"])
    assert dx_r < 0 and dx_l > 0, (dx_r, dx_l)
    assert 0.6 * expected <= -dx_r <= 1.4 * expected and 0.6 * expected <= dx_l <= 1.4 * expected
    assert abs(dy_r) <= 1 and abs(dy_l) <= 1
    # positive vertical angles look up: the scene moves down the image
    set_joint(env, 0, "right_eye_horizontal", 0.0)
    set_joint(env, 0, "left_eye_horizontal", 0.0)
    set_joint(env, 0, "right_eye_vertical", angle)
    set_joint(env, 0, "left_eye_vertical", angle)
    mujoco.mj_forward(m, d)
    render_now(env)
    up = eye_images(env, 0)
    for eye in ("left", "right"):
        dx, dy = image_shift(base[f"eye_{eye}"], up[f"eye_{eye}"])
        assert 0.6 * expected <= dy <= 1.4 * expected and abs(dx) <= 1, (eye, dx, dy)
    env.reset(seed=0)


def test_near_ball_has_horizontal_disparity(env):
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    right_cam, left_cam = env.world.agents[0].eye_cameras
    forward = -(d.cam_xmat[right_cam].reshape(3, 3)[:, 2]
                + d.cam_xmat[left_cam].reshape(3, 3)[:, 2]) / 2
    centre = (d.cam_xpos[right_cam] + d.cam_xpos[left_cam]) / 2
    adr = env.world.prop_qpos["ball"]

    def place(pos):
        d.qpos[adr:adr + 3] = pos
        d.qpos[adr + 3:adr + 7] = (1, 0, 0, 0)
        mujoco.mj_forward(m, d)
        render_now(env)
        return eye_images(env, 0)

    away = place((5.0, 5.0, 0.04))
    near = place(centre + 0.15 * forward)
    cols = {}
    for eye in ("left", "right"):
        mask = np.any(away[f"eye_{eye}"] != near[f"eye_{eye}"], axis=2)
        assert mask.sum() > 50, f"the ball is not in the {eye} eye's image"
        cols[eye] = np.nonzero(mask)[1].mean()
    # seen from the left eye the ball lies to the right of straight ahead, and vice versa
    assert cols["left"] - cols["right"] > 8, cols
    assert cols["left"] > S / 2 > cols["right"]
    env.reset(seed=0)


def test_stereo_pairs_match_one_eye_at_a_time(env):
    """Both eyes in one side-by-side stereo draw give each eye's own view (no offsets)."""
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    jobs = []
    for a in env.world.agents:
        right, left = (int(c) for c in a.eye_cameras)
        jobs += [(len(jobs), left), (len(jobs) + 1, right)]
    tiles = [eye_renderer.Tile(S, S) for _ in jobs]
    groups = [[0, 1], [2, 3]]
    pair = eye_renderer.TileRenderer(tiles, groups)
    mono = eye_renderer.TileRenderer(tiles, groups, stereo=False)
    assert pair.pairs == {0: 1, 2: 3}
    a, b = pair.render(m, d, jobs), mono.render(m, d, jobs)
    for t in range(4):
        assert np.array_equal(a[t][0], b[t][0]), t
    pair.close()
    mono.close()


def test_tiles_beyond_one_buffer_render_in_batches(env):
    """More eyes than fit the buffer's side limit: several batches, the same images."""
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    cams = [int(c) for a in env.world.agents for c in a.eye_cameras]
    jobs = list(enumerate(cams + cams[:2]))
    tiles = [eye_renderer.Tile(S, S) for _ in jobs]
    groups = [[0, 1], [2, 3], [4, 5]]
    small = eye_renderer.TileRenderer(tiles, groups, limit=2 * S)
    big = eye_renderer.TileRenderer(tiles, groups)
    assert small.n_batches == 2 and small.buffer_size == (2 * S, 2 * S)
    assert big.n_batches == 1 and big.buffer_size == (2 * S, 3 * S)
    a, b = small.render(m, d, jobs), big.render(m, d, jobs)
    for t in range(len(jobs)):  # a tile drawn elsewhere in the buffer may differ in a pixel
        diff = np.abs(a[t][0].astype(int) - b[t][0])
        assert diff.max() <= 2 and np.mean(diff > 0) < 0.002, t
    assert np.array_equal(a[0][0], a[4][0])  # same camera, same place, another batch
    small.close()
    big.close()


def test_spaces_follow_the_configuration():
    off = free_play_v0.parallel_env(n_agents=2)
    for a in off.possible_agents:
        assert not any(k.startswith(("eye_", "depth_")) for k in off.observation_space(a).spaces)
    env = free_play_v0.parallel_env(
        n_agents=3, per_agent=[{"vision": {"width": 40, "height": 32, "depth": True}},
                               {"vision": False}, {"vision": {"width": 24, "height": 16}}])
    sp = [env.observation_space(a).spaces for a in env.possible_agents]
    assert sp[0]["eye_left"].shape == (32, 40, 3) and sp[0]["eye_right"].dtype == np.uint8
    assert sp[0]["depth_left"].shape == (32, 40) and sp[0]["depth_right"].dtype == np.float32
    assert not any(k.startswith(("eye_", "depth_")) for k in sp[1])
    assert sp[2]["eye_right"].shape == (16, 24, 3) and "depth_left" not in sp[2]
    obs, _ = env.reset(seed=0)
    for a in env.possible_agents:
        assert env.observation_space(a).contains(obs[a]), a
    assert obs["infant_2"]["eye_left"].std() > 5  # a real image, not a blank one
    # depth: metres along the eye's viewing axis, as a ray cast through the pixel centre finds
    m, d = env.world.model, env.world.data
    depth = obs["infant_0"]["depth_left"]
    assert np.all(depth > 0.01) and depth.max() > 10  # the sky is far
    cam = env.world.agents[0].eye_cameras[1]
    R = d.cam_xmat[cam].reshape(3, 3)
    f = 16 / np.tan(np.deg2rad(30))
    head_body = m.geom_bodyid[env.world.agents[0].head_geom]
    hits = 0
    for row in range(2, 32, 3):
        for col in range(2, 40, 3):
            ray = R @ np.array([(col + 0.5 - 20) / f, -(row + 0.5 - 16) / f, -1.0])
            z = mujoco.mj_ray(m, d, d.cam_xpos[cam], ray, np.array([1, 1, 1, 0, 0, 0], np.uint8),
                              1, head_body, np.array([-1], np.int32))  # in units of ray: z-depth
            # a ray near a silhouette can hit the true round surface and miss its polygon
            # (or the reverse): there the rendered depth jumps between neighbouring pixels
            near = depth[max(row - 1, 0):row + 2, max(col - 1, 0):col + 2]
            edge = near.max() - near.min() > 0.05
            if z < 0:
                assert depth[row, col] > 10 or edge, (row, col, depth[row, col])
            else:
                hits += 1
                assert abs(depth[row, col] - z) < 0.01 + 0.02 * z or edge, \
                    (row, col, depth[row, col], z)
    assert hits > 50
    env.close()


def test_every_k_holds_images_between_renders():
    env = free_play_v0.parallel_env(n_agents=2, vision={"width": 32, "height": 32, "every": 3})
    obs0, _ = env.reset(seed=0)
    system = vision_system(env)
    assert system.renders == {0: 1, 1: 1}
    held = [obs0]
    for _ in range(2):
        obs, *_ = env.step(zero_actions(env, (0, 3)))  # the partner changes expression
        held.append(obs)
    for obs in held[1:]:
        for key in ("eye_left", "eye_right"):
            assert np.array_equal(obs["infant_0"][key], obs0["infant_0"][key])
    held[1]["infant_0"]["eye_left"][:] = 0  # observations are the caller's to change
    assert np.array_equal(held[2]["infant_0"]["eye_right"], obs0["infant_0"]["eye_right"])
    assert system.renders == {0: 1, 1: 1}
    obs3, *_ = env.step(zero_actions(env, (0, 3)))
    assert system.renders == {0: 2, 1: 2}
    assert np.any(obs3["infant_0"]["eye_left"] != obs0["infant_0"]["eye_left"])
    env.close()


def test_pickle_after_rendering_recreates_the_renderer(env, tmp_path):
    env.reset(seed=0)
    env.step(zero_actions(env))
    system = vision_system(env)
    assert system.renderer is not None and system.renderer._con is not None
    clone = pickle.loads(pickle.dumps(env))
    csys = vision_system(clone)
    assert csys.renderer is None
    render_now(clone)
    for i in (0, 1):
        a, b = eye_images(env, i), eye_images(clone, i)
        for key in a:
            assert np.array_equal(a[key], b[key]), (i, key)
    obs, *_ = clone.step(zero_actions(clone))
    assert obs["infant_1"]["eye_left"].shape == (S, S, 3)
    env.step(zero_actions(env))  # the original still renders
    clone.close()


def test_anaglyph(env, tmp_path):
    env.reset(seed=0)
    imgs = eye_images(env, "infant_0")
    img = save_anaglyph(env, "infant_0", tmp_path / "a.png", scale=2)
    assert np.array_equal(img[..., 0], imgs["eye_left"][..., 0])
    assert np.array_equal(img[..., 1:], imgs["eye_right"][..., 1:])
    data = (tmp_path / "a.png").read_bytes()
    assert data.startswith(b"\x89PNG") and len(data) > 500
    with pytest.raises(ValueError):
        anaglyph(imgs["eye_left"], imgs["eye_left"][:10])


def test_missing_gl_backend_says_what_to_install(monkeypatch):
    def broken(*args, **kwargs):
        raise OSError("libEGL.so.1: cannot open shared object file")
    monkeypatch.setattr(eye_renderer, "_GL", None)
    monkeypatch.setattr(mujoco, "GLContext", broken)
    with pytest.raises(RuntimeError, match="apt-get install"):
        eye_renderer.shared_gl_context()


VEC_SCRIPT = textwrap.dedent("""
    import functools
    import sys
    import numpy as np
    import mimo_social
    from mimo_social.envs import free_play_v0
    from mimo_social.train.vector import sb3_vec_env

    if __name__ == "__main__":
        fn = functools.partial(free_play_v0.parallel_env, n_agents=2,
                               vision={"width": 32, "height": 32}, max_steps=20)
        venv = sb3_vec_env(fn, n_envs=2, n_cpus=2, start_method=sys.argv[1])
        venv.seed(0)
        obs = venv.reset()
        rng = np.random.default_rng(0)
        low, high = venv.action_space.low, venv.action_space.high
        for _ in range(30):
            obs, rew, done, info = venv.step(rng.uniform(low, high, (venv.num_envs,) + low.shape))
        assert obs.shape[0] == 4 and np.isfinite(obs).all()
        venv.close()
        print("VEC-OK", obs.shape)
""")


@pytest.mark.parametrize("start_method", ["spawn", "forkserver"])
def test_two_process_vector_env_with_vision_does_not_hang(tmp_path, start_method):
    script = tmp_path / "vec.py"
    script.write_text(VEC_SCRIPT)
    proc = subprocess.Popen([sys.executable, str(script), start_method], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True,
                            cwd=os.getcwd())
    try:
        out, _ = proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        pytest.fail(f"the vector env with vision hung:\n{out[-3000:]}")
    assert proc.returncode == 0 and "VEC-OK" in out, out[-3000:]


def test_bench_vision_command_and_report():
    from mimo_social.bench import vision_cost
    from mimo_social.cli import build_parser

    args = build_parser().parse_args(["bench", "vision", "--backends", "egl", "--rounds", "2"])
    assert (args.backends, args.rounds, args.sim_seconds, args.worker) == ("egl", 2, 5.0, False)
    res = {"egl": {"images": [{"agents": 1, "size": 64, "variant": "final", "ms_per_image": 0.2},
                              {"variant": "readback_rgb_mjr_readPixels", "ms_per_2x256x256": 1.0}],
                   "env": [{"config": "1 infant", "vision": 0.05, "total": 0.3,
                            "physics": 0.2}]}}
    text = vision_cost.format_results(res)
    assert "| final | 0.200 |" in text and "readback_rgb_mjr_readPixels: 1.000 ms" in text
    assert "egl | 1 infant | vision 0.0500 | total 0.3000" in text
