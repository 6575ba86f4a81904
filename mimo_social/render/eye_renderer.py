"""Fast offscreen rendering of many small fixed-camera images: one GL context per process.

Software OpenGL (Mesa llvmpipe through EGL or OSMesa) spends almost all of its time on vertex
work on the calling thread, plus a fixed cost per ``mjr_render`` and per read-back (each
read-back waits for the rasterizer threads). So:

* one GL context per process, created lazily in the process that renders and never pickled;
  current only inside :func:`gl_current` (a process-wide lock; released after each render, ~10
  us), so any thread may render; a process forked after its parent used OpenGL makes its own
  context on a new EGL display (:func:`mimo_social.render.gl.fresh_display_after_fork`; the
  inherited one would hang) and renderers made in the parent remake their GL objects there;
  where no new display can be had (OSMesa) it refuses to render with a RuntimeError that says
  to use the ``spawn`` / ``forkserver`` start methods for worker processes;
* one :class:`TileRenderer` (one ``MjrContext``, one offscreen buffer) for all the cameras of
  a world: every image is a tile (a viewport) of that buffer, rendered one after the other and
  read back with ONE ``glReadPixels`` per step; an agent's two eyes sit side by side and are
  drawn by ONE ``mjr_render`` in MuJoCo's side-by-side stereo mode, the scene's two GL cameras
  set to the two eye cameras (the headlight then shines along the mean of the two eyes'
  directions, the same light for both eyes);
* geoms whose bounding sphere is outside the eyes' view frustum are left out of the scene
  (llvmpipe transforms every vertex it is given): about half the cost with the partner in view;
* the buffer is sized to the tiles, with no multisampling, and the context is made with coarse
  capsule/sphere tessellation (the biggest cost at these image sizes), no shadow map;
* no shadows, reflections, skybox, haze or fog, no site markers; back faces culled (the eye
  cameras sit inside their own head sphere, whose inside is thus invisible);
* floor planes drawn as one quad instead of MuJoCo's grid of ``size[2]``-sized quads (the
  lights are directional, so the subdivision changes nothing visible and cost ~40 % of a frame);
* colours read as RGBA (a plain copy in Mesa; RGB goes through a slow per-pixel conversion)
  and split into channels with numpy.

:mod:`mimo_social.render.scene` gives a drop-in for ``mujoco.Renderer`` on the same shared
context (used by ``env.render()``).

All MuJoCo visual settings changed to make a context (offscreen size, quality) are restored on
the model right after, so other renderers of the same model see the model's own settings.
"""

from __future__ import annotations

import atexit
import contextlib
import ctypes
import os
import sys
import threading
from dataclasses import dataclass
from typing import Sequence

import mujoco
import numpy as np

from .gl import INSTALL_HINT, fresh_display_after_fork, gl_backend, gl_context_class

__all__ = ["shared_gl_context", "gl_current", "free_shared_gl_context", "has_gl_context",
           "inherited", "TileRenderer", "Tile", "tessellation_for", "coarse_planes",
           "free_render_context", "MAX_BUFFER_SIDE"]

MAX_BUFFER_SIDE = 4096      # tiles are packed in batches no larger than this (pixels per side)
_GL = None                  # the process's GL context
_GL_PID = None              # the process that made it
_GL_MADE = False            # whether this process (or the one it was forked from) made one
_ATEXIT = False
_LOCK = threading.RLock()   # one thread at a time renders on the context
_FORKED_FROM = None         # (parent pid, what it had made) in a child forked after GL was used
_TLS = threading.local()    # .depth: gl_current blocks open on this thread
_PENDING = []               # MjrContexts to free when the current render ends
_LEFT_ON = None             # the thread shared_gl_context() left the context current on
_INHERITED = []             # GL objects a forked child got from its parent: kept, never freed


def has_gl_context() -> bool:
    """Whether this process has made the shared GL context (a forked child has not)."""
    return _GL is not None and _GL_PID == os.getpid()


