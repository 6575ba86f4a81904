"""Bodies at 0, 6, 12, 18 and 24 months and the adult caregiver, side by side, standing in a
held pose (every joint frozen at the standing posture); writes one picture and prints each
body's standing height and mass.

    python examples/bodies_by_age.py [docs/bodies_by_age.png]

The growth law, the adult's anthropometry and their sources are in docs/bodies.md.
"""

import sys

import mujoco
import numpy as np

from mimo_social.body.joint_groups import held_posture
from mimo_social.body.postures import posture_joints
from mimo_social.body.tables import load_body
from mimo_social.core.env import MimoParallelEnv
from mimo_social.core.world import AgentSetup
from mimo_social.figures import free_camera_pixel
from mimo_social.tasks.free_play import FreePlay

#: (label, agent settings) from left to right
BODIES = (("0 months", {"age_months": 0.0}), ("6 months", {"age_months": 6.0}),
          ("12 months", {"age_months": 12.0}), ("18 months", {}),
          ("24 months", {"age_months": 24.0}), ("adult", {"body": "adult"}))
#: y position of each body (m), so neighbours do not overlap (the adult needs more room)
SPOTS = (-0.95, -0.62, -0.27, 0.09, 0.47, 1.05)


class Lineup(FreePlay):
    """Everyone stands in a row along y, facing +x, every joint held."""

    def setup(self, i, config):
        tables = load_body(config.hands, age_months=config.age_months, body=config.body)
        frozen = held_posture(tables, keep=(), angles=posture_joints("standing", config.body))
        return AgentSetup(config, position=(0.0, SPOTS[i]), facing=(5.0, SPOTS[i]),
                          frozen=frozen, base="fixed")


def standing_height(env, i: int) -> float:
    """Top of the head to the soles (m): the highest minus the lowest point of the agent's geoms."""
    m, d = env.world.model, env.world.data
    g = env.world.agents[i].geom_ids
    g = g[m.geom_contype[g] != 0]   # the body's solid parts, not the eyes' irises and pupils
    r = m.geom_rbound[g]
    top = d.geom_xpos[g, 2] + np.where(m.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE, r, 0)
    head = m.geom(f"{env.world.names[i]}/head").id
    top = max(float(top.max()), float(d.geom_xpos[head, 2] + m.geom_size[head, 0]))
    from mimo_social.core.world import _support_below
    return top - float(_support_below(m, d, g).min())


def main(path: str = "docs/bodies_by_age.png") -> None:
    env = MimoParallelEnv(Lineup(len(BODIES)), per_agent=[s for _, s in BODIES],
                          render_mode="rgb_array", render_size=(600, 1200), vestibular=False)
    env.reset(seed=0)
    for i, (label, _) in enumerate(BODIES):
        mass = env.world.model.body_subtreemass[env.world.agents[i].root_body]
        print(f"{label:>10}: standing height {100 * standing_height(env, i):.1f} cm, "
              f"mass {mass:.2f} kg")
    for i in range(len(BODIES)):
        env.world.set_expression(i, 1)      # everyone smiles
    mujoco.mj_forward(env.world.model, env.world.data)
    cam = mujoco.MjvCamera()
    cam.lookat[:] = (0.0, 0.05, 0.72)
    cam.distance = 3.1
    cam.azimuth = 180.0     # looking along -x at the row, which faces +x
    cam.elevation = -5.0
    frame = env.render_rgb(cam)
    from PIL import Image, ImageDraw
    image = Image.fromarray(frame)
    draw = ImageDraw.Draw(image)
    fovy = float(env.world.model.vis.global_.fovy)
    for (label, _), y in zip(BODIES, SPOTS):
        u, v = free_camera_pixel(cam, (0.0, y, -0.04), frame.shape[0], frame.shape[1], fovy)
        draw.text((u - 3 * len(label), v), label, fill=(20, 20, 20))
    image.save(path)
    print(f"wrote {path}")
    env.close()


if __name__ == "__main__":
    main(*sys.argv[1:])
