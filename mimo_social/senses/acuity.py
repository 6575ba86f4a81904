"""Visual development: the grating acuity of an infant's eye by age, applied to its eye images
as a blur.

**Data** (``senses/data/acuity.csv``, sources in ``senses/data/README.md``): mean binocular
grating acuity of each age group measured with the Teller Acuity Cards (Salomao & Ventura 1995,
Table 1: 0.66 cycles per degree at half a month, 7.4 at 6 months, 12.4 at 18 months, 14.6 at 24
months; adults resolve 30 or more). :func:`acuity_at` interpolates the table linearly in octaves
(log2 of the acuity) between its ages and holds the first value before half a month. With
``VisionConfig(acuity="age")`` the blur is off from :data:`OFF_FROM_MONTHS` (24) months and for
adults, as the issue asks: the data at 24 months still say 14.6 cycles per degree, about one
octave short of an adult, so "off" there is a choice, not what the data say (give the number,
``acuity=14.64``, to keep the blur on).

**Filter law**: a Gaussian blur whose modulation transfer ``exp(-2 pi^2 sigma^2 f^2)`` is
:data:`CUTOFF_MODULATION` (10 %) at the cut-off frequency ``fc``: ``sigma = sqrt(ln(1 / 0.1) / 2)
/ (pi fc)`` (in pixels, ``fc`` in cycles per pixel). A grating at half the cut-off keeps 56 % of
its contrast, one at 1.5 times the cut-off 0.6 %. Cycles per degree become cycles per pixel
through the pixels per degree on the line of sight of a pinhole camera with vertical field of
view ``fovy`` (60 degrees, :data:`mimo_social.body.builder.EYE_FOVY_DEG`) and image height ``H``:
``ppd = (H / 2) / tan(fovy / 2) * pi / 180`` (1.93 per degree for H = 128, 3.87 for 256); pixels
are square, so the same sigma blurs rows and columns. Away from the centre a pixel covers less
angle (by ``cos^2`` of the angle off the axis: 0.75 at the top and bottom edge), so the blur is
slightly finer there in degrees. Where the cut-off is at or above the image's Nyquist frequency
(``ppd / 2``) the image cannot hold what the eye would lose, and the filter is the identity: the
newborn's 0.66 cycles per degree blurs images of 88 pixels and taller, 6 months' 7.4 only images
of 985 pixels and taller (:func:`blur_acts_from_height`).

**Cost**: per colour channel, two products of a band matrix (the Gaussian weights, cut at 4
sigma) with the channel in float32 (``rows @ channel @ columns^T``), uint8 out. The band
matrices are sparse (scipy CSR): their products run in one thread; dense products through a
multithreaded BLAS were as fast alone but fought the software renderer's threads for the cores
inside an env (12 times slower per step on a 2-core machine), and the cut keeps float32
denormals (20-30 times slower) out of the sums. Depth
images are not blurred: a depth image is the distance along each pixel's ray, not light on a
retina, and averaging distances across an occluding edge would make surfaces that are not there.
"""

from __future__ import annotations

import csv
import math
from functools import lru_cache
from importlib import resources
from numbers import Real

import numpy as np
from scipy import sparse

from ..body.builder import EYE_FOVY_DEG
from ..util.checks import ConfigError, show

__all__ = ["CUTOFF_MODULATION", "OFF_FROM_MONTHS", "ACUITY_RANGE", "acuity_table", "acuity_at",
           "pixels_per_degree", "nyquist_cpd", "blur_sigma_px", "blur_acts_from_height",
           "AcuityBlur", "acuity_blur", "check_acuity", "cutoff_for"]

#: the modulation transfer of the blur at the cut-off frequency
CUTOFF_MODULATION = 0.1
#: ``acuity="age"``: no blur from this age (months) on, nor for adults
OFF_FROM_MONTHS = 24.0
#: the cut-offs a number may give, in cycles per degree
ACUITY_RANGE = (0.1, 100.0)
_KERNEL_SIGMAS = 4.0     # Gaussian weights beyond this many sigma are zero