def _gl_state_in_use() -> str | None:
    """What of OpenGL this process has set up (a context of ours, an EGL display), if any."""
    if _GL is not None or _GL_MADE:
        return f"an OpenGL context (MUJOCO_GL={gl_backend()!r})"
    egl = sys.modules.get("mujoco.egl")
    if egl is not None and getattr(egl, "EGL_DISPLAY", None) is not None:
        return "an EGL display"
    return None


def _after_fork_in_child() -> None:
    global _FORKED_FROM, _LOCK, _TLS, _PENDING, _LEFT_ON
    used = _gl_state_in_use()
    if used is not None and _FORKED_FROM is None:
        _FORKED_FROM = (os.getppid(), used)
    # a lock held by a parent's thread at the fork would never be released here
    _LOCK, _TLS, _PENDING, _LEFT_ON = threading.RLock(), threading.local(), [], None


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork_in_child)


def _own_display_after_fork() -> None:
    """In a process forked after its parent used OpenGL: a new display for this process's own
    context (the parent's context and display are kept, untouched: using or freeing them here
    hangs), else a RuntimeError naming the cause and the fix. Call under _LOCK."""
    global _GL, _GL_PID, _FORKED_FROM
    if _FORKED_FROM is None:
        return
    if fresh_display_after_fork():
        if _GL is not None:
            _INHERITED.append(_GL)
        _GL, _GL_PID, _FORKED_FROM = None, None, None
        return
    parent, used = _FORKED_FROM
    raise RuntimeError(
        f"cannot render in process {os.getpid()}: it was forked from process {parent}, which "
        f"had already made {used}; with MUJOCO_GL={gl_backend()!r} no new display could be "
        "made here (that needs EGL with Mesa's surfaceless platform), and the inherited one "
        "hangs. Start worker processes with the 'spawn' or 'forkserver' method "
        "(multiprocessing.set_start_method('spawn'), or the start method or context argument "
        "of the vector env), use MUJOCO_GL=egl, or fork before the parent renders anything")


def inherited(con, made_in: int | None) -> bool:
    """Whether ``con`` (GL objects made in process ``made_in``) came from a parent process
    through fork; it is then kept alive and never freed here (its ids mean nothing, or other
    objects, in this process's context). Renderers call this before drawing and remake their
    objects when it says True."""
    if con is None or made_in is None or made_in == os.getpid():
        return False
    _INHERITED.append(con)
    return True


def _context():
    """The process's GL context, made on first use (not left current); call under _LOCK."""
    global _GL, _GL_PID, _GL_MADE, _ATEXIT
    _own_display_after_fork()
    if _GL is not None and _GL_PID == os.getpid():
        return _GL
    if _GL is not None:   # made in a parent process: kept, never freed here
        _INHERITED.append(_GL)
    _GL = None
    cls = gl_context_class()
    try:
        ctx = cls(16, 16)   # its own buffer is unused: an MjrContext renders to its FBO
        with ctx.as_current():
            pass
    except Exception as e:  # noqa: BLE001 - re-raised with the fix attached
        raise RuntimeError(f"could not create an OpenGL context with MUJOCO_GL="
                           f"{gl_backend()!r} ({type(e).__name__}: {e}); {INSTALL_HINT}") from e
    _GL, _GL_PID, _GL_MADE = ctx, os.getpid(), True
    if not _ATEXIT:  # free before interpreter teardown (avoids noisy errors from PyOpenGL)
        atexit.register(free_shared_gl_context)
        _ATEXIT = True
    return _GL


