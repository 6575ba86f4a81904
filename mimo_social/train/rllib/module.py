"""``EyesPPOModule`` / ``EyesAPPOModule``: torch RLModules (RLlib's new API stack) for an agent
whose observation is the image ``Dict`` of :class:`~mimo_social.core.wrappers.ImageDict`: each
eye a ``uint8`` channel-first image ``(3 * frame_stack, H, W)``, every other sense one float32
``"vector"``. :func:`~mimo_social.train.rllib.config.build_config` gives them to PPO and APPO
for such agents; agents without eyes keep RLlib's default module on their flat Box.

The network is the one of the SB3 path (:mod:`mimo_social.train.encoders`), written for RLlib;
the CNN and the running statistics are the same classes (:mod:`mimo_social.train.image_cnn`):

* a CNN per image (:class:`~mimo_social.train.image_cnn.ImageCNN`): pixels scaled to [0, 1], a
  5x5 convolution of stride 2 with 32 channels, then 3x3 convolutions of stride 2 with 64
  channels (at least three convolutions in all) until the side is at most 8 px, ReLU after
  each, flattened, then ``Linear + ReLU`` to ``image_dim`` (128) features. Images of the same
  shape (the two eyes) share one CNN (``share_weights``), their features are kept apart
  (concatenated). Its layers are ``cnn.*`` and ``head.0`` (state keys such as
  ``encoder.cnns.eye_left.cnn.0.weight``); checkpoints saved when this module had its own copy
  (``convs.*``, ``out.0``) are renamed as they load;
* the ``"vector"`` appended to the image features as it is, or (``normalize_vector``) shifted and
  scaled by running statistics (:class:`~mimo_social.train.image_cnn.RunningMeanStd`, updated
  by the learner's training passes, torch buffers of the module: saved in its checkpoint and
  sent to the env runners with the weights; the pixels are only scaled);
* as SB3's PPO: the features shared by a policy MLP and a separate value MLP (``fcnet_hiddens``
  of ``fcnet_activation``: two tanh layers of 64), a linear action layer and a linear value
  layer; SB3's initial weights (orthogonal, gain sqrt 2, 0.01 on the action layer, 1 on the
  value layer, zero biases).

Actions: a ``Box`` gets a diagonal Gaussian (the action means, then the log stds: a state-free
parameter starting at 0 with ``free_log_std``, else outputs of the action layer), RLlib's
``TorchDiagGaussian``; a ``Discrete`` (a face-only agent) gets its logits, ``TorchCategorical``
(RLlib's defaults for these spaces). PPO's learner takes the values from ``compute_values``
(``ValueFunctionAPI``); APPO's also needs the target network (``TargetNetworkAPI``: copies of the
encoder and the policy head).

``model_config`` keys (a dict; :data:`DEFAULTS` for the missing ones): ``fcnet_hiddens``,
``fcnet_activation`` (``tanh``, ``relu``, ``elu``, ``silu``/``swish`` or ``linear``),
``free_log_std``, ``image_dim``, ``share_weights``, ``normalize_vector``. Imports ray and torch.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np
import torch
from gymnasium import spaces
from ray.rllib.core.columns import Columns
from ray.rllib.core.learner.utils import make_target_network
from ray.rllib.core.rl_module.apis import (TARGET_NETWORK_ACTION_DIST_INPUTS,
                                           TargetNetworkAPI, ValueFunctionAPI)
from ray.rllib.core.rl_module.torch import TorchRLModule
from torch import nn

from ...core.wrappers import VECTOR_KEY
from ..image_cnn import MAX_FINAL_SIDE, ImageCNN, RunningMeanStd

__all__ = ["EyesPPOModule", "EyesAPPOModule", "EyesEncoder", "ImageCNN", "RunningMeanStd",
           "DEFAULTS", "has_images", "MAX_FINAL_SIDE"]

#: the model settings of the modules (SB3's PPO network behind the CNN)
DEFAULTS: dict[str, Any] = {"fcnet_hiddens": [64, 64], "fcnet_activation": "tanh",
                            "free_log_std": True, "image_dim": 128, "share_weights": True,
                            "normalize_vector": False}
HIDDEN_GAIN, PI_GAIN, VF_GAIN = math.sqrt(2.0), 0.01, 1.0
_ACTIVATIONS = {"tanh": nn.Tanh, "relu": nn.ReLU, "elu": nn.ELU, "silu": nn.SiLU,
                "swish": nn.SiLU, "linear": nn.Identity, None: nn.Identity}


def has_images(space: spaces.Space) -> bool:
    """Whether an agent's observation space is an image Dict (channel-first ``uint8`` images,
    bounds 0..255), what these modules take."""
    return bool(_image_shapes(space))


def _image_shapes(space: spaces.Space) -> dict[str, tuple[int, int, int]]:
    """key -> (C, H, W) of the channel-first uint8 images of a Dict space."""
    if not isinstance(space, spaces.Dict):
        return {}
    out = {}
    for key, sub in space.spaces.items():
        # channel-first: the channels are the smallest axis (ImageDict's C * frame_stack is at
        # most min(H, W)); a channel-last image is not one of these
        if (isinstance(sub, spaces.Box) and sub.dtype == np.uint8 and len(sub.shape) == 3
                and int(np.argmin(sub.shape)) == 0 and np.all(sub.low == 0)
                and np.all(sub.high == 255)):
            out[key] = tuple(int(v) for v in sub.shape)
    return out


class EyesEncoder(nn.Module):
    """An image Dict to one feature vector: a CNN per image (shared by images of the same shape
    with ``share_weights``), then the ``"vector"`` (normalised with ``normalize_vector``)."""

    def __init__(self, space: spaces.Dict, image_dim: int = 128, share_weights: bool = True,
                 normalize_vector: bool = False):
        super().__init__()
        shapes = _image_shapes(space)
        if not shapes:
            raise TypeError(f"EyesEncoder needs a Dict of channel-first uint8 images (and a "
                            f"'{VECTOR_KEY}'), got {space}")
        by_shape: dict[tuple, ImageCNN] = {}
        cnns: dict[str, ImageCNN] = {}
        for key, shape in shapes.items():
            if share_weights and shape in by_shape:
                cnns[key] = by_shape[shape]
            else:
                cnns[key] = by_shape[shape] = ImageCNN(shape, image_dim)
        self.image_keys = tuple(shapes)
        self.cnns = nn.ModuleDict(cnns)   # a shared CNN's parameters are registered once
        self.other_keys = tuple(k for k in space.spaces if k not in shapes)
        n_other = sum(int(spaces.flatdim(space[k])) for k in self.other_keys)
        self.norm = RunningMeanStd(n_other) if normalize_vector and n_other else None
        self.out_dim = len(shapes) * int(image_dim) + n_other

    def _vector(self, obs: Mapping[str, torch.Tensor]) -> torch.Tensor | None:
        if not self.other_keys:
            return None
        return torch.cat([obs[k].flatten(1).float() for k in self.other_keys], 1)

    def update_stats(self, obs: Mapping[str, torch.Tensor]) -> None:
        """Update the vector's running statistics (``normalize_vector``) with a batch."""
        if self.norm is not None:
            self.norm.update(self._vector(obs))

    def forward(self, obs: Mapping[str, torch.Tensor]) -> torch.Tensor:
        feats = [self.cnns[k](obs[k]) for k in self.image_keys]
        vector = self._vector(obs)
        if vector is not None:
            feats.append(vector if self.norm is None else self.norm(vector))
        return torch.cat(feats, 1)


