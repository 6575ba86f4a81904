"""Faces in the 3D replay (issue 31): the default camera looks from where the faces show best, the
heads' textures are warmer with stronger features, the eyeballs drawn larger; the model (what the
agents' eyes render) and the face panels' images are unchanged."""

from __future__ import annotations

import numpy as np
import pytest

from mimo_social.experiments.demo import demo_env
from mimo_social.expressions.faces import SKIN_RGB, face_images
from mimo_social.recording.blueprint import face_visibility, scene_eye
from mimo_social.recording.faces import HEAD_SKIN_RGB, head_texture
from mimo_social.recording.geometry import EYE_SCALE, geom_archetype


@pytest.fixture(scope="module")
def demo():
    env = demo_env()
    env.reset(seed=0)
    yield env
    env.close()


def _faces(env):
    d = env.world.data
    sites = [a.head_site for a in env.world.agents]
    return d.site_xpos[sites], d.site_xmat[sites].reshape(-1, 3, 3)[:, :, 0]


def test_visibility_is_the_cosine_of_the_face_to_the_camera():
    heads = np.zeros((3, 3))
    faces = np.array([[1.0, 0, 0], [0, 1.0, 0], [-1.0, 0, 0]])
    np.testing.assert_allclose(face_visibility(heads, faces, (2.0, 0, 0)), [1, 0, -1])


def test_the_default_camera_sees_the_faces_better_than_the_scene_camera(demo):
    """The demo's pair faces each other: from the scene camera's direction the infant's face is
    edge-on (about 86 degrees from face on); the recording's camera sees both faces better."""
    heads, faces = _faces(demo)
    cam = demo.scene_camera()
    az, el = np.deg2rad(cam.azimuth), np.deg2rad(cam.elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    before = face_visibility(heads, faces, np.array(cam.lookat) - cam.distance * forward)
    eye = scene_eye(demo)
    position = np.asarray(eye.position.as_arrow_array().to_pylist()[0])
    target = np.asarray(eye.look_target.as_arrow_array().to_pylist()[0])
    after = face_visibility(heads, faces, position)
    assert after.min() > before.min() + 0.15, (before, after)
    np.testing.assert_allclose(target, cam.lookat, atol=1e-6)        # it looks at the same place
    room = demo.world.room
    assert np.all(np.abs(position[:2] - room.centre) < 2.0)         # inside the 4 x 4 m room
    view = (target - position) / np.linalg.norm(target - position)
    assert np.all((heads - position) @ view > 0.5)                   # every head in front of it


def test_a_head_texture_is_warmer_and_its_features_stronger():
    face = face_images(64)[1]                                         # happy
    tex = head_texture(face)
    skin = np.all(face == SKIN_RGB, axis=-1)
    assert skin.mean() > 0.5 and np.all(tex[skin] == HEAD_SKIN_RGB)
    dark = face.astype(int).sum(-1) < 400                             # lines, mouth, irises
    assert dark.any()
    assert tex[dark].astype(int).sum(-1).mean() < face[dark].astype(int).sum(-1).mean() - 40
    def contrast(img):   # how far the features' brightness is from the skin's, on average
        light = img.astype(float) @ (0.299, 0.587, 0.114)
        return np.abs(light[~skin] - light[skin][0]).mean()

    assert contrast(tex) > 1.15 * contrast(face)


def test_the_eyeballs_are_drawn_larger_about_their_centre(demo):
    m = demo.world.model
    for part, kind in (("right_eye", "half_sizes"), ("right_eye_iris", "centers")):
        g = m.geom(f"infant_0/{part}").id
        plain, big = geom_archetype(m, g), geom_archetype(m, g, scale=EYE_SCALE)
        a = np.asarray(getattr(plain, kind).as_arrow_array().to_pylist()[0])
        b = np.asarray(getattr(big, kind).as_arrow_array().to_pylist()[0])
        np.testing.assert_allclose(b, EYE_SCALE * a, rtol=1e-6)
    assert 1.2 <= EYE_SCALE <= 2.0
