"""Every primitive shape of a body is logged solid: the replay draws trunks, arms and legs as
filled capsules, not as see-through wire cages (capsules were the one shape logged without a
fill mode, issue 20)."""

from __future__ import annotations

import mujoco
import rerun as rr

from mimo_social.envs import free_play_v0
from mimo_social.recording.geometry import geom_archetype

SOLID = rr.components.FillMode.Solid.value


def test_every_primitive_of_the_body_is_logged_solid():
    env = free_play_v0.parallel_env(n_agents=1, hands="five_fingers", task_options={"props": True})
    m = env.world.model
    shapes = {}
    for g in range(m.ngeom):
        t = int(m.geom_type[g])
        if t == mujoco.mjtGeom.mjGEOM_PLANE:
            continue
        arch = geom_archetype(m, g)
        assert arch is not None, m.geom(g).name
        assert arch.fill_mode is not None, (m.geom(g).name, type(arch).__name__)
        assert arch.fill_mode.as_arrow_array().to_pylist() == [SOLID], m.geom(g).name
        shapes[type(arch).__name__] = shapes.get(type(arch).__name__, 0) + 1
    env.close()
    # the body's capsules (trunk, arms, legs) are among them
    assert shapes.get("Capsules3D", 0) >= 10 and "Ellipsoids3D" in shapes and "Boxes3D" in shapes