@lru_cache(maxsize=None)
def acuity_table(column: str = "binocular_cpd") -> tuple[tuple[float, float], ...]:
    """``((age_months, cycles_per_degree), ...)`` of one column of ``acuity.csv``
    (``binocular_cpd``, the one used, or ``monocular_cpd``), rows without a value left out."""
    with resources.files("mimo_social.senses").joinpath("data", "acuity.csv").open() as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    if not rows or column == "age_months" or column not in rows[0]:
        raise ValueError(f"acuity.csv has no column {column!r}")
    return tuple((float(r["age_months"]), float(r[column])) for r in rows if r[column].strip())


def acuity_at(age_months: float | None) -> float | None:
    """The eye's grating acuity (cycles per degree) at ``age_months`` for ``acuity="age"``:
    interpolated in octaves from :func:`acuity_table`; None (no blur) for an adult (None) and from
    :data:`OFF_FROM_MONTHS` on."""
    if age_months is None or age_months >= OFF_FROM_MONTHS:
        return None
    ages, cpd = np.array(acuity_table()).T
    return float(2.0 ** np.interp(float(age_months), ages, np.log2(cpd)))


def pixels_per_degree(height: int, fovy_deg: float = EYE_FOVY_DEG) -> float:
    """Pixels per degree on the line of sight of an image ``height`` pixels tall whose vertical
    field of view is ``fovy_deg`` (square pixels: the same across)."""
    return (height / 2.0) / math.tan(math.radians(fovy_deg) / 2.0) * math.pi / 180.0


def nyquist_cpd(height: int, fovy_deg: float = EYE_FOVY_DEG) -> float:
    """The finest grating the image holds on its line of sight, in cycles per degree."""
    return pixels_per_degree(height, fovy_deg) / 2.0


def blur_sigma_px(cutoff_cpd: float, height: int, fovy_deg: float = EYE_FOVY_DEG,
                  level: float = CUTOFF_MODULATION) -> float:
    """The Gaussian's standard deviation in pixels whose modulation transfer is ``level`` at
    ``cutoff_cpd``; 0.0 where the cut-off is at or above the image's Nyquist frequency."""
    fc = cutoff_cpd / pixels_per_degree(height, fovy_deg)        # cycles per pixel
    if fc >= 0.5:
        return 0.0
    return math.sqrt(math.log(1.0 / level) / 2.0) / (math.pi * fc)


def blur_acts_from_height(cutoff_cpd: float, fovy_deg: float = EYE_FOVY_DEG) -> int:
    """The smallest image height (pixels) at which a cut-off of ``cutoff_cpd`` blurs."""
    per_px = pixels_per_degree(1, fovy_deg)
    return int(math.floor(2.0 * cutoff_cpd / per_px)) + 1


def _blur_matrix(n: int, sigma: float) -> sparse.csr_matrix:
    """``(n, n)`` float32, sparse: row i holds the Gaussian weights of pixel i's neighbours,
    reflected at the image's edges (``..., 2, 1 | 0, 1, 2, ...``) and summing to 1."""
    radius = max(1, int(math.ceil(_KERNEL_SIGMAS * sigma)))
    offsets = np.arange(-radius, radius + 1)
    weights = np.exp(-0.5 * (offsets / sigma) ** 2)
    weights /= weights.sum()
    out = np.zeros((n, n))
    rows = np.arange(n)
    for off, w in zip(offsets, weights):
        cols = rows + off
        period = 2 * (n - 1) if n > 1 else 1
        cols = np.abs(cols) % period                # reflect about 0 and n - 1
        cols = np.where(cols > n - 1, period - cols, cols)
        np.add.at(out, (rows, cols), w)
    return sparse.csr_matrix(out.astype(np.float32))


