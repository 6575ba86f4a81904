"""What the CPU vision sense does to a rendered eye image, done on the device to a batch of them
(:mod:`mimo_social.gpu.eyes`): the acuity blur (:mod:`mimo_social.senses.acuity`), then the
fovea's warp (:mod:`mimo_social.senses.fovea`), with the CPU's own filters: the blur's two band
matrices and the warp's sparse weights are the ones the CPU sense built for the agent, carried
to torch's device once. Colour images are rounded as the CPU rounds them (half up, in float32:
the sums run in another order, so a pixel may differ by one count); depth images are not
blurred, and warped by the nearest render pixel, as on the CPU.
"""

from __future__ import annotations

import numpy as np

__all__ = ["EyeOptics"]


class EyeOptics:
    """One agent's optics: ``blur`` (an :class:`~mimo_social.senses.acuity.AcuityBlur` at the
    render size, or None) and ``fovea`` (a :class:`~mimo_social.senses.fovea.FovealWarp`, or
    None), on torch's ``device``."""

    def __init__(self, blur, fovea, torch, device):
        self._torch = torch
        self.blur, self.fovea = blur is not None, fovea is not None
        if self.blur:
            rows, cols = blur.matrices()
            self._rows = torch.as_tensor(rows, device=device)                  # (H, H)
            self._cols_t = torch.as_tensor(cols.T.copy(), device=device)       # (W, W)
        if self.fovea:
            m = fovea.matrix.tocoo()
            index = torch.as_tensor(np.stack([m.row, m.col]).astype(np.int64))
            self._warp = torch.sparse_coo_tensor(index, torch.as_tensor(m.data), size=m.shape,
                                                 device=device, check_invariants=True).coalesce()
            self._nearest = torch.as_tensor(fovea.nearest.ravel(), device=device)
            self.shape = (fovea.height, fovea.width)

    @property
    def identity(self) -> bool:
        return not (self.blur or self.fovea)

    def rgb(self, images):
        """``(n, H, W, 3)`` uint8 rendered images -> the observed ``(n, h, w, 3)`` uint8."""
        if self.identity:
            return images
        torch = self._torch
        x = images.to(torch.float32)
        if self.blur:
            x = (self._rows @ x.permute(0, 3, 1, 2)) @ self._cols_t          # (n, 3, H, W)
            x = x.permute(0, 2, 3, 1)
            if not self.fovea:
                return _to_uint8(x, torch)
            x = _to_uint8(x, torch).to(torch.float32)   # the CPU warps the rounded blur
        n = x.shape[0]
        flat = x.reshape(n, -1, 3).permute(1, 0, 2).reshape(x.shape[1] * x.shape[2], n * 3)
        out = (self._warp @ flat).reshape(self.shape + (n, 3)).permute(2, 0, 1, 3)
        return _to_uint8(out, torch)

    def depth(self, images):
        """``(n, H, W)`` float32 rendered depth -> the observed ``(n, h, w)`` (nearest pixel)."""
        if not self.fovea:
            return images
        n = images.shape[0]
        return images.reshape(n, -1)[:, self._nearest].reshape((n,) + self.shape)


def _to_uint8(x, torch):
    """Round half up and clip into 0..255, as the CPU's filters do."""
    return (x + 0.5).clamp_(0.0, 255.0).to(torch.uint8)
