"""body/inertia.py gives what MuJoCo's compiler gives: each shape's moments, a body's mass,
centre of mass and inertia tensor from several turned and shifted geoms, the bounding sphere and
box of each geom."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from mimo_social.body import inertia as I

SHAPES = {"sphere": [0.03, 0, 0], "capsule": [0.03, 0.05, 0], "cylinder": [0.02, 0.07, 0],
          "box": [0.01, 0.02, 0.03], "ellipsoid": [0.015, 0.025, 0.035]}


def _compiled(geoms):
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body(name="b")
    body.add_freejoint()
    for kind, size, pos, quat, mass in geoms:
        body.add_geom(type=getattr(mujoco.mjtGeom, f"mjGEOM_{kind.upper()}"), size=size,
                      pos=pos, quat=quat, mass=mass)
    return spec.compile()


@pytest.mark.parametrize("kind", list(SHAPES))
def test_each_shape_as_compiled(kind):
    m = _compiled([(kind, SHAPES[kind], [0, 0, 0], [1, 0, 0, 0], 1.7)])
    t = m.geom_type
    np.testing.assert_allclose(I.geom_moments(t, m.geom_size, [1.7])[0], m.body_inertia[1],
                               rtol=1e-12)
    np.testing.assert_allclose(I.geom_rbound(t, m.geom_size), m.geom_rbound, rtol=1e-12)
    np.testing.assert_allclose(I.geom_aabb(t, m.geom_size), m.geom_aabb, rtol=1e-12)
    np.testing.assert_allclose(I.geom_volumes(t, m.geom_size) * 1000.0,
                               _volume_by_density(kind), rtol=1e-9)


def _volume_by_density(kind):
    spec = mujoco.MjSpec()
    spec.worldbody.add_body().add_geom(type=getattr(mujoco.mjtGeom, f"mjGEOM_{kind.upper()}"),
                                       size=SHAPES[kind], density=1000.0)
    return spec.compile().body_mass[1]


def test_a_body_of_turned_shifted_geoms_as_compiled():
    rng = np.random.default_rng(0)
    geoms = []
    for k, kind in enumerate(SHAPES):
        q = rng.normal(size=4)
        geoms.append((kind, SHAPES[kind], rng.uniform(-0.1, 0.1, 3), q / np.linalg.norm(q),
                      0.2 + k))
    m = _compiled(geoms)
    kind = m.geom_type
    moments = I.geom_moments(kind, m.geom_size, [g[4] for g in geoms])
    mass, com, iquat, inertia, tensor = I.body_inertials(
        np.zeros(len(geoms), int), 1, [g[4] for g in geoms], m.geom_pos, m.geom_quat, moments)
    assert mass[0] == pytest.approx(m.body_mass[1], rel=1e-12)
    np.testing.assert_allclose(com[0], m.body_ipos[1], atol=1e-14)
    R = I.quat_matrices(m.body_iquat[1:])[0]
    np.testing.assert_allclose(tensor[0], R @ np.diag(m.body_inertia[1]) @ R.T, atol=1e-15)
    np.testing.assert_allclose(np.sort(inertia[0]), np.sort(m.body_inertia[1]), rtol=1e-10)
    mine = I.quat_matrices(iquat)[0]
    np.testing.assert_allclose(mine @ np.diag(inertia[0]) @ mine.T, tensor[0], atol=1e-15)
