"""Pixels through a CNN: the features extractor SB3 learners use when they see images.

``EyesExtractor(observation_space)``
    An SB3 ``BaseFeaturesExtractor`` for the ``Dict`` observation of
    :class:`~mimo_social.core.wrappers.DictObservationWrapper`: one small convolutional
    encoder per image (the eyes; ``uint8`` channel-first ``(C, H, W)``, C possibly
    ``3 x frame_stack``) and the float32 ``"vector"`` (every other sense) passed through
    unchanged, or through one ``Linear + ReLU`` layer of ``vector_dim`` units; the features are
    concatenated, images in key order, the vector last.
``policy_spec(observation_space)``
    ``("MultiInputPolicy", {"features_extractor_class": EyesExtractor, ...})`` for a ``Dict``
    with an image, else ``("MlpPolicy", {})``.

The image encoder is :class:`~mimo_social.train.image_cnn.ImageCNN` (``ImageEncoder`` here: the
same class), the one CNN of the SB3 and the RLlib paths, sized for square images of 32 to 128
px: pixels scaled to [0, 1] inside; a 5x5 convolution of stride 2 with 32 channels, then 3x3
convolutions of stride 2 with 64 channels until the side is at most 8 px, ReLU after each;
flattened and one ``Linear + ReLU`` to ``image_dim`` (128) features. No pooling.

Weights: images of the same shape (the two eyes) share one encoder by default
(``share_weights=True``): both eyes see the same kind of scene, sharing halves the parameters
and doubles the data each filter learns from, and the features of each eye are still kept
apart (concatenated, not summed), so the policy can compare them. ``share_weights=False`` gives
each image its own encoder.

Pixels are scaled here, so :func:`policy_spec` turns SB3's own image scaling off
(``normalize_images=False``); keep it off when passing this extractor by hand.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from gymnasium import spaces
from stable_baselines3.common.preprocessing import is_image_space
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from .image_cnn import MAX_FINAL_SIDE, ImageCNN
from .obs_norm import RunningNorm

__all__ = ["EyesExtractor", "policy_spec", "policy_for", "image_space_keys",
           "RECURRENT_POLICIES", "ImageCNN", "ImageEncoder", "MAX_FINAL_SIDE"]

#: the image CNN's former name here (the class lives in :mod:`~mimo_social.train.image_cnn`)
ImageEncoder = ImageCNN


def image_space_keys(space: spaces.Space) -> tuple[str, ...]:
    """The keys of a ``Dict`` space that SB3 treats as images (``uint8`` (C, H, W) or
    (H, W, C), bounds 0..255); ``()`` for any other space."""
    if not isinstance(space, spaces.Dict):
        return ()
    return tuple(k for k, sub in space.spaces.items() if is_image_space(sub))


class EyesExtractor(BaseFeaturesExtractor):
    """A CNN per image key and the other keys flattened, features concatenated.

    ``image_dim``: features per image (128); ``vector_dim``: ``None`` passes the non-image keys
    through unchanged (flattened), a number puts one ``Linear + ReLU`` of that width on them;
    ``share_weights``: one encoder for all images of the same shape (the two eyes);
    ``normalize_vector``: the non-image keys go through :class:`~.obs_norm.RunningNorm` first
    (running mean and variance, saved with the policy: ``--normalize-obs`` for a learner with
    eyes; the pixels are only scaled to [0, 1]); ``norm_min_std``: that normaliser's floor on
    its scale (``--obs-min-std``; 0: none).
    Images must be channel-first, as :class:`~mimo_social.core.wrappers.DictObservationWrapper`
    gives them (SB3's ``VecTransposeImage`` also makes channel-last images channel-first).
    """

    def __init__(self, observation_space: spaces.Dict, image_dim: int = 128,
                 vector_dim: int | None = None, share_weights: bool = True,
                 normalize_vector: bool = False, norm_min_std: float = 0.0):
        keys = image_space_keys(observation_space)
        if not keys:
            raise TypeError(f"EyesExtractor needs a Dict observation with an image (a uint8 "
                            f"Box (C, H, W), bounds 0..255), got {observation_space}")
        encoders: dict[str, ImageCNN] = {}
        by_shape: dict[tuple, ImageCNN] = {}
        for key in keys:
            shape = _channels_first(observation_space[key].shape)
            if share_weights and shape in by_shape:
                encoders[key] = by_shape[shape]
            else:
                encoders[key] = by_shape[shape] = ImageCNN(shape, image_dim)
        others = [k for k in observation_space.spaces if k not in encoders]
        n_other = sum(int(spaces.flatdim(observation_space[k])) for k in others)
        if vector_dim is not None and n_other > 0:
            vector: nn.Module = nn.Sequential(nn.Linear(n_other, int(vector_dim)), nn.ReLU())
            n_vector = int(vector_dim)
        else:
            vector, n_vector = nn.Identity(), n_other
        super().__init__(observation_space, len(keys) * int(image_dim) + n_vector)
        self.image_keys = keys
        self.other_keys = tuple(others)
        # a ModuleDict registers a shared encoder once (parameters are deduplicated)
        self.encoders = nn.ModuleDict(encoders)
        self.vector = vector
        self.norm = (RunningNorm(spaces.Box(-np.inf, np.inf, (n_other,), np.float32),
                                 min_std=float(norm_min_std))
                     if normalize_vector and n_other > 0 else None)
        self.transpose = {k: _is_channels_last(observation_space[k].shape) for k in keys}

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        feats = []
        for key in self.image_keys:
            x = observations[key]
            if self.transpose[key]:
                x = x.permute(0, 3, 1, 2)
            feats.append(self.encoders[key](x))
        if self.other_keys:
            rest = torch.cat([observations[k].flatten(1).float() for k in self.other_keys], 1)
            if self.norm is not None:
                rest = self.norm(rest)
            feats.append(self.vector(rest))
        return torch.cat(feats, dim=1)


def _is_channels_last(shape: tuple[int, ...]) -> bool:
    # SB3's rule (is_image_space_channels_first): the smallest axis holds the channels
    return int(np.argmin(shape)) != 0


def _channels_first(shape: tuple[int, ...]) -> tuple[int, int, int]:
    if _is_channels_last(shape):
        return int(shape[2]), int(shape[0]), int(shape[1])
    return int(shape[0]), int(shape[1]), int(shape[2])


def policy_spec(observation_space: spaces.Space, **extractor_kwargs: Any) -> tuple[str, dict]:
    """The SB3 policy name and ``policy_kwargs`` for an observation space.

    A ``Dict`` with an image: ``("MultiInputPolicy", {"features_extractor_class":
    EyesExtractor, "features_extractor_kwargs": extractor_kwargs, "normalize_images": False})``
    (the extractor scales the pixels itself); anything else: ``("MlpPolicy", {})``. Merge your
    own ``policy_kwargs`` over the returned ones (``net_arch`` etc. apply after the extractor).
    """
    if image_space_keys(observation_space):
        return "MultiInputPolicy", {"features_extractor_class": EyesExtractor,
                                    "features_extractor_kwargs": dict(extractor_kwargs),
                                    "normalize_images": False}
    if extractor_kwargs:
        raise TypeError(f"extractor keyword arguments {sorted(extractor_kwargs)} given for an "
                        "observation without images (MlpPolicy has no image extractor)")
    return "MlpPolicy", {}


#: the recurrent (LSTM) policy of sb3-contrib's RecurrentPPO for each of SB3's policy names
RECURRENT_POLICIES = {"MlpPolicy": "MlpLstmPolicy", "MultiInputPolicy": "MultiInputLstmPolicy"}


def policy_for(observation_space: spaces.Space, algo_kwargs: dict,
               normalize_obs: bool = False, recurrent: bool = False,
               min_std: float = 0.0, categorical_groups=None) -> tuple[Any, dict]:
    """What the trainers build: the SB3 policy name and the algorithm's keyword arguments for
    an observation space. Images: :func:`policy_spec`'s ``MultiInputPolicy`` with the CNN
    (``normalize_obs``: running statistics over the ``"vector"`` part); otherwise
    ``MlpPolicy`` (``normalize_obs``: :class:`~mimo_social.train.obs_norm.RunningNorm` over the
    whole input); ``min_std`` (> 0, with ``normalize_obs``): the normaliser's floor on its
    scale (``--obs-min-std``). ``recurrent`` (``--algo recurrent_ppo``): the LSTM policies of
    sb3-contrib, ``MultiInputLstmPolicy`` (the same CNN in front of the LSTM) and
    ``MlpLstmPolicy``. The ``policy_kwargs`` of ``algo_kwargs`` (the shipped hyperparameters and the command line's)
    are merged over these. ``categorical_groups`` (the learner's logit groups, ``[[start, n],
    ...]``): the policy is :class:`~mimo_social.train.categorical_heads.CategoricalHeadsPolicy`
    (the class, not a name) with them among its ``policy_kwargs``."""
    kwargs = dict(algo_kwargs)
    own = dict(kwargs.pop("policy_kwargs", None) or {})
    if image_space_keys(observation_space):
        floor = {"norm_min_std": float(min_std)} if normalize_obs and min_std else {}
        policy, base = policy_spec(observation_space,
                                   **({"normalize_vector": True, **floor} if normalize_obs
                                      else {}))
    else:
        policy, base = policy_spec(observation_space)
        if normalize_obs:
            base = {"features_extractor_class": RunningNorm}
            if min_std:
                base["features_extractor_kwargs"] = {"min_std": float(min_std)}
    merged = {**base, **own}
    if categorical_groups:
        from .categorical_heads import CategoricalHeadsPolicy
        if recurrent:
            raise ValueError("categorical heads are not for a recurrent policy")
        merged["categorical_groups"] = [list(g) for g in categorical_groups]
        return CategoricalHeadsPolicy, {**kwargs, "policy_kwargs": merged}
    if merged:
        kwargs["policy_kwargs"] = merged
    return (RECURRENT_POLICIES[policy] if recurrent else policy), kwargs
