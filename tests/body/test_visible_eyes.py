"""Visible eyes: each eyeball (white sclera, iris, pupil) turns with its eye joints, is seen by
the other agents' eyes and not by its own, carries no mass, contact or touch of its own."""

import numpy as np
import pytest

from mimo_social.body.builder import build_infant
from mimo_social.body.tables import load_body
from mimo_social.envs import free_play_v0, joint_attention_v0

SIDES = ("right", "left")
ZERO = np.zeros(9, np.float32)


@pytest.mark.parametrize("hands", ["mitten", "five_fingers"])
def test_iris_and_pupil_are_visual_only_and_the_eye_keeps_its_mass(hands):
    m = build_infant(hands).spec.compile()
    tables = load_body(hands)
    for side in SIDES:
        eye = m.body(f"{side}_eye").id
        sclera, iris, pupil = (m.geom(f"{side}_eye{s}") for s in ("", "_iris", "_pupil"))
        for g in (sclera, iris, pupil):
            assert g.group[0] == 0 and g.rgba[3] == 1.0          # drawn by every renderer
            assert g.bodyid[0] == eye                          # they turn with the eye joints
        assert np.all(sclera.rgba[:3] > 0.9)                   # white
        assert np.all(pupil.rgba[:3] < 0.1) and iris.rgba[0] > pupil.rgba[0]
        for g in (iris, pupil):
            assert g.contype[0] == 0 and g.conaffinity[0] == 0
        # the eye body is the tables' sphere alone: its mass, a solid sphere's inertia
        row = next(g for g in tables.geoms if g.body == f"{side}_eye")
        assert m.body_mass[eye] == pytest.approx(row.mass, rel=1e-12)
        r = row.size[0]
        np.testing.assert_allclose(m.body_inertia[eye], 0.4 * row.mass * r * r, rtol=1e-9)
        np.testing.assert_allclose(m.body_ipos[eye], 0.0, atol=1e-12)
        # the eye camera sits on the line of sight in front of the pupil, outside the eyeball
        cam = m.camera(f"{side}_eye")
        front = pupil.pos[0] + pupil.size[1]
        assert cam.pos[0] > front > r and abs(cam.pos[1]) < 1e-12 and abs(cam.pos[2]) < 1e-12


def test_iris_and_pupil_have_no_touch_sensors():
    env = free_play_v0.parallel_env(n_agents=1, touch=True)
    env.reset(seed=0)
    m = env.world.model
    touch = env.system("touch")
    for side in SIDES:
        for part in ("_iris", "_pupil"):
            assert touch.geom_part[m.geom(f"infant_0/{side}_eye{part}").id] == -1


def _face_to_face(size=96):
    env = joint_attention_v0.parallel_env(vision={"width": size, "height": size})
    env.reset(seed=0)
    return env


def test_an_eye_sees_the_partners_eyeballs_but_never_its_own():
    """Paint infant_0's eyeballs magenta: infant_1 sees magenta where infant_0's eyes are;
    infant_0's own eyes (looking straight, then turned fully to each side) see none."""
    env = _face_to_face()
    m = env.world.model
    for side in SIDES:
        for part in ("", "_iris", "_pupil"):
            m.geom_rgba[m.geom(f"infant_0/{side}_eye{part}").id] = (1, 0, 1, 1)

    def magenta(img):
        img = img.astype(int)
        return int(((img[..., 0] > 150) & (img[..., 2] > 150) & (img[..., 1] < 60)).sum())

    for h, v in ((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)):
        a0 = ZERO.copy()
        a0[[3, 6]], a0[[4, 7]] = h, v
        for _ in range(25):
            obs, *_ = env.step({"infant_0": a0, "infant_1": ZERO})
        for eye in ("eye_left", "eye_right"):
            assert magenta(obs["infant_0"][eye]) == 0, (h, v, eye)
            assert magenta(obs["infant_1"][eye]) >= 2, (h, v, eye)


def _project(data, cam, points, size, fovy_deg):
    """Pixel (row, col) of world points in camera ``cam`` (looking along its -z, +y up)."""
    R = data.cam_xmat[cam].reshape(3, 3)
    rel = (points - data.cam_xpos[cam]) @ R
    f = size / 2 / np.tan(np.deg2rad(fovy_deg) / 2)
    return np.stack([size / 2 - f * rel[:, 1] / -rel[:, 2],
                     size / 2 + f * rel[:, 0] / -rel[:, 2]], axis=1)


@pytest.mark.parametrize("h, v", [(1, 0), (-1, 0), (0, 1)])
def test_partner_eye_rotation_changes_the_image_only_where_its_eyes_are(h, v):
    """Two runs from the same state; only the partner's eye motors differ (head motors, the
    learner: zero). The learner's eye images change around the partner's eyes, hardly
    elsewhere."""
    size = 128
    runs = []
    for turn in (False, True):
        env = _face_to_face(size)
        a1 = ZERO.copy()
        if turn:
            a1[[3, 6]], a1[[4, 7]] = h, v
        for _ in range(30):
            obs, *_ = env.step({"infant_0": ZERO, "infant_1": a1})
        w = env.world
        names = list(w.agents[1].joint_names)
        angle = w.data.qpos[w.agents[1].qpos_adr[names.index("right_eye_horizontal")]]
        runs.append((obs["infant_0"], angle, env))
    (still, a_still, env), (turned, a_turned, _) = runs
    assert abs(a_still) < np.deg2rad(1)
    if h:
        assert abs(a_turned) > np.deg2rad(30)                   # the eyes did turn
    w = env.world
    d, m = w.data, w.model
    eyes = d.xpos[[m.body(f"infant_1/{s}_eye").id for s in SIDES]]
    for k, eye in enumerate(("eye_right", "eye_left")):
        cam = int(w.agents[0].eye_cameras[k])
        centres = _project(d, cam, eyes, size, m.cam_fovy[cam])
        diff = np.abs(turned[eye].astype(int) - still[eye].astype(int)).max(axis=2)
        rows, cols = np.mgrid[:size, :size]
        near = np.zeros((size, size), bool)
        for r, c in centres:
            near |= np.hypot(rows - r, cols - c) < 4.0             # ~1.5 eyeball radii
        assert (diff[near] > 25).sum() >= 4, eye                  # the irises moved
        for r, c in centres:                                      # at each eye
            assert diff[np.hypot(rows - r, cols - c) < 4.0].max() > 40, (eye, r, c)
        assert diff[~near].max() <= 12, eye                       # nothing else visibly
