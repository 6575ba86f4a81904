"""Headless OpenGL set-up for MuJoCo's renderer.

MuJoCo's Python bindings pick their OpenGL backend from ``MUJOCO_GL`` when ``mujoco`` is first
imported. :func:`choose_gl_backend` (run when ``mimo_social`` is imported) sets it when the user
set none and there is no display: EGL (Mesa) first, then OSMesa. Renderers are always created
lazily, in the process that uses them: a GL context does not survive ``fork``, so subprocess
vector envs must use the ``spawn`` or ``forkserver`` start method.
"""

from __future__ import annotations

import ctypes.util
import os
import sys

INSTALL_HINT = ("install Mesa's headless OpenGL libraries, e.g. on Debian/Ubuntu: "
                "apt-get install -y libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6; "
                "then set MUJOCO_GL=egl (or osmesa)")


def choose_gl_backend() -> str | None:
    """Set MUJOCO_GL for headless use if the user has not; return the backend in force."""
    if os.environ.get("MUJOCO_GL"):
        return os.environ["MUJOCO_GL"]
    if "mujoco" in sys.modules:  # too late to choose: report what mujoco chose
        return None
    if os.environ.get("DISPLAY") or sys.platform == "darwin":
        return None
    for backend, lib in (("egl", "EGL"), ("osmesa", "OSMesa")):
        if ctypes.util.find_library(lib):
            os.environ["MUJOCO_GL"] = backend
            if backend == "osmesa":
                os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
            elif backend == "egl":
                os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
            return backend
    return None


def gl_backend() -> str:
    return os.environ.get("MUJOCO_GL", "") or "default (glfw)"


def ensure_gl_backend() -> None:
    """Raise a RuntimeError that says what to install when no OpenGL backend can render."""
    if not os.environ.get("MUJOCO_GL") and not os.environ.get("DISPLAY") \
            and sys.platform.startswith("linux"):
        raise RuntimeError("no OpenGL backend for offscreen rendering was found (neither EGL nor "
                           f"OSMesa, and no display): {INSTALL_HINT}")


def make_renderer(model, height: int, width: int):
    """A ``mujoco.Renderer``; errors explain what to install."""
    import mujoco

    ensure_gl_backend()
    try:
        return mujoco.Renderer(model, height, width)
    except Exception as e:  # noqa: BLE001 - re-raised with the fix attached
        raise RuntimeError(f"could not create an OpenGL context with MUJOCO_GL="
                           f"{gl_backend()!r} ({e}); {INSTALL_HINT}") from e
