"""The play room's pictures for docs/playroom.md: an overview from inside the room and an eye view.

Run (headless, OpenGL through EGL)::

    MUJOCO_GL=egl python examples/playroom_picture.py [docs/playroom.png]

It builds the high five in the play room (``scene="playroom"``) with an infant and the kneeling
adult caregiver, lets the scripted pair play until the high five (the task's rule: the palms
meet, palm side to palm side, and stay together ``hold_time``, 0.1 s; the episode ends on it;
with seed 0 after 124 steps, 1.24 s; at most the episode's 500 steps), says when (or that it
did not come) and writes one PNG: the env's own scene camera (inside the room, looking over
the pair) on the left, and on the right what the infant's left eye sees (120 x 120, enlarged)
and a second view across the room, from the shelf's side.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from mimo_social.envs import high_five_v0
from mimo_social.envs.catalog import entry
from mimo_social.render.png import write_png


def _enlarge(img: np.ndarray, k: int) -> np.ndarray:
    return np.repeat(np.repeat(img, k, axis=0), k, axis=1)


def main(out: str = "docs/playroom.png") -> None:
    env = high_five_v0.scripted_env(
        scene="playroom", render_mode="rgb_array", render_size=(720, 960),
        per_agent=[{"vision": {"width": 120, "height": 120}},
                   {"body": "adult", "posture": "kneeling"}])
    inner = env.unwrapped
    obs, _ = env.reset(seed=0)
    ctrl = entry("high_five").controller()
    ctrl.reset(inner, "infant_0", np.random.default_rng(0))
    steps, success = 0, False
    while True:     # until the high five ends the episode (or the episode's steps run out)
        obs, _, term, trunc, info = env.step({"infant_0": ctrl.act(inner, "infant_0",
                                                                   obs["infant_0"])})
        steps += 1
        if term["infant_0"] or trunc["infant_0"]:
            success = bool(info["infant_0"].get("is_success", False))
            break
    print(f"high five after {steps} steps ({steps * inner.dt:.2f} s)" if success else
          f"no high five in {steps} steps: the picture shows the pair where they stopped")
    overview = inner.render()                                   # 720 x 960
    eye = obs["infant_0"]["eye_left"]
    eye = eye if eye.ndim == 3 and eye.shape[-1] == 3 else np.moveaxis(eye, 0, -1)
    eye = _enlarge(np.asarray(eye, np.uint8), 360 // eye.shape[0])   # 360 x 360
    cam = inner.scene_camera()
    cam.azimuth, cam.elevation = cam.azimuth + 150.0, -28.0
    cx, cy = inner.world.room.centre
    cam.lookat[:] = (cx + 0.3, cy - 0.1, 0.35)
    cam.distance = 2.0
    across = inner.render_rgb(cam)
    across = across[::2, ::2][:, 60:420]                          # 360 x 360
    right = np.concatenate([eye, across], axis=0)
    gap = np.full((720, 8, 3), 255, np.uint8)
    picture = np.concatenate([overview, gap, right], axis=1)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    write_png(out, picture)
    env.close()
    print(f"wrote {out} ({picture.shape[1]} x {picture.shape[0]})")


if __name__ == "__main__":
    main(*sys.argv[1:])