class AcuityBlur:
    """The blur of one eye image size for one cut-off (see the module docstring for the law).

    Call it on a ``(height, width, 3)`` or ``(height, width)`` uint8 image: a new uint8 image,
    or the image itself when :attr:`identity` (cut-off at or above the Nyquist frequency)."""

    def __init__(self, cutoff_cpd: float, height: int, width: int,
                 fovy_deg: float = EYE_FOVY_DEG, level: float = CUTOFF_MODULATION):
        self.cutoff_cpd, self.height, self.width = float(cutoff_cpd), int(height), int(width)
        self.fovy_deg, self.level = float(fovy_deg), float(level)
        self.ppd = pixels_per_degree(self.height, self.fovy_deg)
        self.sigma_px = blur_sigma_px(self.cutoff_cpd, self.height, self.fovy_deg, self.level)
        self.identity = self.sigma_px == 0.0
        if not self.identity:
            self._rows = _blur_matrix(self.height, self.sigma_px)                 # (H, H)
            self._cols = _blur_matrix(self.width, self.sigma_px)                  # (W, W)

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """The filter as two dense float32 band matrices ``(rows (H, H), columns (W, W))``: the
        blurred channel is ``rows @ channel @ columns.T`` (e.g. for a blur on another device);
        identity matrices for the identity."""
        if self.identity:
            return (np.eye(self.height, dtype=np.float32), np.eye(self.width, dtype=np.float32))
        return self._rows.toarray(), self._cols.toarray()

    def modulation(self, cpd: float) -> float:
        """The filter's modulation transfer at ``cpd`` cycles per degree on the line of sight
        (the continuous Gaussian's; 1.0 for the identity)."""
        if self.identity:
            return 1.0
        f = cpd / self.ppd
        return math.exp(-2.0 * math.pi ** 2 * self.sigma_px ** 2 * f ** 2)

    def __call__(self, image: np.ndarray) -> np.ndarray:
        if self.identity:
            return image
        h, w = self.height, self.width
        if image.shape[:2] != (h, w) or image.ndim not in (2, 3):
            raise ValueError(f"acuity blur for {h}x{w} images got shape {image.shape}")
        planes = image[..., None] if image.ndim == 2 else image
        out = np.empty(planes.shape, np.uint8)
        for k in range(planes.shape[2]):        # channel by channel: each product cache-sized
            x = planes[:, :, k].astype(np.float32)
            y = self._rows @ x                           # blur along each column
            z = (self._cols @ y.T).T                     # then along each row
            z += np.float32(0.5)                         # round (weights >= 0, sum 1)
            out[:, :, k] = z
        return out.reshape(image.shape)


def acuity_blur(cutoff_cpd: float | None, height: int, width: int,
                fovy_deg: float = EYE_FOVY_DEG) -> AcuityBlur | None:
    """The :class:`AcuityBlur` of a cut-off (None: no blur) for ``height`` x ``width`` eye
    images; None where it would do nothing (no cut-off, or one at or above Nyquist)."""
    if cutoff_cpd is None:
        return None
    blur = AcuityBlur(cutoff_cpd, height, width, fovy_deg)
    return None if blur.identity else blur


def check_acuity(value, owner: str = "vision"):
    """A :class:`VisionConfig` ``acuity`` value: None, ``"age"`` or a number of cycles per
    degree in :data:`ACUITY_RANGE` (as a float); else a ConfigError naming field and value."""
    if value is None or (isinstance(value, str) and value == "age"):
        return value
    lo, hi = ACUITY_RANGE
    if isinstance(value, Real) and not isinstance(value, (bool, np.bool_)) \
            and math.isfinite(value) and lo <= value <= hi:
        return float(value)
    raise ConfigError(f"{owner}: acuity={show(value)} not allowed; allowed: None (off), 'age' "
                      f"(from the agent's age) or a cut-off in cycles per degree from {lo:g} "
                      f"to {hi:g}")


def cutoff_for(acuity, age: float | None) -> float | None:
    """The cut-off (cycles per degree) a checked ``acuity`` setting gives an agent of ``age``
    months (:attr:`AgentConfig.age`: None for an adult); None: no blur."""
    if acuity is None:
        return None
    if acuity == "age":
        return acuity_at(age)
    return float(acuity)
