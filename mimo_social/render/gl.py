"""Headless OpenGL set-up for MuJoCo's renderer.

MuJoCo's Python bindings pick their OpenGL backend from ``MUJOCO_GL`` when ``mujoco`` is first
imported. :func:`choose_gl_backend` (run when ``mimo_social`` is imported) sets it when the user
set none and there is no display: EGL (Mesa) first, then OSMesa. Both run Mesa's llvmpipe
software rasterizer here and measured the same speed for the eye images (within the noise of a
shared 2-core machine, see :mod:`mimo_social.render.eye_renderer`); EGL comes first because it
needs no window buffer and is what GPU machines use. Mesa's own knobs (``LP_NUM_THREADS``,
``GALLIUM_DRIVER``) are left to the user: llvmpipe's default (one rasterizer thread per core)
was as fast as any other thread count, and ``softpipe`` is ~50x slower.

Every renderer of the package shares ONE GL context per process (made on first use, in the
process that renders): the eyes (:mod:`mimo_social.render.eye_renderer`) and ``env.render()``
(:mod:`mimo_social.render.scene`). It is current only while a renderer draws, so any thread
may render. An OpenGL context does not survive ``fork`` (Mesa hangs in the child on the
display its parent used): a process forked after its parent used EGL makes its own context on a
new display of Mesa's surfaceless platform (:func:`fresh_display_after_fork`), so subprocess
vector envs work with the default ``fork`` start method too; where that is not possible (OSMesa,
a driver without the surfaceless platform) it raises a RuntimeError that says to use ``spawn``
or ``forkserver``. When
``mujoco`` was imported before ``mimo_social`` (so it chose GLFW, useless without a display),
:func:`gl_context_class` loads EGL's or OSMesa's context class when the first context is made.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import sys

INSTALL_HINT = ("install Mesa's headless OpenGL libraries, e.g. on Debian/Ubuntu: "
                "apt-get install -y libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6; "
                "then set MUJOCO_GL=egl (or osmesa)")


_HEADLESS = (("egl", ("EGL", "EGL_mesa|EGL_nvidia")), ("osmesa", ("OSMesa",)))


def headless_backends() -> list[str]:
    """The headless backends whose libraries are installed, best first (EGL, then OSMesa)."""
    # libEGL (glvnd) alone cannot make a context: it needs a vendor library too
    return [backend for backend, libs in _HEADLESS
            if all(any(ctypes.util.find_library(n) for n in lib.split("|")) for lib in libs)]


def _headless() -> bool:
    return sys.platform.startswith("linux") and not os.environ.get("DISPLAY")


def choose_gl_backend() -> str | None:
    """Set MUJOCO_GL for headless use if the user has not; return the backend in force."""
    if os.environ.get("MUJOCO_GL"):
        return os.environ["MUJOCO_GL"]
    if "mujoco" in sys.modules:  # too late for mujoco: gl_context_class() picks one later
        return None
    if not _headless():
        return None
    for backend in headless_backends():
        os.environ["MUJOCO_GL"] = backend
        os.environ.setdefault("PYOPENGL_PLATFORM", backend)
        return backend
    return None


def gl_backend() -> str:
    return os.environ.get("MUJOCO_GL", "") or "default (glfw)"


def ensure_gl_backend() -> None:
    """Raise a RuntimeError that says what to install when no OpenGL backend can render."""
    if not os.environ.get("MUJOCO_GL") and _headless() and not headless_backends():
        raise RuntimeError("no OpenGL backend for offscreen rendering was found (neither EGL nor "
                           f"OSMesa, and no display): {INSTALL_HINT}")


def gl_context_class():
    """The GL context class to render with: ``mujoco.GLContext``, or, when ``mujoco`` was
    imported before a headless backend was chosen (it then holds GLFW's, useless without a
    display), EGL's or OSMesa's context class imported now (and ``MUJOCO_GL`` set to it)."""
    import mujoco

    ensure_gl_backend()
    chosen = getattr(sys.modules.get("mujoco.rendering.classic.gl_context"), "_MUJOCO_GL", None)
    if chosen or not _headless():   # mujoco chose a backend itself, or there is a display
        return mujoco.GLContext
    errors = []
    for backend in headless_backends():
        if os.environ.get("PYOPENGL_PLATFORM", backend) != backend:
            errors.append(f"{backend}: PYOPENGL_PLATFORM={os.environ['PYOPENGL_PLATFORM']!r}")
            continue
        try:
            os.environ.setdefault("PYOPENGL_PLATFORM", backend)
            if backend == "egl":
                from mujoco.egl import GLContext
            else:
                from mujoco.osmesa import GLContext
        except Exception as e:  # noqa: BLE001 - try the next one, report all
            errors.append(f"{backend}: {e}")
            continue
        os.environ["MUJOCO_GL"] = backend
        return GLContext
    raise RuntimeError("mujoco was imported before mimo_social, so no headless OpenGL backend "
                       "was chosen, and none could be loaded now (" + "; ".join(errors) + "); "
                       "set MUJOCO_GL=egl (or osmesa) before starting Python, or import "
                       f"mimo_social first; if that fails too, {INSTALL_HINT}")


EGL_PLATFORM_SURFACELESS_MESA = 0x31DD


def fresh_display_after_fork() -> bool:
    """In a process forked after its parent used EGL: point MuJoCo's EGL module at a new,
    initialised display of Mesa's surfaceless platform, so that the next context is made there
    (the inherited display's rasterizer threads were not forked: a context on it hangs). The
    inherited display is left alone. Returns whether it did; False where the backend is not EGL,
    the driver has no surfaceless platform, or the inherited display already was that one."""
    egl_module = sys.modules.get("mujoco.egl")
    if egl_module is None or os.environ.get("MUJOCO_GL") != "egl":
        return False
    egl = egl_module.EGL
    try:
        extensions = egl.eglQueryString(egl.EGL_NO_DISPLAY, egl.EGL_EXTENSIONS) or b""
        if b"EGL_MESA_platform_surfaceless" not in extensions:
            return False
        display = egl.eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA,
                                               egl.EGL_DEFAULT_DISPLAY, None)
        if not display or _address(display) == _address(egl_module.EGL_DISPLAY):
            return False
        if egl.eglInitialize(display, None, None) != egl.EGL_TRUE:
            return False
    except Exception:  # noqa: BLE001 - no fresh display: the caller says what to do instead
        return False
    egl_module.EGL_DISPLAY = display
    return True


def _address(pointer) -> int | None:
    return None if pointer is None else ctypes.cast(pointer, ctypes.c_void_p).value
