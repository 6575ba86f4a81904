"""The eyes on the device: every agent's eye images for every world, rendered by MuJoCo Warp's
batch renderer (ray tracing on the device: ``create_render_context`` / ``render``), in the CPU
vision sense's layout (:mod:`mimo_social.senses.vision`): ``eye_left`` and ``eye_right`` per
agent with vision, ``(nworld, height, width, 3)`` uint8, row 0 at the top, and with ``depth``
on ``depth_left`` and ``depth_right``, ``(nworld, height, width)`` float32 metres along the
viewing axis (nothing hit: the CPU's far plane); delayed as the CPU env delays the ``vision``
channel. Every setting of the CPU sense is honoured: the ``acuity`` blur and the ``fovea``
(the eye rendered ``render_scale`` times larger, blurred, warped: the CPU's own filters run on
the device, :mod:`mimo_social.gpu.optics`), ``depth``, ``field_of_view`` and ``every`` (each
world counts its steps since its reset, as the CPU env does; the renderer runs on steps where
some world is due and the others keep their images).

After each control step's physics the cameras' poses are brought up to the state
(``camlight``), the renderer's bounding volumes refitted to the geoms' poses (``refit_bvh``) and
every eye of every world rendered in one launch; at a reset, the reset worlds' images are
rendered from their new state. The images are the CPU's view of the scene with the renderer's
shading, not its pixels: docs/gpu.md measures the difference. The faces: the renderer maps a
sphere's texture as a flat longitude-latitude image, while the heads carry cube textures (the
face on the +x side, :mod:`mimo_social.expressions.switch`), so the renderer is given a copy of
the model whose cube textures are resampled to longitude-latitude images
(:func:`ray_traced_textures`); each world's expressions are drawn by
:class:`~mimo_social.gpu.faces.BatchedFaces` (the head materials' texture per world).
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from ..senses.vision import render_scale
from .delay_ring import DelayRing
from .optics import EyeOptics

__all__ = ["BatchedEyes", "BatchedEyeSense", "EYES", "ray_traced_textures"]

#: the eyes, in the CPU sense's order of keys
EYES = ("left", "right")


#: the front side's coordinates are the line of sight's ``(u, v)`` times this: fitted to the
#: CPU's images, not derived from MuJoCo's mapping (zoomed on a partner's face, the change each
#: expression makes to the image correlates 0.66-0.84 between the device and the CPU with it,
#: -0.15 to 0.25 with 1: tests/gpu/test_gpu_faces.py)
FRONT_SCALE = float(np.sqrt(1.5))


def _longitude_latitude(cube: np.ndarray, width: int, height: int) -> np.ndarray:
    """A cube texture (six ``n`` x ``n`` sides stacked, MuJoCo's order +x, -x, +y, -y, +z, -z)
    as the ``height`` x ``width`` longitude-latitude image the renderer maps onto a sphere
    (column: the azimuth from +x towards +y, row 0: straight up). The +x side is sampled where
    the line of sight meets it, the direction ``(1, u, v)`` at the side's ``(u, v)`` times
    :data:`FRONT_SCALE`, its stored image turned as MuJoCo shows it (checked against the CPU's
    images with an asymmetric mark); the other sides, plain skin on the faces, in their mean
    colour."""
    n = cube.shape[1]
    sides = cube.reshape(6, n, n, -1)
    front = np.rot90(sides[0], 3)
    az = 2.0 * np.pi * (np.arange(width) + 0.5) / width
    el = np.pi * (0.5 - (np.arange(height) + 0.5) / height)
    d = np.stack(np.broadcast_arrays(np.cos(el)[:, None] * np.cos(az)[None],
                                     np.cos(el)[:, None] * np.sin(az)[None],
                                     np.sin(el)[:, None] * np.ones_like(az)[None]), axis=-1)
    big = np.argmax(np.abs(d), axis=-1) * 2 + (np.take_along_axis(
        d, np.argmax(np.abs(d), axis=-1)[..., None], -1)[..., 0] < 0)    # the side: 0..5
    out = sides.reshape(6, n * n, -1).mean(axis=1).round().astype(cube.dtype)[big]
    on = big == 0
    u, v = FRONT_SCALE * d[on, 1] / d[on, 0], FRONT_SCALE * d[on, 2] / d[on, 0]
    col = np.clip(((u + 1.0) / 2.0 * n).astype(int), 0, n - 1)
    row = np.clip(((1.0 - v) / 2.0 * n).astype(int), 0, n - 1)
    out[on] = front[row, col]
    return out


def ray_traced_textures(mjm):
    """A copy of the compiled model ``mjm`` for the batch renderer: every cube texture as a
    longitude-latitude image of the same bytes (width 3n, height 2n; the renderer samples a
    sphere's texture so); the other textures unchanged."""
    out = copy.deepcopy(mjm)
    for t in np.flatnonzero(mjm.tex_type == mujoco.mjtTexture.mjTEXTURE_CUBE):
        n, nc, adr = int(mjm.tex_width[t]), int(mjm.tex_nchannel[t]), int(mjm.tex_adr[t])
        if adr < 0 or int(mjm.tex_height[t]) != 6 * n:
            continue                 # a texture by reference, or not six sides stacked
        cube = mjm.tex_data[adr:adr + 6 * n * n * nc].reshape(6 * n, n, nc)
        image = _longitude_latitude(cube, 3 * n, 2 * n)
        out.tex_type[t] = mujoco.mjtTexture.mjTEXTURE_2D
        out.tex_width[t], out.tex_height[t] = 3 * n, 2 * n
        out.tex_data[adr:adr + image.size] = image.ravel()
    return out


class BatchedEyes:
    """The eyes of the agents that have vision in the CPU env whose vision system is
    ``system`` (its compiled model ``mjm``), for the ``nworld`` worlds of the Warp ``model``
    and ``data``; ``on_device``: the context that runs Warp's work on the device
    (:class:`~mimo_social.gpu.batched.BatchedEnv`'s); the images live on torch's ``device``.
    :attr:`images`: ``(agent, key)`` -> the current images of every world, the keys those of
    the CPU sense (``eye_left``, ``eye_right``; with depth on ``depth_left``, ``depth_right``)."""

    def __init__(self, system, mjm, model, data, nworld: int, wp, mjw, torch, device,
                 on_device):
        self._torch, self._mjw = torch, mjw
        self._model, self._data, self._on_device = model, data, on_device
        self.agents = list(system.agents)
        cams, res, depth = [], [], []
        #: per agent: the blur and the fovea's warp (:class:`~mimo_social.gpu.optics.EyeOptics`)
        self.optics = {}
        #: per agent: its eyes are rendered every ``every``-th step (the CPU's setting)
        self.every = {}
        for i in self.agents:
            cfg = system.configs[i]
            k = render_scale(cfg)
            for e in EYES:
                cams.append(int(system.cameras[i][e]))
                res.append((int(cfg.width) * k, int(cfg.height) * k))
                depth.append(bool(cfg.depth))
            self.optics[i] = EyeOptics(system.blurs[i], system.foveas[i], torch, device)
            self.every[i] = int(cfg.every)
        with on_device():
            self.rc = mjw.create_render_context(ray_traced_textures(mjm), nworld, cam_res=res,
                                                render_rgb=True, render_depth=depth,
                                                render_seg=False, cam_active=cams)
        # nothing hit: the CPU's depth is its far plane's distance, the renderer's 0
        self._far = float(mjm.vis.map.zfar * mjm.stat.extent)
        self._packed = wp.to_torch(self.rc.rgb_data)                    # (nworld, pixels) uint32
        self._depths = wp.to_torch(self.rc.depth_data) if any(depth) else None
        rgb_adr, depth_adr = self.rc.rgb_adr.numpy(), self.rc.depth_adr.numpy()
        #: per agent and key: (first pixel in the packed rows, render height, render width)
        self.slots = {}
        k = 0
        for i in self.agents:
            for e in EYES:
                w, h = res[k]
                self.slots[i, f"eye_{e}"] = (int(rgb_adr[k]), h, w)
                if depth[k]:
                    self.slots[i, f"depth_{e}"] = (int(depth_adr[k]), h, w)
                k += 1
        self.images = {}
        for (i, key), (_, h, w) in sorted(self.slots.items(), key=lambda kv: _order(kv[0])):
            cfg = system.configs[i]
            shape = (nworld, cfg.height, cfg.width) + ((3,) if key.startswith("eye") else ())
            dtype = torch.uint8 if key.startswith("eye") else torch.float32
            self.images[i, key] = torch.zeros(shape, dtype=dtype, device=device)
        #: per world, the steps since its reset: the reset's render is its 0th, the k-th control
        #: step after it the k-th (an agent's eyes render where this is a multiple of ``every``)
        self.count = torch.zeros(nworld, dtype=torch.int64, device=device)
        self._all = torch.ones(nworld, dtype=torch.bool, device=device)
        self.renders = 0

    def keys(self, agent: int) -> list[str]:
        """Agent ``agent``'s image keys, in the CPU sense's order."""
        return [key for (i, key) in self.images if i == agent]

    def render(self, worlds=None) -> None:
        """After a reset or load of ``worlds`` (a bool mask; None: all): render every eye from
        the current state and keep the images of those worlds (their step 0; the next control
        step is their step 1)."""
        mask = self._all if worlds is None else worlds
        self.count[mask] = 1
        self._draw({i: (None if worlds is None else mask) for i in self.agents})

    def step(self) -> None:
        """After a control step: render the eyes due in some world (an agent's are due every
        ``every``-th step since the world's reset) and keep their images in the worlds where
        they are due; the others hold their last images."""
        due = {}
        for i in self.agents:
            every = self.every[i]
            due[i] = None if every == 1 else (self.count % every) == 0
        self.count += 1
        if all(d is not None and not bool(d.any()) for d in due.values()):
            return
        self._draw(due)

    def _draw(self, keep: dict) -> None:
        m, d, mjw, torch = self._model, self._data, self._mjw, self._torch
        with self._on_device():
            mjw.camlight(m, d)
            mjw.refit_bvh(m, d, self.rc)
            mjw.render(m, d, self.rc)
        packed = self._packed.view(torch.int32)
        for (i, key), (start, h, w) in self.slots.items():
            if keep[i] is not None and not bool(keep[i].any()):
                continue
            if key.startswith("eye"):
                px = packed[:, start:start + h * w]
                # the renderer packs a pixel as 0xAARRGGBB
                rgb = torch.stack([(px >> 16) & 255, (px >> 8) & 255, px & 255], dim=-1)
                img = self.optics[i].rgb(rgb.to(torch.uint8).reshape(-1, h, w, 3))
            else:
                raw = self._depths[:, start:start + h * w].reshape(-1, h, w)
                img = self.optics[i].depth(torch.where(raw > 0, raw, self._far))
            if keep[i] is None:
                self.images[i, key] = img
            else:
                self.images[i, key][keep[i]] = img[keep[i]]
        self.renders += 1


def _order(key):
    """The CPU sense's order of an agent's keys: its eyes, then its depth images."""
    i, name = key
    return (i, name.startswith("depth"), EYES.index(name.split("_")[1]))


class BatchedEyeSense:
    """Agent ``agent``'s image ``key`` (``eye_left``, ..., ``depth_right``) read from ``eyes``,
    delayed by ``delay`` control steps (the CPU env's ``vision`` channel)."""

    def __init__(self, eyes: BatchedEyes, agent: int, key: str, delay: int, nworld: int,
                 torch, device):
        self.name = key
        self._eyes, self._key = eyes, (agent, key)
        image = eyes.images[agent, key]
        self._shape = tuple(image.shape[1:])
        self._ring = DelayRing(delay, nworld, int(np.prod(self._shape)), torch, device,
                               dtype=image.dtype)

    def _flat(self):
        return self._eyes.images[self._key].reshape(self._eyes.images[self._key].shape[0], -1)

    def reset(self, data, worlds=None):
        """The images at reset (the reset worlds' rendered by :meth:`BatchedEyes.render`)."""
        return self._ring.reset(self._flat(), worlds).reshape((-1,) + self._shape)

    def observe(self, data):
        """This step's images (of ``delay`` steps before, when delayed)."""
        reading = self._flat()     # a delay ring copies it; undelayed, the copy handed out
        return self._ring.push(reading if self._ring.delay else reading.clone()).reshape(
            (-1,) + self._shape)
