"""An intrinsic-motivation bonus for SB3 learners: random network distillation (RND).

``intrinsic={"kind": "rnd", "coef": 0.01, "extrinsic": 1.0, "seed": s}`` (``train(...,
intrinsic=...)``, ``mimo-social train --intrinsic rnd``) wraps the learner's VecEnv in
:class:`RNDBonus`: the reward the learner sees is ``extrinsic * task reward + coef * bonus``;
``extrinsic=0`` is a reward-free run (e.g. a paradigm explored for novelty alone).

The bonus of an observation is the error of a trained *predictor* network at reproducing the
output of a fixed, randomly initialised *target* network on it (Burda et al. 2018, "Exploration
by Random Network Distillation"): high for observations unlike those seen so far, falling as
they recur. Here:

* the observation: a flat Box as it is; a ``Dict`` (eye images and a ``"vector"``) flattened,
  images scaled to [0, 1] and average-pooled to at most 16 x 16 per channel (novelty in
  coarse views; keeps the networks small);
* inputs normalised by running statistics (clipped to +-5, as in the paper), updated on every
  batch;
* target and predictor: ``Linear(n, 64) - ReLU - Linear(64, 64)``, initialised from
  ``torch.Generator().manual_seed(seed)`` (the run's seed: the same bonus under the same seed);
* the predictor takes one Adam step (learning rate ``lr``, 1e-3) on each vector step's batch;
* the bonus divided by the running root mean square of the bonuses so far, so ``coef`` has
  the same meaning across tasks.

Every slot's info gets ``intrinsic_reward`` (the scaled bonus before ``coef``) and
``extrinsic_reward`` (the task's reward). The episodes a run logs and its evaluations are the
task's own returns (the monitors sit below this wrapper; evaluations use a separate env). The
predictor and the statistics are not saved with the model: they shape training only.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import torch
from gymnasium import spaces
from stable_baselines3.common.vec_env import VecEnvWrapper
from torch import nn

from .image_cnn import RunningMeanStd

__all__ = ["RNDBonus", "check_intrinsic", "INTRINSIC_KINDS", "DEFAULTS"]

INTRINSIC_KINDS = ("rnd",)
#: the settings' defaults (``seed`` defaults to the run's)
DEFAULTS = {"coef": 0.01, "extrinsic": 1.0, "lr": 1e-3, "hidden": 64}
#: the largest side an image keeps (average pooling) before it enters the networks
MAX_SIDE = 16


def check_intrinsic(intrinsic: Any, seed: int) -> dict | None:
    """``intrinsic`` (None, a kind's name, or a mapping with ``kind`` and settings) as a full
    settings dict, or None; ValueError naming the field, the value and what is allowed."""
    if intrinsic is None:
        return None
    spec = {"kind": intrinsic} if isinstance(intrinsic, str) else intrinsic
    if not isinstance(spec, Mapping):
        raise ValueError(f"intrinsic={intrinsic!r}; allowed: None, 'rnd' or a mapping "
                         "{'kind': 'rnd', 'coef': ..., 'extrinsic': ..., 'lr': ...}")
    out = {"kind": spec.get("kind"), **DEFAULTS, "seed": int(seed)}
    unknown = sorted(set(spec) - set(out))
    if unknown:
        raise ValueError(f"intrinsic: unknown setting(s) {unknown}; allowed: "
                         f"{sorted(out)}")
    if out["kind"] not in INTRINSIC_KINDS:
        raise ValueError(f"intrinsic kind={out['kind']!r}; allowed: {list(INTRINSIC_KINDS)}")
    out.update(spec)
    for key, low in (("coef", 0.0), ("extrinsic", 0.0), ("lr", 0.0)):
        v = out[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) \
                or v < low or (key == "lr" and v == 0):
            raise ValueError(f"intrinsic {key}={v!r}; allowed: a finite number "
                             f"{'> 0' if key == 'lr' else '>= 0'}")
        out[key] = float(v)
    h = out["hidden"]
    if isinstance(h, bool) or not isinstance(h, int) or h < 1:
        raise ValueError(f"intrinsic hidden={h!r}; allowed: an integer >= 1")
    if isinstance(out["seed"], bool) or not isinstance(out["seed"], int):
        raise ValueError(f"intrinsic seed={out['seed']!r}; allowed: an integer")
    return out


class _Features:
    """A batch of VecEnv observations as one float tensor ``(B, n)`` (module docstring)."""

    def __init__(self, space: spaces.Space):
        self.keys = sorted(space.spaces) if isinstance(space, spaces.Dict) else [None]
        self.pools: dict = {}
        n = 0
        for k in self.keys:
            sub = space[k] if k is not None else space
            shape = tuple(sub.shape)
            if len(shape) == 3:          # a channel-first image (C, H, W)
                c, h, w = shape
                kh, kw = -(-h // MAX_SIDE), -(-w // MAX_SIDE)
                self.pools[k] = (kh, kw)
                n += c * (-(-h // kh)) * (-(-w // kw))
            else:
                n += int(np.prod(shape)) if shape else 1
        self.n = n

    def __call__(self, obs) -> torch.Tensor:
        parts = []
        for k in self.keys:
            x = torch.as_tensor(np.asarray(obs[k] if k is not None else obs))
            if k in self.pools:
                kh, kw = self.pools[k]
                x = nn.functional.avg_pool2d(x.float() / 255.0, (kh, kw), ceil_mode=True)
            parts.append(x.float().reshape(x.shape[0], -1))
        return torch.cat(parts, dim=1)


def _mlp(n_in: int, hidden: int, generator: torch.Generator) -> nn.Sequential:
    net = nn.Sequential(nn.Linear(n_in, hidden), nn.ReLU(), nn.Linear(hidden, hidden))
    with torch.no_grad():
        for layer in net:
            if isinstance(layer, nn.Linear):
                bound = 1.0 / np.sqrt(layer.in_features)
                layer.weight.uniform_(-bound, bound, generator=generator)
                layer.bias.uniform_(-bound, bound, generator=generator)
    return net


class RNDBonus(VecEnvWrapper):
    """``venv`` whose rewards are ``extrinsic * reward + coef * RND bonus`` (module docstring);
    ``settings``: :func:`check_intrinsic`'s dict."""

    def __init__(self, venv, settings: Mapping[str, Any]):
        super().__init__(venv)
        self.settings = dict(settings)
        gen = torch.Generator().manual_seed(int(self.settings["seed"]))
        self.features = _Features(venv.observation_space)
        hidden = int(self.settings["hidden"])
        self.target = _mlp(self.features.n, hidden, gen).requires_grad_(False)
        self.predictor = _mlp(self.features.n, hidden, gen)
        self.optimizer = torch.optim.Adam(self.predictor.parameters(), lr=self.settings["lr"])
        self.obs_stats = RunningMeanStd(self.features.n, clip=5.0)
        self.bonus_var, self.bonus_count = 1.0, 1e-4
        self.last_obs = None

    def reset(self):
        obs = self.venv.reset()
        self.obs_stats.update(self.features(obs))
        return obs

    def bonus(self, obs) -> np.ndarray:
        """The raw bonus of each observation of a batch (the predictor's squared error), after
        one training step of the predictor on the batch."""
        x = self.features(obs)
        self.obs_stats.update(x)
        z = self.obs_stats.normalize(x)
        with torch.no_grad():
            goal = self.target(z)
        err = (self.predictor(z) - goal).pow(2).mean(dim=1)
        self.optimizer.zero_grad()
        err.mean().backward()
        self.optimizer.step()
        return err.detach().numpy().astype(np.float64)

    def _scaled(self, raw: np.ndarray) -> np.ndarray:
        b = raw.shape[0]
        total = self.bonus_count + b
        delta_var = raw.var() if b > 1 else 0.0
        mean_sq = raw.mean() ** 2
        self.bonus_var = (self.bonus_var * self.bonus_count + (delta_var + mean_sq) * b) / total
        self.bonus_count = total
        return raw / np.sqrt(self.bonus_var + 1e-8)

    def step_wait(self):
        obs, rewards, dones, infos = self.venv.step_wait()
        scaled = self._scaled(self.bonus(obs))
        for info, r, bonus in zip(infos, rewards, scaled):
            info["extrinsic_reward"] = float(r)
            info["intrinsic_reward"] = float(bonus)
        total = (self.settings["extrinsic"] * np.asarray(rewards, dtype=np.float64)
                 + self.settings["coef"] * scaled)
        return obs, total.astype(np.float32), dones, infos
