"""Red-cyan anaglyph of what an infant sees (like Fig. 5a of the MIMo paper).

Two infants stand face to face with a ball and a cube held up between them; infant_1 smiles.
The script saves infant_0's anaglyph (red: left eye, cyan: right eye; view it with red-cyan
glasses, red over the left eye) and its two eye images side by side.

    python examples/anaglyph.py [--size 256] [--distance 0.25] [--out anaglyph.png]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import mimo_social  # noqa: F401  (chooses the headless OpenGL backend before mujoco loads)
import mujoco
import numpy as np

from mimo_social.envs import free_play_v0
from mimo_social.render.png import write_png
from mimo_social.senses.vision import eye_images, render_now, save_anaglyph


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--size", type=int, default=256, help="eye image width and height (px)")
    p.add_argument("--distance", type=float, default=0.25,
                   help="distance of the ball in front of infant_0's eyes (m)")
    p.add_argument("--out", default="anaglyph.png", help="PNG of the anaglyph")
    p.add_argument("--pair", default=None,
                   help="PNG of the left and right eye images side by side "
                        "(default: <out>_eyes.png)")
    args = p.parse_args(argv)

    env = free_play_v0.parallel_env(n_agents=2, vision={"width": args.size, "height": args.size},
                                    task_options={"props": True})
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    env.world.set_expression(1, 1)  # infant_1 smiles at infant_0

    # hold the props up between the infants: the ball near infant_0, down to the left of its
    # gaze, the cube further away, down to the right (the nearer, the larger the disparity)
    right_cam, left_cam = env.world.agents[0].eye_cameras
    eyes = (d.cam_xpos[right_cam] + d.cam_xpos[left_cam]) / 2
    R = d.cam_xmat[left_cam].reshape(3, 3)           # columns: right, up, backwards
    for prop, dist, side in (("ball", args.distance, -0.035), ("cube", 0.4, 0.06)):
        adr = env.world.prop_qpos[prop]
        d.qpos[adr:adr + 3] = eyes - dist * R[:, 2] - 0.05 * R[:, 1] + side * R[:, 0]
        d.qpos[adr + 3:adr + 7] = (0.92, 0.2, 0.3, 0.1)
    mujoco.mj_forward(m, d)
    render_now(env)

    out = Path(args.out)
    scale = max(1, 256 // args.size)
    save_anaglyph(env, "infant_0", out, scale=scale)
    imgs = eye_images(env, "infant_0")
    gap = np.full((args.size, max(2, args.size // 32), 3), 255, np.uint8)
    pair = np.concatenate([imgs["eye_left"], gap, imgs["eye_right"]], axis=1)
    pair_path = Path(args.pair) if args.pair else out.with_name(out.stem + "_eyes.png")
    write_png(pair_path, pair.repeat(scale, axis=0).repeat(scale, axis=1))
    print(f"saved {out} (anaglyph) and {pair_path} (left | right eye)")
    env.close()


if __name__ == "__main__":
    main()
