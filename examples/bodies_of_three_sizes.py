"""Three bodies in one world: an 18-month-old (scale 1), a 3-4-year-old (1.3) and a
caregiver-sized body (2.2), standing on a circle; writes a picture of the scene.

    python examples/bodies_of_three_sizes.py [out.png]

The scaling laws (mass s^3, inertia s^5, torque s^4 x strength, ...) are in docs/bodies.md.
"""

import sys

import numpy as np

from mimo_social.envs import free_play_v0


def main(path: str = "bodies_of_three_sizes.png") -> None:
    env = free_play_v0.parallel_env(
        n_agents=3, render_mode="rgb_array", render_size=(480, 640), expressions=True,
        per_agent=[{"scale": 1.0}, {"scale": 1.3}, {"scale": 2.2, "strength": 1.0}])
    env.reset(seed=0)
    for a in range(3):
        print(f"infant_{a}: scale {env.agent_configs[a].scale}, "
              f"mass {env.world.model.body_subtreemass[env.world.agents[a].root_body]:.1f} kg")
    still = {a: np.zeros(env.action_space(a)["motors"].shape, np.float32) for a in env.agents}
    for _ in range(10):  # a tenth of a second, everyone smiling
        env.step({a: {"motors": still[a], "expression": 1} for a in env.agents})
    frame = env.render()
    from PIL import Image
    Image.fromarray(frame).save(path)
    print(f"wrote {path}")
    env.close()


if __name__ == "__main__":
    main(*sys.argv[1:])
