"""Observation normalisation inside the policy: ``RunningNorm``, an SB3 features extractor.

Each input is shifted and scaled by running estimates of its mean and variance (clipped to
+-10), so inputs that barely vary (most pixels of an eye image: the partner's face is a small
part of it) are not drowned by the ones that do not matter. The statistics are torch buffers of
the policy: they are saved in ``model.zip`` and restored by ``PPO.load`` / ``SAC.load``, so
evaluation needs nothing else. They are updated from the batches the policy is trained on (SB3
puts the policy in training mode only in ``train()``), never while acting or evaluating.

``mimo-social train ... --normalize-obs`` uses it (``policy_kwargs={"features_extractor_class":
RunningNorm}``).
"""

from __future__ import annotations

import numpy as np
import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

__all__ = ["RunningNorm"]


class RunningNorm(BaseFeaturesExtractor):
    def __init__(self, observation_space: spaces.Box, clip: float = 10.0, eps: float = 1e-8):
        n = int(np.prod(observation_space.shape))
        super().__init__(observation_space, features_dim=n)
        self.clip, self.eps = float(clip), float(eps)
        self.register_buffer("mean", torch.zeros(n))
        self.register_buffer("var", torch.ones(n))
        self.register_buffer("count", torch.tensor(1e-4, dtype=torch.float64))

    @torch.no_grad()
    def _update(self, x: torch.Tensor) -> None:
        """Merge a batch's mean and variance into the running ones (Chan et al.'s parallel
        formula)."""
        b = x.shape[0]
        bm, bv = x.mean(0), x.var(0, unbiased=False)
        total = self.count + b
        delta = bm - self.mean
        w = float(b / total)
        self.mean += delta * w
        m2 = self.var * float(self.count) + bv * b + delta.pow(2) * float(self.count * b / total)
        self.var.copy_(m2 / float(total))
        self.count.copy_(total)

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        x = observations.flatten(1).float()
        if self.training and x.shape[0] > 1:
            self._update(x)
        return ((x - self.mean) / torch.sqrt(self.var + self.eps)).clamp(-self.clip, self.clip)