def _mlp(n_in: int, hiddens, activation: str | None) -> tuple[nn.Module, int]:
    act = _ACTIVATIONS.get(activation)
    if act is None:
        raise ValueError(f"fcnet_activation={activation!r} not allowed; allowed: "
                         f"{', '.join(k for k in _ACTIVATIONS if k)}")
    layers: list[nn.Module] = []
    for n in hiddens:
        layers += [nn.Linear(n_in, int(n)), act()]
        n_in = int(n)
    return nn.Sequential(*layers), n_in


class PolicyHead(nn.Module):
    """Features to the action distribution's inputs: an MLP, the action layer and, for a Box
    with ``free_log_std``, the state-free log stds."""

    def __init__(self, n_in: int, action_space: spaces.Space, hiddens, activation,
                 free_log_std: bool):
        super().__init__()
        self.net, n = _mlp(n_in, hiddens, activation)
        if isinstance(action_space, spaces.Discrete):
            n_out, self.log_std = int(action_space.n), None
        elif isinstance(action_space, spaces.Box):
            dim = int(np.prod(action_space.shape))
            if free_log_std:
                n_out, self.log_std = dim, nn.Parameter(torch.zeros(dim))
            else:
                n_out, self.log_std = 2 * dim, None
        else:
            raise TypeError(f"action space {action_space} not supported; allowed: Box, "
                            "Discrete")
        self.out = nn.Linear(n, n_out)

    def forward(self, feats: torch.Tensor) -> torch.Tensor:
        out = self.out(self.net(feats))
        if self.log_std is None:
            return out
        return torch.cat([out, self.log_std.expand(out.shape[0], -1)], 1)


