"""Foveated vision: each eye image resampled so that its centre is magnified and its periphery
compressed, the whole field of view still in the image (``VisionConfig(fovea=...)``).

**The warp.** Each output pixel looks along its ray from the image centre: an output point at
normalised position ``p = (u, v)`` (``-1 .. 1`` across the image, ``0`` at the centre) shows the
source point ``p * f(rho) / rho``, where ``rho = max(|u|, |v|)`` is its distance from the centre
relative to the image's border along that ray. The radial profile

    ``f(rho) = (exp(a rho) - 1) / (exp(a) - 1)``,  inverse: ``rho = ln(1 + f (exp(a) - 1)) / a``

is the logarithmic map of eccentricity of a log-polar retina with a fovea (output radius
growing as ``ln(1 + E / E0)`` of the source eccentricity ``E``). ``f(0) = 0`` and ``f(1) = 1``:
the centre stays the centre and the border stays the border (each ray is warped over its whole
length, so the corners and the edges are kept, nothing of the field of view is lost). Its slope
at the centre is ``a / (exp(a) - 1) = 1 / strength``: the **strength** is the magnification at
the centre, output pixels per degree there over those of the plain image of the same size
(:func:`profile_exponent` solves for ``a``; strength 1 is the identity). At the border the slope
is ``a exp(a) / (exp(a) - 1)``: 2.6 plain pixels per output pixel at strength 4.

**Real detail at the centre.** The eye is rendered ``render_scale`` times larger than the output
(default: the strength rounded up), so the magnified centre is made of rendered detail, not
interpolated pixels, up to a strength of ``render_scale``.

**The resampling** is precomputed once per image size: each output pixel averages
``s x s`` sub-samples spread evenly over its own area (``s = render_scale``), each sub-sample a
bilinear interpolation of the four render pixels around its source point. The weights of all of
them form one sparse matrix (rows: output pixels, columns: render pixels; equal taps merged), so
a colour image is one sparse product, all channels at once (:class:`FovealWarp`). Averaging
over the pixel's area keeps the compressed periphery from aliasing (a point sample there would skip
render pixels). Depth images use the same warp but take the one render pixel nearest each
output pixel's centre: averaging distances across an occluding edge would make surfaces that
are not there (as the acuity blur leaves depth sharp, :mod:`mimo_social.senses.acuity`).

**With the acuity blur** (``acuity``) the blur is applied first, at the render resolution and
in degrees (its sigma in render pixels), then the warp: the eye's optics blur the image before
the retina samples it unevenly. Blurring after the warp would blur the magnified centre less,
in degrees, than the periphery and so give the centre a better acuity than the one asked for.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from numbers import Real
from typing import Mapping

import numpy as np
from scipy import sparse

from ..util.checks import ConfigError, show

__all__ = ["STRENGTH_RANGE", "RENDER_SCALE_RANGE", "DEFAULT_STRENGTH", "MAX_RENDER_SIDE",
           "FoveaConfig", "check_fovea", "profile_exponent", "radial_profile",
           "source_points", "FovealWarp", "foveal_warp"]

#: the strengths (magnification at the centre) allowed
STRENGTH_RANGE = (1.0, 16.0)
#: the render scales allowed (the eye rendered this many times the output size, per side)
RENDER_SCALE_RANGE = (1, 8)
#: the strength of ``fovea=True``
DEFAULT_STRENGTH = 4.0
#: the largest rendered side (pixels) a fovea may ask for
MAX_RENDER_SIDE = 4096

_ALLOWED = (f"None (off), True (strength {DEFAULT_STRENGTH:g}), a strength (the magnification "
            f"at the centre) from {STRENGTH_RANGE[0]:g} to {STRENGTH_RANGE[1]:g}, or a mapping "
            "{'strength': ..., 'render_scale': ...} (render_scale: an integer from "
            f"{RENDER_SCALE_RANGE[0]} to {RENDER_SCALE_RANGE[1]}, default: the strength rounded "
            "up)")


@dataclass(frozen=True)
class FoveaConfig:
    """A checked fovea setting: ``strength`` (magnification at the centre) and
    ``render_scale`` (the eye is rendered this many times the output size)."""

    strength: float
    render_scale: int


def _strength(value, owner: str) -> float:
    lo, hi = STRENGTH_RANGE
    if isinstance(value, Real) and not isinstance(value, (bool, np.bool_)) \
            and math.isfinite(value) and lo <= value <= hi:
        return float(value)
    raise ConfigError(f"{owner}: fovea strength={show(value)} not allowed; allowed: {_ALLOWED}")


def check_fovea(value, width: int, height: int, owner: str = "vision") -> FoveaConfig | None:
    """A :class:`VisionConfig` ``fovea`` value as a :class:`FoveaConfig` (None: off), for eyes
    of ``width`` x ``height`` output pixels; else a ConfigError naming the field, the value
    and what is allowed."""
    if isinstance(value, FoveaConfig):        # checked again (e.g. after replace())
        value = {"strength": value.strength, "render_scale": value.render_scale}
    if value is None or value is False:
        config = None
    elif value is True:
        config = FoveaConfig(DEFAULT_STRENGTH, math.ceil(DEFAULT_STRENGTH))
    elif isinstance(value, Mapping):
        unknown = sorted(set(value) - {"strength", "render_scale"}, key=str)
        if unknown:
            raise ConfigError(f"{owner}: fovea has unknown setting(s) {unknown}; allowed: "
                              f"{_ALLOWED}")
        if "strength" not in value:
            raise ConfigError(f"{owner}: fovea={show(value)} has no 'strength'; allowed: "
                              f"{_ALLOWED}")
        strength = _strength(value["strength"], owner)
        scale = value.get("render_scale")
        if scale is None:
            scale = math.ceil(strength)
        lo, hi = RENDER_SCALE_RANGE
        if isinstance(scale, (bool, np.bool_)) or not isinstance(scale, (int, np.integer)) \
                or not lo <= scale <= hi:
            raise ConfigError(f"{owner}: fovea render_scale={show(scale)} not allowed; "
                              f"allowed: an integer from {lo} to {hi} (or None: the strength "
                              "rounded up)")
        config = FoveaConfig(strength, int(scale))
    elif isinstance(value, Real) and not isinstance(value, np.bool_):
        strength = _strength(value, owner)
        config = FoveaConfig(strength, math.ceil(strength))
    else:
        raise ConfigError(f"{owner}: fovea={show(value)} not allowed; allowed: {_ALLOWED}")
    if config is not None and max(width, height) * config.render_scale > MAX_RENDER_SIDE:
        raise ConfigError(f"{owner}: fovea render_scale={config.render_scale} renders "
                          f"{width * config.render_scale}x{height * config.render_scale} "
                          f"pixels; allowed: at most {MAX_RENDER_SIDE} per side (a smaller "
                          "render_scale or smaller eyes)")
    return config


def profile_exponent(strength: float) -> float:
    """The ``a`` of the radial profile whose magnification at the centre, ``(exp(a) - 1) / a``,
    is ``strength`` (0.0 for strength 1: the identity)."""
    strength = float(strength)
    if strength <= 1.0:
        return 0.0
    lo, hi = 1e-12, 1.0
    while math.expm1(hi) / hi < strength:
        hi *= 2.0
    for _ in range(200):                     # bisection: the magnification grows with a
        mid = 0.5 * (lo + hi)
        if math.expm1(mid) / mid < strength:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def radial_profile(rho: np.ndarray, strength: float) -> np.ndarray:
    """``f(rho)``: the source radius shown at output radius ``rho`` (both 0 .. 1, relative to
    the border along the ray)."""
    a = profile_exponent(strength)
    rho = np.asarray(rho, float)
    if a == 0.0:
        return rho.copy()
    return np.expm1(a * rho) / math.expm1(a)


def source_points(x: np.ndarray, y: np.ndarray, width: int, height: int,
                  strength: float) -> tuple[np.ndarray, np.ndarray]:
    """The source points (in the same pixel units: ``0 .. width``, ``0 .. height``, pixel ``i``
    spanning ``i .. i + 1``) shown at output points ``(x, y)`` of a ``width`` x ``height``
    image."""
    u = (np.asarray(x, float) - width / 2.0) / (width / 2.0)
    v = (np.asarray(y, float) - height / 2.0) / (height / 2.0)
    rho = np.maximum(np.abs(u), np.abs(v))
    safe = np.where(rho > 0.0, rho, 1.0)
    a = profile_exponent(strength)
    gain = np.where(rho > 0.0, radial_profile(rho, strength) / safe,
                    a / math.expm1(a) if a else 1.0)
    return width / 2.0 * (1.0 + u * gain), height / 2.0 * (1.0 + v * gain)


class FovealWarp:
    """The warp of one output size (``height`` x ``width``) for one :class:`FoveaConfig`: call
    :meth:`rgb` on a rendered ``(height * k, width * k, 3)`` uint8 image and :meth:`depth` on a
    rendered ``(height * k, width * k)`` float32 depth image (``k``: the render scale)."""

    def __init__(self, config: FoveaConfig, height: int, width: int):
        self.config, self.height, self.width = config, int(height), int(width)
        k = self.scale = config.render_scale
        self.render_height, self.render_width = self.height * k, self.width * k
        h, w, rh, rw = self.height, self.width, self.render_height, self.render_width
        # sub-samples: s x s per output pixel, at the centres of an even s x s split of it
        s = k
        sub = (np.arange(s) + 0.5) / s
        ys = (np.arange(h)[:, None] + sub[None, :]).reshape(h, 1, s, 1)
        xs = (np.arange(w)[:, None] + sub[None, :]).reshape(1, w, 1, s)
        ys, xs = np.broadcast_to(ys, (h, w, s, s)), np.broadcast_to(xs, (h, w, s, s))
        sx, sy = source_points(xs, ys, w, h, config.strength)
        # bilinear taps in render pixels (pixel centres at i + 0.5), clamped at the border
        fx, fy = sx * k - 0.5, sy * k - 0.5
        x0, y0 = np.floor(fx), np.floor(fy)
        tx, ty = fx - x0, fy - y0
        x0, y0 = x0.astype(np.int64), y0.astype(np.int64)
        cols, weights = [], []
        for dy, wy in ((0, 1.0 - ty), (1, ty)):
            for dx, wx in ((0, 1.0 - tx), (1, tx)):
                cx = np.clip(x0 + dx, 0, rw - 1)
                cy = np.clip(y0 + dy, 0, rh - 1)
                cols.append((cy * rw + cx).reshape(h * w, -1))
                weights.append((wy * wx).reshape(h * w, -1))
        cols = np.concatenate(cols, axis=1).ravel()
        weights = np.concatenate(weights, axis=1).ravel() / (s * s)
        rows = np.repeat(np.arange(h * w), 4 * s * s)
        keep = weights > 0.0
        matrix = sparse.coo_matrix((weights[keep], (rows[keep], cols[keep])),
                                   shape=(h * w, rh * rw)).tocsr()
        matrix.sum_duplicates()
        self._matrix = matrix.astype(np.float32)
        # depth: the render pixel nearest each output pixel's centre
        cx, cy = source_points(np.arange(w)[None, :] + 0.5, np.arange(h)[:, None] + 0.5,
                               w, h, config.strength)
        px = np.clip(np.floor(cx * k), 0, rw - 1).astype(np.int64)
        py = np.clip(np.floor(cy * k), 0, rh - 1).astype(np.int64)
        #: ``(height, width)`` flat index into the render image of each output pixel's centre
        self.nearest = py * rw + px

    def __reduce__(self):
        # pickled as its recipe (the matrix is megabytes; rebuilt, or shared, on arrival)
        return foveal_warp, (self.config, self.height, self.width)

    @property
    def matrix(self) -> sparse.csr_matrix:
        """The warp's weights, float32 ``(height * width, render pixels)``: the warped channels
        are ``matrix @ render.reshape(-1, channels)`` (read only)."""
        return self._matrix

    @property
    def taps(self) -> int:
        """Render pixels read for one colour channel (non-zero weights of the matrix)."""
        return int(self._matrix.nnz)

    def rgb(self, image: np.ndarray) -> np.ndarray:
        """The warped ``(height, width, 3)`` uint8 image of a rendered one."""
        rh, rw = self.render_height, self.render_width
        if image.shape != (rh, rw, 3):
            raise ValueError(f"fovea warp for {rh}x{rw} renders got shape {image.shape}")
        flat = image.reshape(rh * rw, 3).astype(np.float32)
        out = self._matrix @ flat
        out += np.float32(0.5)                   # round (weights >= 0, summing to 1)
        np.clip(out, 0.0, 255.0, out=out)
        return out.astype(np.uint8).reshape(self.height, self.width, 3)

    def depth(self, image: np.ndarray) -> np.ndarray:
        """The warped ``(height, width)`` float32 depth image of a rendered one (nearest)."""
        rh, rw = self.render_height, self.render_width
        if image.shape != (rh, rw):
            raise ValueError(f"fovea warp for {rh}x{rw} depth renders got shape {image.shape}")
        return image.reshape(-1)[self.nearest]

    def pixels_within(self, fraction: float) -> int:
        """How many output pixels show the central square of the field of view whose half side
        is ``fraction`` (0 .. 1) of the image's half side (a measure of central pixel density:
        ``(fraction * side) ** 2`` without a fovea, more with one)."""
        cx, cy = source_points(np.arange(self.width)[None, :] + 0.5,
                               np.arange(self.height)[:, None] + 0.5, self.width, self.height,
                               self.config.strength)
        u = np.abs(cx - self.width / 2.0) / (self.width / 2.0)
        v = np.abs(cy - self.height / 2.0) / (self.height / 2.0)
        return int(np.count_nonzero(np.maximum(u, v) <= float(fraction)))


@lru_cache(maxsize=32)
def foveal_warp(config: FoveaConfig, height: int, width: int) -> FovealWarp:
    """The :class:`FovealWarp` of one setting and output size, made once per process and
    shared (agents with the same eyes, unpickled envs): it is only read."""
    return FovealWarp(config, int(height), int(width))
