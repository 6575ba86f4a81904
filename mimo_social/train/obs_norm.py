"""Observation normalisation inside the policy: ``RunningNorm``, an SB3 features extractor.

Each input is shifted and scaled by running estimates of its mean and variance (clipped to
+-10), so inputs that barely vary (most pixels of an eye image: the partner's face is a small
part of it) are not drowned by the ones that do not matter. The statistics are torch buffers of
the policy: they are saved in ``model.zip`` and restored by ``PPO.load`` / ``SAC.load``, so
evaluation needs nothing else. They are updated from the batches the policy is trained on (SB3
puts the policy in training mode only in ``train()``), never while acting or evaluating.

The statistics and their update are :class:`~mimo_social.train.image_cnn.RunningMeanStd`'s
(the normaliser of the RLlib eyes module too); ``RunningNorm`` is that module and an SB3
``BaseFeaturesExtractor``, flattening its input and learning in training mode.

``mimo-social train ... --normalize-obs`` uses it (``policy_kwargs={"features_extractor_class":
RunningNorm}``); ``--obs-min-std S`` floors the scale at S (``features_extractor_kwargs``
``{"min_std": S}``: an input that only jitters stays small instead of being scaled up to +-10).
"""

from __future__ import annotations

import numpy as np
import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

from .image_cnn import RunningMeanStd

__all__ = ["RunningNorm"]


class RunningNorm(RunningMeanStd, BaseFeaturesExtractor):
    """Running mean/std normalisation of a flattened observation (module docstring); the
    state-dict keys are ``mean``, ``var`` and ``count``."""

    def __init__(self, observation_space: spaces.Box, clip: float = 10.0, eps: float = 1e-8,
                 min_std: float = 0.0):
        n = int(np.prod(observation_space.shape))
        super().__init__(n, clip, eps, min_std, observation_space=observation_space,
                         features_dim=n)

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        x = observations.flatten(1).float()
        if self.training:
            self.update(x)     # (a batch of one row is skipped)
        return self.normalize(x)