def _sb3_init(*nets: nn.Module) -> None:
    """SB3's initial weights: orthogonal with gain sqrt 2, zero biases."""
    with torch.no_grad():
        for net in nets:
            for m in net.modules():
                if isinstance(m, (nn.Linear, nn.Conv2d)):
                    nn.init.orthogonal_(m.weight, gain=HIDDEN_GAIN)
                    nn.init.zeros_(m.bias)


class EyesPPOModule(TorchRLModule, ValueFunctionAPI):
    """PPO's RLModule for an image Dict observation (module docstring)."""

    def setup(self):
        cfg = {**DEFAULTS, **dict(self.model_config or {})}
        self.encoder = EyesEncoder(self.observation_space, int(cfg["image_dim"]),
                                   bool(cfg["share_weights"]), bool(cfg["normalize_vector"]))
        hiddens, act = list(cfg["fcnet_hiddens"]), cfg["fcnet_activation"]
        self.pi = PolicyHead(self.encoder.out_dim, self.action_space, hiddens, act,
                             bool(cfg["free_log_std"]))
        self.vf_net, n = _mlp(self.encoder.out_dim, hiddens, act)
        self.vf_out = nn.Linear(n, 1)
        _sb3_init(self.encoder, self.pi, self.vf_net, self.vf_out)
        with torch.no_grad():
            nn.init.orthogonal_(self.pi.out.weight, gain=PI_GAIN)
            nn.init.orthogonal_(self.vf_out.weight, gain=VF_GAIN)

    def _forward(self, batch: dict[str, Any], **kwargs) -> dict[str, Any]:
        return {Columns.ACTION_DIST_INPUTS: self.pi(self.encoder(batch[Columns.OBS]))}

    def _forward_train(self, batch: dict[str, Any], **kwargs) -> dict[str, Any]:
        obs = batch[Columns.OBS]
        self.encoder.update_stats(obs)   # (normalize_vector: the learner's batches only)
        feats = self.encoder(obs)
        return {Columns.ACTION_DIST_INPUTS: self.pi(feats), Columns.EMBEDDINGS: feats}

    def compute_values(self, batch: dict[str, Any], embeddings: Any | None = None):
        if embeddings is None:
            embeddings = self.encoder(batch[Columns.OBS])
        return self.vf_out(self.vf_net(embeddings)).squeeze(-1)


class EyesAPPOModule(EyesPPOModule, TargetNetworkAPI):
    """APPO's RLModule for an image Dict observation: :class:`EyesPPOModule` with a target copy
    of its encoder and policy head."""

    def make_target_networks(self):
        self._old_encoder = make_target_network(self.encoder)
        self._old_pi = make_target_network(self.pi)

    def get_target_network_pairs(self):
        return [(self.encoder, self._old_encoder), (self.pi, self._old_pi)]

    def forward_target(self, batch: dict[str, Any]) -> dict[str, Any]:
        logits = self._old_pi(self._old_encoder(batch[Columns.OBS]))
        return {TARGET_NETWORK_ACTION_DIST_INPUTS: logits}