@contextlib.contextmanager
def gl_current():
    """Hold the process's GL context, current on the calling thread, for the ``with`` block.

    The renderers draw only inside this block: one thread at a time (a process-wide lock), and
    at the end the context is released again (or the context that was current before is made
    current again), so any thread may render next: an env made and reset on one thread can be
    stepped on another. Costs ~10 us a block (EGL, llvmpipe). In a process forked from one
    that had used OpenGL the context is made on a new display; where none can be made (OSMesa)
    it raises a RuntimeError naming the cause and the fix (rendering there would hang)."""
    global _LEFT_ON
    with _LOCK:
        ctx = _context()
        me = threading.get_ident()
        with contextlib.ExitStack() as stack:
            try:
                stack.enter_context(ctx.as_current())
            except Exception as e:  # noqa: BLE001 - re-raised with the cause and the fix
                where = (f"thread {_thread_name(_LEFT_ON)!r}, where shared_gl_context() left it"
                         if _LEFT_ON not in (None, me) else "another thread")
                raise RuntimeError(
                    f"could not make the OpenGL context current on thread "
                    f"{threading.current_thread().name!r} ({type(e).__name__}): it is still "
                    f"current on {where}; render through gl_current(), which releases it "
                    "after each block") from e
            _TLS.depth = getattr(_TLS, "depth", 0) + 1
            try:
                yield ctx
            finally:
                _TLS.depth -= 1
                while _TLS.depth == 0 and _PENDING:   # freed while this thread was rendering
                    _free_now(_PENDING.pop())
                if _TLS.depth == 0 and _LEFT_ON == me:  # left current by shared_gl_context()
                    _release(ctx)
                    _LEFT_ON = None


def _thread_name(ident) -> str:
    return next((t.name for t in threading.enumerate() if t.ident == ident), str(ident))


def _release(ctx) -> None:
    """Make no context current on this thread (ctx's backend: EGL, OSMesa or GLFW)."""
    mod = sys.modules.get(type(ctx).__module__)
    if hasattr(mod, "EGL_DISPLAY"):
        egl = mod.EGL
        egl.eglMakeCurrent(mod.EGL_DISPLAY, egl.EGL_NO_SURFACE, egl.EGL_NO_SURFACE,
                           egl.EGL_NO_CONTEXT)
    elif hasattr(mod, "osmesa"):
        mod.osmesa.OSMesaMakeCurrent(None, None, mod.GL.GL_FLOAT, 0, 0)
        if hasattr(mod, "_current_context"):
            mod._current_context.ref = None
    elif hasattr(mod, "glfw"):
        mod.glfw.make_context_current(None)


def shared_gl_context():
    """The process's GL context, made current on the calling thread and LEFT current there
    (for code that calls OpenGL itself, on one thread) until the next render on this thread.
    The renderers use :func:`gl_current`, which releases it after each render so that other
    threads can render too."""
    global _LEFT_ON
    with _LOCK:
        ctx = _context()
        try:
            ctx.make_current()
        except Exception as e:  # noqa: BLE001 - re-raised with the cause
            raise RuntimeError(f"could not make the OpenGL context current on thread "
                               f"{threading.current_thread().name!r} ({type(e).__name__}); is "
                               "it current on another thread?") from e
        _LEFT_ON = threading.get_ident()
        return ctx


def free_shared_gl_context() -> None:
    global _GL, _GL_PID
    with _LOCK:
        if _GL is not None and _GL_PID == os.getpid():
            try:
                _GL.free()
            except Exception:  # noqa: BLE001 - best effort at exit
                pass
        _GL, _GL_PID = None, None


def _gl_functions():
    """Raw ctypes entry points (no PyOpenGL array handling per call): glReadPixels, glFlush."""
    from OpenGL.raw.GL.VERSION.GL_1_0 import glFlush, glReadPixels
    return glReadPixels, glFlush


_GL_RGBA, _GL_UNSIGNED_BYTE = 0x1908, 0x1401
_CULL_GROUP = 5             # geom group hidden from the eyes (culled geoms sit here briefly)
_GLCAM_FIELDS = ("pos", "forward", "up", "frustum_center", "frustum_width", "frustum_bottom",
                 "frustum_top", "frustum_near", "frustum_far")


