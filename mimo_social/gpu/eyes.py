"""The eyes on the device: every agent's eye images for every world, rendered by MuJoCo Warp's
batch renderer (ray tracing on the device: ``create_render_context`` / ``render``), in the CPU
vision sense's layout (:mod:`mimo_social.senses.vision`): ``eye_left`` and ``eye_right`` per
agent with vision, ``(nworld, height, width, 3)`` uint8, row 0 at the top, delayed as the CPU
env delays the ``vision`` channel.

After each control step's physics the cameras' poses are brought up to the state
(``camlight``), the renderer's bounding volumes refitted to the geoms' poses (``refit_bvh``) and
every eye of every world rendered in one launch; at a reset, the reset worlds' images are
rendered from their new state. The images are the CPU's view of the scene with the renderer's
shading, not its pixels: docs/gpu.md measures the difference. What the device does not render
is refused with a ValueError naming the agent and the setting: ``acuity`` blur, ``fovea``,
``depth`` images, and ``every`` other than 1.
"""

from __future__ import annotations


from .delay_ring import DelayRing

__all__ = ["BatchedEyes", "BatchedEyeSense", "EYES"]

#: the eyes, in the CPU sense's order of keys
EYES = ("left", "right")


def _check(name: str, cfg, cutoff) -> None:
    """A ValueError for a vision setting the device does not render."""
    for field, value, allowed in (
            ("acuity", cfg.acuity if cutoff is not None else None, "None (no blur)"),
            ("fovea", cfg.fovea, "None"), ("depth", cfg.depth, "False"),
            ("every", cfg.every, "1 (every step rendered)")):
        if value is not None and value is not False and not (field == "every" and value == 1):
            raise ValueError(f"{name}: vision {field}={value!r} is not rendered on the device; "
                             f"allowed there: {allowed} (or eyes=False: no eyes on the device)")


class BatchedEyes:
    """The eyes of the agents ``names`` (index -> name) that have vision in the CPU env whose
    vision system is ``system`` (its compiled model ``mjm``), for the ``nworld`` worlds of the
    Warp ``model`` and ``data``; ``on_device``: the context that runs Warp's work on the
    device (:class:`~mimo_social.gpu.batched.BatchedEnv`'s); the images live on torch's
    ``device``."""

    def __init__(self, system, mjm, model, data, nworld: int, names: dict, wp, mjw, torch,
                 device, on_device):
        self._torch, self._mjw = torch, mjw
        self._model, self._data, self._on_device = model, data, on_device
        self.agents = list(system.agents)
        cams, res = [], []
        for i in self.agents:
            cfg = system.configs[i]
            _check(names[i], cfg, system.cutoffs[i])
            for e in EYES:
                cams.append(int(system.cameras[i][e]))
                res.append((int(cfg.width), int(cfg.height)))
        with on_device():
            self.rc = mjw.create_render_context(mjm, nworld, cam_res=res, render_rgb=True,
                                                render_depth=False, render_seg=False,
                                                cam_active=cams)
        adr = self.rc.rgb_adr.numpy()
        self._packed = wp.to_torch(self.rc.rgb_data)                    # (nworld, pixels) uint32
        #: per agent and eye: (first pixel, height, width) in the packed rows
        self.slots = {}
        k = 0
        for i in self.agents:
            for e in EYES:
                w, h = res[k]
                self.slots[i, e] = (int(adr[k]), h, w)
                k += 1
        self.images = {key: torch.zeros((nworld, h, w, 3), dtype=torch.uint8, device=device)
                       for key, (_, h, w) in self.slots.items()}
        self.renders = 0

    def render(self, worlds=None) -> None:
        """Render every eye from the current state; keep the images of ``worlds`` (a bool mask;
        None: all)."""
        m, d, mjw = self._model, self._data, self._mjw
        with self._on_device():
            mjw.camlight(m, d)
            mjw.refit_bvh(m, d, self.rc)
            mjw.render(m, d, self.rc)
        packed = self._packed.view(self._torch.int32)
        for key, (start, h, w) in self.slots.items():
            px = packed[:, start:start + h * w]
            # the renderer packs a pixel as 0xAARRGGBB
            rgb = self._torch.stack([(px >> 16) & 255, (px >> 8) & 255, px & 255], dim=-1)
            img = rgb.to(self._torch.uint8).reshape(-1, h, w, 3)
            if worlds is None:
                self.images[key] = img
            else:
                self.images[key][worlds] = img[worlds]
        self.renders += 1


class BatchedEyeSense:
    """Agent ``agent``'s eye ``eye`` (``"left"`` / ``"right"``) read from ``eyes``, delayed by
    ``delay`` control steps (the CPU env's ``vision`` channel)."""

    def __init__(self, eyes: BatchedEyes, agent: int, eye: str, delay: int, nworld: int,
                 torch, device):
        self.name = f"eye_{eye}"
        self._eyes, self._key = eyes, (agent, eye)
        _, h, w = eyes.slots[agent, eye]
        self._shape = (h, w, 3)
        self._ring = DelayRing(delay, nworld, h * w * 3, torch, device, dtype=torch.uint8)

    def _flat(self):
        return self._eyes.images[self._key].reshape(self._eyes.images[self._key].shape[0], -1)

    def reset(self, data, worlds=None):
        """The images at reset (the reset worlds' rendered by :meth:`BatchedEyes.render`)."""
        return self._ring.reset(self._flat(), worlds).reshape((-1,) + self._shape)

    def observe(self, data):
        """This step's images (of ``delay`` steps before, when delayed)."""
        return self._ring.push(self._flat().clone()).reshape((-1,) + self._shape)
