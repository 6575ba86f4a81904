"""The on-device PPO's networks (:mod:`mimo_social.train.gpu_ppo`): a running normalisation of
the senses, an optional convolutional encoder of the eyes, the actor (TorchRL's
:class:`~torchrl.modules.ProbabilisticActor`, a tanh-normal distribution over the motors' Box:
an MLP for the mean, a learnt state-independent log std) and the critic (a
:class:`~torchrl.modules.ValueOperator` MLP).

Inputs: ``"observation"``, the senses other than the eyes concatenated (float32 ``(n, size)``),
and with eyes ``"pixels"``, both eyes' images stacked along the colour axis (uint8 ``(n, H, W,
6)``: left RGB then right RGB). The actor and the critic each have their own
:class:`EyeEncoder` (the critic's gradients do not shape the actor's features) and share the
normaliser: its statistics are buffers of both, saved with the actor.
"""

from __future__ import annotations

import torch
from tensordict import TensorDict
from tensordict.nn import TensorDictModule
from torch import nn
from torchrl.envs.utils import ExplorationType, set_exploration_type
from torchrl.modules import MLP, ProbabilisticActor, TanhNormal, ValueOperator

__all__ = ["RunningObsNorm", "EyeEncoder", "build_networks", "act", "input_keys"]


class RunningObsNorm(nn.Module):
    """Observations shifted and scaled by running estimates of their mean and variance
    (clipped to +-``clip``); the estimates are buffers (``mean``, ``var``, ``count``), changed
    only by :meth:`update`, never by the forward pass."""

    def __init__(self, size: int, clip: float = 10.0, eps: float = 1e-8):
        super().__init__()
        self.clip, self.eps = float(clip), float(eps)
        self.register_buffer("mean", torch.zeros(size))
        self.register_buffer("var", torch.ones(size))
        self.register_buffer("count", torch.zeros(()))

    @torch.no_grad()
    def update(self, x: torch.Tensor) -> None:
        """Merge a batch ``(..., size)`` into the estimates (Chan et al.'s parallel rule)."""
        x = x.reshape(-1, self.mean.shape[0]).to(self.mean.dtype)
        n = float(x.shape[0])
        if n == 0:
            return
        mean, var = x.mean(0), x.var(0, unbiased=False)
        total = self.count + n
        delta = mean - self.mean
        m2 = self.var * self.count + var * n + delta.square() * self.count * n / total
        self.mean += delta * n / total
        self.var.copy_(m2 / total)
        self.count.copy_(total)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        z = (x - self.mean) / torch.sqrt(self.var + self.eps)
        return z.clamp(-self.clip, self.clip)


class EyeEncoder(nn.Module):
    """uint8 images ``(..., H, W, C)`` -> ``(..., features)`` numbers: three convolutions of stride 2,
    each halving the image (5x5, then two 3x3, padded; 16, 32, 32 channels, ReLU) over the
    images scaled to 0..1, then a linear layer with ReLU. For 64x64 eyes: 32 x 8 x 8 = 2,048
    numbers into the layer; for 16x16: 32 x 2 x 2."""

    def __init__(self, height: int, width: int, channels: int = 6, features: int = 128):
        super().__init__()
        self.conv = nn.Sequential(
            nn.Conv2d(channels, 16, 5, stride=2, padding=2), nn.ReLU(),
            nn.Conv2d(16, 32, 3, stride=2, padding=1), nn.ReLU(),
            nn.Conv2d(32, 32, 3, stride=2, padding=1), nn.ReLU(), nn.Flatten())
        with torch.no_grad():
            size = self.conv(torch.zeros(1, channels, int(height), int(width))).shape[1]
        self.out = nn.Sequential(nn.Linear(size, features), nn.ReLU())
        self.features = int(features)

    def forward(self, pixels: torch.Tensor) -> torch.Tensor:
        lead = pixels.shape[:-3]            # any leading dims: worlds, steps, ...
        x = pixels.reshape((-1,) + tuple(pixels.shape[-3:])).permute(0, 3, 1, 2)
        y = self.out(self.conv(x.to(torch.float32) * (1.0 / 255.0)))
        return y.reshape(tuple(lead) + (self.features,))


