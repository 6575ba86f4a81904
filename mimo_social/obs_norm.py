"""Kept so that SB3 models saved before the package was laid out in layers still load: their
``model.zip`` names ``mimo_social.obs_norm.RunningNorm``. The class lives in
:mod:`mimo_social.train.obs_norm`."""

from .train.obs_norm import RunningNorm

__all__ = ["RunningNorm"]
