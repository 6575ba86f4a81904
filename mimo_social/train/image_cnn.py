"""The eyes' image CNN and the running mean/std normaliser: one torch definition for both
training paths. SB3's :class:`~mimo_social.train.encoders.EyesExtractor` (and
:class:`~mimo_social.train.obs_norm.RunningNorm`) and RLlib's
:class:`~mimo_social.train.rllib.module.EyesEncoder` build on these classes. Imports torch only
(neither SB3 nor ray), so either path can import it.

``ImageCNN(shape, out_dim=128)``
    One channel-first image ``(C, H, W)`` of raw 0..255 values (``uint8`` or float) to
    ``out_dim`` features, sized for square images of 32 to 128 px: pixels scaled to [0, 1]
    inside; a 5x5 convolution of stride 2 with 32 channels, then 3x3 convolutions of stride 2
    with 64 channels (at least three convolutions in all) until the side is at most
    :data:`MAX_FINAL_SIDE` (8) px (two more for 32 and 64 px, three for 96 and 128 px; padding
    keeps ``ceil(side / 2)`` at each, so a 32 px image ends at 4x4 and nothing goes negative),
    ReLU after each; flattened (at most 64 x 8 x 8 = 4096 values, whatever the resolution) and
    one ``Linear + ReLU`` to ``out_dim`` features. No pooling: where the partner's face is in
    the image is what joint attention needs.
``RunningMeanStd(n)``
    Inputs shifted and scaled by a running mean and variance (clipped to +-10); ``min_std`` (0:
    none) floors the scale, so an input that barely varies (a held joint's jitter of 1e-5 rad)
    is not blown up to the size of one that matters. The statistics
    are torch buffers (``mean``, ``var``, ``count``: saved with the model) and change only
    through :meth:`RunningMeanStd.update` (a batch of at least 2; Chan et al.'s parallel
    formula), so the caller decides which passes learn them.

State-dict keys: ``cnn.<i>.weight`` / ``.bias`` for the convolutions and ``head.0.weight`` /
``.bias`` for the linear layer (the names of SB3's ``ImageEncoder`` before this module).
RLlib's ``ImageCNN`` named them ``convs.<i>`` and ``out.0``: a state holding those names (an
RLlib checkpoint saved before) is renamed while it loads.
"""

from __future__ import annotations

from typing import Any

import torch
from torch import nn

__all__ = ["ImageCNN", "RunningMeanStd", "MAX_FINAL_SIDE"]

#: the side (px) at or below which no further stride-2 convolution is added
MAX_FINAL_SIDE = 8
#: names of the layers in states saved before (RLlib's ImageCNN) -> today's names
_OLD_NAMES = {"convs.": "cnn.", "out.": "head."}


class ImageCNN(nn.Module):
    """One channel-first image ``(C, H, W)``, raw 0..255 values, to ``out_dim`` features
    (module docstring); ``first_channels`` / ``channels``: the widths of the first and of the
    later convolutions."""

    def __init__(self, shape: tuple[int, int, int], out_dim: int = 128,
                 first_channels: int = 32, channels: int = 64):
        super().__init__()
        c, h, w = (int(v) for v in shape)
        if min(c, h, w) < 1:
            raise ValueError(f"image shape {shape} not allowed; allowed: (C, H, W), all >= 1")
        layers: list[nn.Module] = [nn.Conv2d(c, first_channels, 5, stride=2, padding=2),
                                   nn.ReLU()]
        side, n_in, n_convs = (max(h, w) + 1) // 2, first_channels, 1
        while (n_convs < 3 or side > MAX_FINAL_SIDE) and side > 1:
            layers += [nn.Conv2d(n_in, channels, 3, stride=2, padding=1), nn.ReLU()]
            n_in, side, n_convs = channels, (side + 1) // 2, n_convs + 1
        layers.append(nn.Flatten())
        self.cnn = nn.Sequential(*layers)
        with torch.no_grad():
            n_flat = int(self.cnn(torch.zeros(1, c, h, w)).shape[1])
        self.head = nn.Sequential(nn.Linear(n_flat, int(out_dim)), nn.ReLU())
        self.out_dim = int(out_dim)

    def forward(self, images: torch.Tensor) -> torch.Tensor:
        return self.head(self.cnn(images.float() * (1.0 / 255.0)))

    def _load_from_state_dict(self, state_dict: dict[str, Any], prefix: str, *args) -> None:
        # a state saved before (RLlib's convs.* / out.*): today's names, then the usual load
        for key in [k for k in state_dict if k.startswith(prefix)]:
            rest = key[len(prefix):]
            for old, new in _OLD_NAMES.items():
                if rest.startswith(old) and prefix + new + rest[len(old):] not in state_dict:
                    state_dict[prefix + new + rest[len(old):]] = state_dict.pop(key)
                    break
        super()._load_from_state_dict(state_dict, prefix, *args)


class RunningMeanStd(nn.Module):
    """Inputs shifted and scaled by a running mean and variance (module docstring).

    Keyword arguments other than ``clip``, ``eps`` and ``min_std`` go on to the next class's
    ``__init__`` (cooperative: SB3's :class:`~mimo_social.train.obs_norm.RunningNorm` is this
    and an SB3 features extractor)."""

    def __init__(self, n: int, clip: float = 10.0, eps: float = 1e-8, min_std: float = 0.0,
                 **kwargs: Any):
        super().__init__(**kwargs)
        self.clip, self.eps, self.min_std = float(clip), float(eps), float(min_std)
        self.register_buffer("mean", torch.zeros(n))
        self.register_buffer("var", torch.ones(n))
        self.register_buffer("count", torch.tensor(1e-4, dtype=torch.float64))

    @torch.no_grad()
    def update(self, x: torch.Tensor) -> None:
        """Merge the mean and variance of a batch ``(B, n)`` into the running ones (Chan et
        al.'s parallel formula); a batch of one row is ignored (it has no variance)."""
        b = x.shape[0]
        if b < 2:
            return
        batch_mean, batch_var = x.mean(0), x.var(0, unbiased=False)
        total = self.count + b
        delta = batch_mean - self.mean
        self.mean += delta * float(b / total)
        m2 = (self.var * float(self.count) + batch_var * b
              + delta.pow(2) * float(self.count * b / total))
        self.var.copy_(m2 / float(total))
        self.count.copy_(total)

    def normalize(self, x: torch.Tensor) -> torch.Tensor:
        """``x`` shifted and scaled by the running statistics (the scale at least
        ``min_std``), clipped to +-``clip``."""
        scale = torch.sqrt(self.var + self.eps).clamp_min(self.min_std)
        return ((x - self.mean) / scale).clamp(-self.clip, self.clip)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.normalize(x)