def tessellation_for(max_side: int) -> tuple[int, int]:
    """(numslices, numstacks) for capsules and spheres, from the largest image side.

    MuJoCo's defaults (28, 16) cost 2-3x the coarse ones at 64 px. A partner's head 0.6 m away
    is ~14 px across at 64 px, ~28 px at 128 px and ~56 px at 256 px: the outline of an 8-gon
    (12-gon, 16-gon) departs from the circle by 1 - cos(pi / n) of the radius, 0.5 px (0.5 px,
    0.5 px) there. With many infants in view the vertex work is most of the cost: at 64 px
    the 8-gon draws 8 infants' eyes in ~0.6x the time of the 12-gon."""
    if max_side <= 64:
        return 8, 4
    if max_side <= 128:
        return 12, 6
    if max_side <= 320:
        return 16, 8
    if max_side <= 640:
        return 20, 10
    return 28, 16


def coarse_planes(model):
    """Set every finite plane's grid spacing (``size[2]``) to its whole size, so a new
    ``MjrContext`` bakes it as one quad instead of (2 size / size[2])^2 of them; returns the
    planes and their old spacing, to put back once the context is made. Under directional
    lights only, the subdivision changes nothing but a few pixels at the far edge."""
    planes = np.flatnonzero((model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)
                            & (model.geom_size[:, 0] > 0) & (model.geom_size[:, 1] > 0))
    grid = model.geom_size[planes, 2].copy()
    directional = bool(np.all(model.light_type == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL))
    if not directional:  # spot/point lights need the grid for their per-vertex lighting
        return planes, None
    model.geom_size[planes, 2] = 2 * model.geom_size[planes, :2].max(axis=1)
    return planes, grid


def free_render_context(con, made_in: int | None = None) -> None:
    """Free an MjrContext made on this process's shared GL context (in process ``made_in``,
    when given); one made in a parent process before a fork is kept, not freed."""
    if inherited(con, made_in):
        return
    if con is None or _GL is None or _GL_PID != os.getpid() or _FORKED_FROM is not None:
        return
    if getattr(_TLS, "depth", 0):   # called (e.g. by the garbage collector) amid a render
        _PENDING.append(con)
        return
    try:
        with gl_current():
            _free_now(con)
    except Exception:  # noqa: BLE001 - freeing at shutdown must not raise
        pass


def _free_now(con) -> None:
    try:
        con.free()
    except Exception:  # noqa: BLE001 - freeing must not raise
        pass


@dataclass
class Tile:
    """One camera image: its size and where it sits in its batch's buffer."""

    width: int
    height: int
    depth: bool = False
    batch: int = 0
    x: int = 0
    y: int = 0


def _pack(tiles: Sequence[Tile], groups: Sequence[Sequence[int]], limit: int) -> tuple[int, int]:
    """Place tiles in rows (one row per group, e.g. one agent's two eyes), rows stacked
    upwards; a new batch starts when the buffer would exceed ``limit``. Returns the buffer
    size (width, height) that fits every batch."""
    batch, y, buf_w, buf_h = 0, 0, 1, 1
    for group in groups:
        row_h = max(tiles[t].height for t in group)
        x = 0
        for t in group:
            if x + tiles[t].width > limit and x > 0:   # too wide: wrap onto a new row
                y += row_h
                x = 0
            if y + row_h > limit and y > 0:
                batch, y = batch + 1, 0
            tiles[t].batch, tiles[t].x, tiles[t].y = batch, x, y
            x += tiles[t].width
            buf_w = max(buf_w, x)
        y += row_h
        buf_h = max(buf_h, y)
    return buf_w, buf_h


