"""Rendering of the ParallelEnv: the scene as an RGB image from a camera that shows every agent.

:class:`SceneRendering` is a mixin of :class:`~mimo_social.core.env.MimoParallelEnv`: it
reads the env's ``world``, ``render_mode`` and ``render_size``; its renderer is made lazily,
closed by :meth:`SceneRendering.close_renderer` and never pickled.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ..render.scene import make_renderer
from ..scenery import inside_camera

__all__ = ["SceneRendering"]


class SceneRendering:
    """``render``, ``render_rgb`` and ``scene_camera`` of the env (a mixin)."""

    _renderer = None

    def render(self, mode: str | None = None):
        """The scene as an RGB array (``render_mode="rgb_array"``), else None.

        ``mode`` (older PettingZoo and RLlib's ``ParallelPettingZooEnv`` pass one): None or the
        env's own render_mode; ``"rgb_array"`` returns a frame whatever the env's mode.
        ``render_mode="human"`` has no window here (headless simulation, frames drawn off
        screen): it raises a RuntimeError that says to use ``"rgb_array"``.
        """
        if mode is None or mode == self.render_mode:
            mode = self.render_mode
        elif mode != "rgb_array":
            raise ValueError(f"render(mode={mode!r}) not allowed; allowed: None, 'rgb_array' "
                             f"or the env's render_mode {self.render_mode!r}")
        if mode == "human":
            raise RuntimeError("render_mode='human' opens no window in this package; make the "
                               "env with render_mode='rgb_array' and show its frames, or record "
                               "the episode (mimo_social.recording)")
        if mode != "rgb_array":
            return None
        return self.render_rgb()

    def render_rgb(self, camera: mujoco.MjvCamera | None = None) -> np.ndarray:
        """An RGB image of the scene from a camera that shows every agent (renderer made lazily)."""
        w = self.world
        if self._renderer is None:
            h, wd = self.render_size
            self._renderer = make_renderer(w.model, h, wd)
        if camera is None:
            camera = self.scene_camera()
        self._renderer.update_scene(w.data, camera)
        return self._renderer.render()

    def scene_camera(self) -> mujoco.MjvCamera:
        d = self.world.data
        roots = d.xpos[[a.root_body for a in self.world.agents]]
        cam = mujoco.MjvCamera()
        centre = roots.mean(axis=0)
        spread = (float(np.max(np.linalg.norm(roots[:, :2] - centre[:2], axis=1)))
                  if len(roots) > 1 else 0.0)
        # frame the tallest head too (a caregiver-sized body is twice an infant's height)
        top = float(np.max(d.site_xpos[[a.head_site for a in self.world.agents], 2]))
        cam.lookat[:] = (centre[0], centre[1], max(0.3, 0.45 * top))
        cam.distance = max(1.4 + 2.0 * spread, 2.2 * top)
        cam.azimuth = 60.0
        cam.elevation = -20.0
        if self.world.room is not None:   # inside the room, looking over the agents at its back
            cam.azimuth, cam.elevation = 70.0, -22.0
            cam.distance = inside_camera(self.world.room.centre, cam.lookat, cam.distance,
                                         cam.azimuth, cam.elevation)
        return cam

    def close_renderer(self) -> None:
        """Close the scene renderer, if one was made."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
