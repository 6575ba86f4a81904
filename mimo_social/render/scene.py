"""A drop-in for ``mujoco.Renderer`` on the process's shared GL context: ``env.render()``.

:func:`make_renderer` checks that an OpenGL backend is there (errors say what to install) and
gives a :class:`SceneRenderer` with the model's own visual quality.
"""

from __future__ import annotations

import os

import mujoco
import numpy as np

from .eye_renderer import coarse_planes, free_render_context, gl_current, inherited
from .gl import ensure_gl_backend

__all__ = ["SceneRenderer", "make_scene_renderer", "make_renderer"]


class SceneRenderer:
    """``update_scene(data, camera)`` / ``render()`` / ``close()`` like ``mujoco.Renderer``, on
    the process's shared GL context, with the model's own visual quality (anti-aliasing as the
    model says) but floor planes as one quad (under directional lights: ~2.5x faster at
    640x480, a handful of pixels differ at the far edge). Made lazily; does not pickle."""

    def __init__(self, model, height: int = 240, width: int = 320, max_geom: int = 10000):
        self._model = model
        self._height, self._width = int(height), int(width)
        self._max_geom = max_geom
        self._con = None
        self._con_pid = None   # the process the GL objects were made in
        self._scene = mujoco.MjvScene(model, max_geom)
        self._scene_option = mujoco.MjvOption()
        self._rect = mujoco.MjrRect(0, 0, self._width, self._height)

    @property
    def width(self):
        return self._width

    @property
    def height(self):
        return self._height

    @property
    def scene(self):
        return self._scene

    def _make(self):
        model = self._model
        vis = model.vis.global_
        saved = (vis.offwidth, vis.offheight)
        planes, grid = coarse_planes(model)
        try:
            vis.offwidth, vis.offheight = max(saved[0], self._width), max(saved[1], self._height)
            self._con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_150)
            self._con_pid = os.getpid()
        finally:
            vis.offwidth, vis.offheight = saved
            if grid is not None:
                model.geom_size[planes, 2] = grid

    def update_scene(self, data, camera=-1, scene_option=None):
        model = self._model
        if not isinstance(camera, mujoco.MjvCamera):
            cam_id = camera
            if isinstance(cam_id, str):
                cam_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, cam_id)
                if cam_id == -1:
                    raise ValueError(f'the camera "{camera}" does not exist')
            if not -1 <= cam_id < model.ncam:
                raise ValueError(f"camera id {cam_id} out of range [-1, {model.ncam})")
            camera = mujoco.MjvCamera()
            if cam_id == -1:
                camera.type = mujoco.mjtCamera.mjCAMERA_FREE
                mujoco.mjv_defaultFreeCamera(model, camera)
            else:
                camera.type = mujoco.mjtCamera.mjCAMERA_FIXED
                camera.fixedcamid = cam_id
        mujoco.mjv_updateScene(model, data, scene_option or self._scene_option, None, camera,
                               mujoco.mjtCatBit.mjCAT_ALL, self._scene)

    def render(self, *, out: np.ndarray | None = None) -> np.ndarray:
        buf = np.empty((self._height, self._width, 3), np.uint8)
        if inherited(self._con, self._con_pid):   # made before a fork: remade in this process
            self._con = None
        with gl_current():     # any thread; the context is released again at the end
            if self._con is None:
                self._make()
            mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._con)
            mujoco.mjr_render(self._rect, self._scene, self._con)
            mujoco.mjr_readPixels(buf, None, self._rect, self._con)
        img = np.flipud(buf)
        if out is not None:
            np.copyto(out, img)
            return out
        return np.ascontiguousarray(img)

    def close(self):
        free_render_context(getattr(self, "_con", None), getattr(self, "_con_pid", None))
        self._con = None

    def __del__(self):   # free the GL objects on the shared context (not current after a render)
        self.close()

    def __getstate__(self):
        raise TypeError("a SceneRenderer holds GL objects and does not pickle; make a new one")


def make_scene_renderer(model, height: int, width: int) -> SceneRenderer:
    """A :class:`SceneRenderer`; its GL context is made (and errors raised) on first render."""
    return SceneRenderer(model, height, width)


def make_renderer(model, height: int, width: int) -> SceneRenderer:
    """A renderer with ``mujoco.Renderer``'s ``update_scene(data, camera)`` / ``render()`` /
    ``close()`` on the process's shared GL context (the model's own visual quality); errors
    explain what to install."""
    ensure_gl_backend()
    with gl_current():  # fail here, with the install hint, if no context can be made
        pass
    return make_scene_renderer(model, height, width)