class TileRenderer:
    """Renders fixed cameras into tiles of one offscreen buffer; one read-back per batch.

    ``tiles``: the images (width, height, depth) in a fixed order; ``groups``: lists of tile
    indices kept on one row (e.g. an agent's two eyes). Nothing touches OpenGL before the first
    :meth:`render`, and pickling drops the GL objects (they are made again when needed).
    """

    def __init__(self, tiles: Sequence[Tile], groups: Sequence[Sequence[int]] | None = None,
                 tessellation: tuple[int, int] | None = None, floor_quads: bool = True,
                 cull: bool = True, stereo: bool = True, limit: int = MAX_BUFFER_SIDE):
        self.tiles = [Tile(t.width, t.height, t.depth) for t in tiles]
        groups = groups if groups is not None else [[i] for i in range(len(tiles))]
        self.buffer_size = _pack(self.tiles, groups, limit)
        self.n_batches = 1 + max(t.batch for t in self.tiles)
        # two equal tiles side by side: drawn by ONE mjr_render in side-by-side stereo mode
        self.pairs = {}
        for g in groups:
            if len(g) == 2:
                a, b = (self.tiles[i] for i in g)
                if ((a.width, a.height, a.batch, a.y) == (b.width, b.height, b.batch, b.y)
                        and b.x == a.x + a.width):
                    self.pairs[g[0]] = g[1]
        self.stereo = stereo
        side = max(max(t.width, t.height) for t in self.tiles)
        self.tessellation = tuple(tessellation or tessellation_for(side))
        self.floor_quads = floor_quads
        self.cull = cull
        self._con = None
        self._con_pid = None   # the process the GL objects were made in
        self._scn = None

    # -- lazily made GL objects ----------------------------------------------------------------
    def _make(self, model):
        vis = model.vis
        saved = (vis.global_.offwidth, vis.global_.offheight, vis.quality.offsamples,
                 vis.quality.numslices, vis.quality.numstacks, vis.quality.numquads,
                 vis.quality.shadowsize)
        planes, grid = coarse_planes(model) if self.floor_quads else (slice(0, 0), None)
        try:
            vis.global_.offwidth, vis.global_.offheight = self.buffer_size
            vis.quality.offsamples = 0
            vis.quality.numslices, vis.quality.numstacks = self.tessellation
            vis.quality.numquads = 1           # box faces: one quad (directional lights)
            vis.quality.shadowsize = 0         # no shadow map
            con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_50)
        finally:
            (vis.global_.offwidth, vis.global_.offheight, vis.quality.offsamples,
             vis.quality.numslices, vis.quality.numstacks, vis.quality.numquads,
             vis.quality.shadowsize) = saved
            if grid is not None:
                model.geom_size[planes, 2] = grid
        con.readDepthMap = mujoco.mjtDepthMap.mjDEPTH_ZEROFAR
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, con)
        scn = mujoco.MjvScene(model, maxgeom=model.ngeom + 200)
        scn.flags[:] = 0
        scn.flags[mujoco.mjtRndFlag.mjRND_CULL_FACE] = 1
        opt = mujoco.MjvOption()
        opt.flags[:] = 0                       # no joints, contacts, lights, ... drawn
        opt.flags[mujoco.mjtVisFlag.mjVIS_TEXTURE] = 1
        opt.flags[mujoco.mjtVisFlag.mjVIS_STATIC] = 1
        opt.flags[mujoco.mjtVisFlag.mjVIS_SKIN] = 1
        opt.flags[mujoco.mjtVisFlag.mjVIS_FLEXSKIN] = 1
        opt.sitegroup[:] = 0                   # sites are markers, not things to see
        self._con, self._scn, self._opt = con, scn, opt
        self._con_pid = os.getpid()
        self._cam = mujoco.MjvCamera()
        self._cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
        opt.geomgroup[_CULL_GROUP] = 0
        groups = np.clip(model.geom_group, 0, len(opt.geomgroup) - 1)
        shown = np.asarray(opt.geomgroup, bool)[groups]
        self._cull_geoms = np.flatnonzero((model.geom_type != mujoco.mjtGeom.mjGEOM_PLANE)
                                          & (model.geom_rbound > 0) & shown)
        self._znear = float(model.vis.map.znear * model.stat.extent)
        w, h = self.buffer_size
        self._rgba = np.empty((h, w, 4), np.uint8)
        self._read, self._flush = _gl_functions()
        extent = model.stat.extent
        near = np.float32(model.vis.map.znear * extent)
        far = np.float32(model.vis.map.zfar * extent)
        # reversed-z depth d in [0, 1] (1 at near) -> metres along the view axis: a / (d + b)
        self._depth_a = np.float32(far * near / (far - near))
        self._depth_b = np.float32(near / (far - near))

    @property
    def render_context(self):
        """The ``mujoco.MjrContext`` the tiles are drawn with (None before the first render or
        after :meth:`close`); for read-back measurements."""
        return self._con

    @property
    def read_pixels(self):
        """The raw ``glReadPixels`` function the tiles are read back with
        (``(x, y, width, height, format, type, pointer)``); for read-back measurements."""
        return self._read

    def close(self):
        free_render_context(getattr(self, "_con", None), getattr(self, "_con_pid", None))
        self._con = self._scn = None

    def __del__(self):   # the GL objects live in a context current only while rendering:
        self.close()     # MjrContext's own destructor, run with none current, would leak them

    def __getstate__(self):
        state = self.__dict__.copy()
        for key in ("_con", "_scn", "_opt", "_cam", "_rgba", "_read", "_flush",
                    "_cull_geoms"):
            state.pop(key, None)
        state["_con"] = state["_scn"] = None
        return state

    # -- rendering -----------------------------------------------------------------------------
    def render(self, model, data, jobs: Sequence[tuple[int, int]]) -> dict:
        """Render ``jobs`` = [(tile index, camera id), ...] now; return {tile index: (rgb,
        depth or None)} as new arrays (rgb uint8 (h, w, 3); depth float32 (h, w) in metres
        along the camera's view axis)."""
        if inherited(self._con, self._con_pid):   # made before a fork: remade in this process
            self._con = None
        with gl_current():     # any thread; the context is released again at the end
            if self._con is None:
                self._make(model)
            mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._con)
            out = {}
            by_batch: dict[int, list] = {}
            for t, cam in jobs:
                by_batch.setdefault(self.tiles[t].batch, []).append((t, cam))
            for batch_jobs in by_batch.values():
                self._render_batch(model, data, batch_jobs, out)
        return out

    def _update_scene(self, model, data, cam_ids: Sequence[int], aspect: float) -> None:
        """``mjv_updateScene`` for ``cam_ids`` (one camera, or a stereo pair: the scene's two
        GL cameras get the two eyes exactly, no inter-pupillary offset added). With culling,
        geoms whose bounding sphere lies outside every one of the cameras' views (llvmpipe
        transforms every vertex it is given, seen or not) are moved to a hidden geom group
        for the call and put back at once."""
        scn, cam = self._scn, self._cam
        hide = None
        if self.cull:
            g = self._cull_geoms
            r = model.geom_rbound[g]
            out = None
            for c in cam_ids:
                R = data.cam_xmat[c].reshape(3, 3)
                rel = (data.geom_xpos[g] - data.cam_xpos[c]) @ R   # camera frame (x, y, z)
                ahead = -rel[:, 2]                                   # cameras look along -z
                ty = np.tan(np.deg2rad(model.cam_fovy[c]) / 2)
                tx = ty * aspect
                o = ((ahead + r < self._znear)
                     | (np.abs(rel[:, 0]) - tx * ahead > r * np.sqrt(1 + tx * tx))
                     | (np.abs(rel[:, 1]) - ty * ahead > r * np.sqrt(1 + ty * ty)))
                out = o if out is None else out & o
            hide = g[out]
            groups = model.geom_group[hide].copy()
            model.geom_group[hide] = _CULL_GROUP
        try:
            if len(cam_ids) == 1:
                cam.fixedcamid = int(cam_ids[0])
                mujoco.mjv_updateCamera(model, data, cam, scn)  # lights follow this camera
                mujoco.mjv_updateScene(model, data, self._opt, None, cam,
                                       mujoco.mjtCatBit.mjCAT_ALL, scn)
            else:
                # MuJoCo puts the scene's two GL cameras ipd/2 to either side of a camera and
                # draws mono views from their average: take each eye's average
                cam.fixedcamid = int(cam_ids[1])
                mujoco.mjv_updateCamera(model, data, cam, scn)
                second = [np.array(getattr(scn.camera[0], f)) for f in _GLCAM_FIELDS]
                second[0] = (scn.camera[0].pos + scn.camera[1].pos) / 2
                cam.fixedcamid = int(cam_ids[0])
                mujoco.mjv_updateCamera(model, data, cam, scn)
                first = (scn.camera[0].pos + scn.camera[1].pos) / 2
                scn.camera[0].pos[:] = first
                self._set_glcam(second)                          # lights follow both eyes
                mujoco.mjv_updateScene(model, data, self._opt, None, cam,
                                       mujoco.mjtCatBit.mjCAT_ALL, scn)
                scn.camera[0].pos[:] = first
                self._set_glcam(second)
        finally:
            if hide is not None:
                model.geom_group[hide] = groups

    def _set_glcam(self, values) -> None:
        c = self._scn.camera[1]
        for f, v in zip(_GLCAM_FIELDS, values):
            if v.ndim:
                getattr(c, f)[:] = v
            else:
                setattr(c, f, float(v))

    def _render_batch(self, model, data, jobs, out):
        scn, con = self._scn, self._con
        x0 = y0 = 1 << 30
        x1 = y1 = 0
        any_depth = False
        cam_of = dict(jobs)
        drawn = set()
        for t, cam_id in jobs:
            if t in drawn:
                continue
            tile = self.tiles[t]
            other = self.pairs.get(t) if self.stereo else None
            if other is not None and other in cam_of:
                self._update_scene(model, data, (cam_id, cam_of[other]), tile.width / tile.height)
                scn.stereo = mujoco.mjtStereo.mjSTEREO_SIDEBYSIDE
                try:
                    mujoco.mjr_render(mujoco.MjrRect(tile.x, tile.y, 2 * tile.width, tile.height),
                                      scn, con)
                finally:
                    scn.stereo = mujoco.mjtStereo.mjSTEREO_NONE
                drawn.update((t, other))
                right = self.tiles[other]
                any_depth |= right.depth
                x1, y1 = max(x1, right.x + right.width), max(y1, right.y + right.height)
            else:
                self._update_scene(model, data, (cam_id,), tile.width / tile.height)
                mujoco.mjr_render(mujoco.MjrRect(tile.x, tile.y, tile.width, tile.height), scn, con)
                drawn.add(t)
            self._flush()  # llvmpipe rasterizes these tiles while the next ones are transformed
            x0, y0 = min(x0, tile.x), min(y0, tile.y)
            x1, y1 = max(x1, tile.x + tile.width), max(y1, tile.y + tile.height)
            any_depth |= tile.depth
        w, h = x1 - x0, y1 - y0
        rgba = self._rgba[:h, :w] if w == self._rgba.shape[1] else np.empty((h, w, 4), np.uint8)
        self._read(x0, y0, w, h, _GL_RGBA, _GL_UNSIGNED_BYTE, rgba.ctypes.data_as(ctypes.c_void_p))
        depth = None
        if any_depth:
            depth = np.empty((h, w), np.float32)
            mujoco.mjr_readPixels(None, depth, mujoco.MjrRect(x0, y0, w, h), con)
        for t, _ in jobs:
            tile = self.tiles[t]
            # GL rows run bottom-up: flip while copying; channel by channel is the fast copy
            top = tile.y - y0
            rows = slice(top + tile.height - 1, None if top == 0 else top - 1, -1)
            cols = slice(tile.x - x0, tile.x - x0 + tile.width)
            src = rgba[rows, cols]
            rgb = np.empty((tile.height, tile.width, 3), np.uint8)
            rgb[..., 0] = src[..., 0]
            rgb[..., 1] = src[..., 1]
            rgb[..., 2] = src[..., 2]
            d = None
            if tile.depth:
                d = self._depth_a / (depth[rows, cols] + self._depth_b)
            out[t] = (rgb, d)