class _Trunk(nn.Module):
    """The normalised senses, and with eyes their encoding, concatenated."""

    def __init__(self, norm: RunningObsNorm, eyes: tuple | None):
        super().__init__()
        self.norm = norm
        self.eyes = None if eyes is None else EyeEncoder(*eyes)
        self.extra = 0 if self.eyes is None else self.eyes.features

    def features(self, obs, pixels=None):
        x = self.norm(obs)
        return x if self.eyes is None else torch.cat([x, self.eyes(pixels)], dim=-1)


class _Gaussian(_Trunk):
    """Inputs -> (loc, scale): an MLP for the mean, a learnt log std."""

    def __init__(self, norm, n_obs: int, n_act: int, hidden: int, init_log_std: float,
                 eyes: tuple | None = None):
        super().__init__(norm, eyes)
        self.mlp = MLP(in_features=n_obs + self.extra, out_features=n_act,
                       num_cells=[hidden, hidden], activation_class=nn.Tanh)
        self.log_std = nn.Parameter(torch.full((n_act,), float(init_log_std)))

    def forward(self, obs, pixels=None):
        loc = self.mlp(self.features(obs, pixels))
        return loc, self.log_std.exp().expand_as(loc)


class _Value(_Trunk):
    def __init__(self, norm, n_obs: int, hidden: int, eyes: tuple | None = None):
        super().__init__(norm, eyes)
        self.mlp = MLP(in_features=n_obs + self.extra, out_features=1,
                       num_cells=[hidden, hidden], activation_class=nn.Tanh)

    def forward(self, obs, pixels=None):
        return self.mlp(self.features(obs, pixels))


def input_keys(eyes) -> list[str]:
    """The networks' input keys: ``"observation"``, and ``"pixels"`` with eyes."""
    return ["observation"] + (["pixels"] if eyes is not None else [])


def build_networks(n_obs: int, low: torch.Tensor, high: torch.Tensor, config,
                   eyes: tuple | None = None):
    """The actor (``"observation"`` (and ``"pixels"``) -> ``"action"`` in ``[low, high]`` and
    its log-probability) and the critic (-> ``"state_value"``) for ``config`` (a
    :class:`~mimo_social.train.gpu_ppo.GpuPPOConfig`: ``hidden``, ``init_log_std``); ``eyes``:
    ``(height, width, channels)`` of ``"pixels"``, or None. Returns ``(actor, critic, norm)``."""
    dev = low.device
    norm = RunningObsNorm(n_obs).to(dev)
    n_act = int(low.shape[-1])
    keys = input_keys(eyes)
    gauss = _Gaussian(norm, n_obs, n_act, config.hidden, config.init_log_std, eyes).to(dev)
    actor = ProbabilisticActor(
        TensorDictModule(gauss, in_keys=keys, out_keys=["loc", "scale"]),
        in_keys=["loc", "scale"], distribution_class=TanhNormal,
        distribution_kwargs={"low": low, "high": high}, return_log_prob=True)
    critic = ValueOperator(_Value(norm, n_obs, config.hidden, eyes).to(dev), in_keys=keys)
    return actor, critic, norm


@torch.no_grad()
def act(actor, inputs, explore: bool = True) -> TensorDict:
    """The actor on ``inputs`` (the ``"observation"`` tensor ``(n, size)``, or a dict of the
    input keys): the actions sampled from its distribution (``explore``; TorchRL's modules take
    the distribution's mode unless told to sample) or its deterministic action, with their
    log-probabilities, as a TensorDict ``(n,)``."""
    if isinstance(inputs, torch.Tensor):
        inputs = {"observation": inputs}
    first = inputs["observation"]
    kind = ExplorationType.RANDOM if explore else ExplorationType.DETERMINISTIC
    with set_exploration_type(kind):
        return actor(TensorDict(dict(inputs), batch_size=[first.shape[0]],
                                device=first.device))
