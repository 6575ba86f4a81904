"""Lines of sight and view frusta from the eye cameras (mimo_social.body.sight), on a built
infant: what lies straight ahead of the eyes is in view, what lies behind or beside them is
not, the frustum's edge is the field of view's, and the line of sight is the eyes' axis."""

import numpy as np

from mimo_social.body.sight import gaze_rays, in_view
from mimo_social.envs import free_play_v0


def _eyes():
    env = free_play_v0.parallel_env(n_agents=1)
    env.reset(seed=0)
    w = env.unwrapped.world
    return w.data, np.asarray(w.agents[0].eye_cameras), w.model


def test_the_line_of_sight_is_the_mean_of_the_eyes_axes_from_between_them():
    d, cams, _ = _eyes()
    origin, direction = gaze_rays(d, cams)
    np.testing.assert_allclose(origin, d.cam_xpos[cams].mean(axis=0))
    assert abs(np.linalg.norm(direction) - 1.0) < 1e-12
    for c in cams:       # each eye's -z axis within a few degrees of the line of sight
        assert -d.cam_xmat[c].reshape(3, 3)[:, 2] @ direction > np.cos(np.deg2rad(10))
    # batched: two agents' worth of eye pairs give two rays
    o2, d2 = gaze_rays(d, np.stack([cams, cams]))
    assert o2.shape == d2.shape == (2, 3)
    np.testing.assert_allclose(d2[1], direction)


def test_points_ahead_are_in_view_and_points_behind_or_beside_are_not():
    d, cams, m = _eyes()
    origin, direction = gaze_rays(d, cams)
    half = np.tan(np.deg2rad(m.cam_fovy[cams]) / 2.0)
    ahead, behind = origin + 0.5 * direction, origin - 0.5 * direction
    side = np.cross(direction, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    beside = origin + 0.01 * direction + 0.5 * side          # about 89 degrees off the axis
    got = in_view(d, cams, np.stack([ahead, behind, beside]), half)
    assert got.shape == (3, 2)
    assert got[0].all() and not got[1].any() and not got[2].any()


def test_the_frustum_edge_is_the_field_of_view():
    """A point 1 degree inside one eye's horizontal half angle is in its view, 1 degree outside
    is not; a wider x than y (an image's aspect) widens only the horizontal edge."""
    d, cams, _ = _eyes()
    eye = int(cams[0])
    rot = d.cam_xmat[eye].reshape(3, 3)
    half_deg = 30.0
    half = np.full(1, np.tan(np.deg2rad(half_deg)))

    def at(deg):     # 0.4 m along the camera's -z, turned by deg about its y axis
        a = np.deg2rad(deg)
        return d.cam_xpos[eye] + rot @ np.array([0.4 * np.sin(a), 0.0, -0.4 * np.cos(a)])

    assert in_view(d, [eye], at(half_deg - 1), half)[0, 0]
    assert not in_view(d, [eye], at(half_deg + 1), half)[0, 0]
    wide_x = np.array([[np.tan(np.deg2rad(half_deg + 5)), half[0]]])
    assert in_view(d, [eye], at(half_deg + 1), wide_x)[0, 0]
