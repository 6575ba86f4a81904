"""Textures of the play room, drawn in code with numpy (no image files).

Each function returns an ``(height, width, 3)`` uint8 RGB array, the same every call (a fixed
seed; cached), and :func:`add_texture` hands one to an ``MjSpec`` as texture data with a
material around it. The textures are small (at most 256 x 256) and repeated over the surfaces
(``texuniform``: so many repeats per metre), which keeps the model light for the eyes' renderer.
"""

from __future__ import annotations

from functools import lru_cache

import mujoco
import numpy as np

__all__ = ["wood_boards", "foam_mat", "wallpaper", "wood_grain", "fabric", "add_texture",
           "TEXTURES"]


def _rgb(img: np.ndarray) -> np.ndarray:
    return np.clip(np.rint(img * 255.0), 0, 255).astype(np.uint8)


def _smooth_noise(rng, h: int, w: int, cells: tuple[int, int]) -> np.ndarray:
    """Value noise in [0, 1], tiling (the texture repeats without a seam): a coarse random
    grid, bilinearly interpolated with wrap-around."""
    gy, gx = cells
    grid = rng.random((gy, gx))
    y = np.arange(h) * gy / h
    x = np.arange(w) * gx / w
    y0, x0 = np.floor(y).astype(int), np.floor(x).astype(int)
    fy, fx = (y - y0)[:, None], (x - x0)[None, :]
    fy, fx = fy * fy * (3 - 2 * fy), fx * fx * (3 - 2 * fx)      # smoothstep
    y1, x1 = (y0 + 1) % gy, (x0 + 1) % gx
    a = grid[y0][:, x0] * (1 - fx) + grid[y0][:, x1] * fx
    b = grid[y1][:, x0] * (1 - fx) + grid[y1][:, x1] * fx
    return a * (1 - fy) + b * fy


@lru_cache(maxsize=None)
def wood_boards(size: int = 256, boards: int = 4) -> np.ndarray:
    """Oak floor boards along x: each board its own tone, a grain of fine streaks, dark seams
    between boards and staggered end joints."""
    rng = np.random.default_rng(11)
    h = w = size
    y = np.arange(h)[:, None] * np.ones((1, w))
    x = np.ones((h, 1)) * np.arange(w)[None, :]
    board_h = h // boards
    k = (y // board_h).astype(int)
    tone = 0.9 + 0.2 * rng.random(boards)[k]
    streak = _smooth_noise(rng, h, w, (48, 4))              # long streaks along the board
    grain = 0.5 + 0.5 * np.sin(2 * np.pi * (y / 7.0 + 3.0 * streak))
    base = np.array([0.78, 0.60, 0.40])
    img = base * (tone * (0.86 + 0.14 * grain))[..., None]
    seam = (y % board_h) < 2
    offsets = (rng.random(boards) * w).astype(int)
    joint = np.abs(((x - offsets[k]) % w)) < 2
    img[seam | joint] *= 0.55
    return _rgb(img)


@lru_cache(maxsize=None)
def foam_mat(size: int = 256) -> np.ndarray:
    """A foam play mat of four interlocking pastel tiles (2 x 2 per texture repeat), each
    with a fine pebbled surface and a lighter rim along its puzzle edge."""
    rng = np.random.default_rng(12)
    colours = np.array([[0.55, 0.78, 0.90], [0.98, 0.84, 0.52],
                        [0.67, 0.86, 0.62], [0.96, 0.66, 0.64]])
    h = w = size
    half = size // 2
    y = np.arange(h)[:, None] * np.ones((1, w))
    x = np.ones((h, 1)) * np.arange(w)[None, :]
    tile = (y >= half).astype(int) * 2 + (x >= half).astype(int)
    img = colours[tile]
    # puzzle edge: a sine-wave boundary line, drawn lighter
    u, v = x % half, y % half
    tooth = 4.0 * np.sin(2 * np.pi * np.where(u < v, v, u) / (half / 3))
    edge = (np.minimum(u, v) + tooth < 3) | (np.minimum(half - u, half - v) - tooth < 2)
    img[edge] = img[edge] * 0.6 + 0.4
    pebble = rng.random((h, w))
    img *= (0.94 + 0.06 * pebble)[..., None]
    return _rgb(img)


@lru_cache(maxsize=None)
def wallpaper(size: int = 128) -> np.ndarray:
    """A cream wallpaper with soft vertical stripes and small dots between them."""
    h = w = size
    y = np.arange(h)[:, None] * np.ones((1, w))
    x = np.ones((h, 1)) * np.arange(w)[None, :]
    img = np.ones((h, w, 3)) * np.array([0.97, 0.93, 0.84])
    stripe = ((x % (w // 2)) < w // 8)
    img[stripe] = np.array([0.90, 0.88, 0.96])
    cx, cy = (x % (w // 2)) - w * 5 / 16, (y % (h // 4)) - h / 8
    dot = cx * cx + cy * cy < (size / 40) ** 2
    img[dot] = np.array([0.96, 0.74, 0.60])
    return _rgb(img)


@lru_cache(maxsize=None)
def wood_grain(size: int = 128, base: tuple = (0.86, 0.72, 0.52)) -> np.ndarray:
    """Light birch for furniture: growth rings bent by noise."""
    rng = np.random.default_rng(13)
    h = w = size
    n = _smooth_noise(rng, h, w, (6, 3))
    y = np.arange(h)[:, None] * np.ones((1, w))
    rings = 0.5 + 0.5 * np.sin(2 * np.pi * (y / 9.0 + 4.0 * n))
    img = np.array(base) * (0.88 + 0.12 * rings)[..., None]
    return _rgb(img)


@lru_cache(maxsize=None)
def fabric(size: int = 64, base: tuple = (0.42, 0.55, 0.70)) -> np.ndarray:
    """A woven upholstery fabric: warp and weft threads crossing, a little random shading."""
    rng = np.random.default_rng(14)
    h = w = size
    y = np.arange(h)[:, None] * np.ones((1, w))
    x = np.ones((h, 1)) * np.arange(w)[None, :]
    weave = ((x // 2 + y // 2) % 2) * 0.08 + 0.04 * np.sin(np.pi * x / 2) ** 2
    img = np.array(base) * (0.9 + weave + 0.05 * rng.random((h, w)))[..., None]
    return _rgb(img)


#: name -> the function that draws it (and its arguments)
TEXTURES = {
    "wood_boards": lambda: wood_boards(),
    "foam_mat": lambda: foam_mat(),
    "wallpaper": lambda: wallpaper(),
    "wood_light": lambda: wood_grain(),
    "wood_white": lambda: wood_grain(base=(0.95, 0.93, 0.89)),
    "wood_red": lambda: wood_grain(base=(0.80, 0.36, 0.30)),
    "fabric_blue": lambda: fabric(),
    "fabric_sage": lambda: fabric(base=(0.60, 0.70, 0.55)),
}


def add_texture(spec: mujoco.MjSpec, name: str, prefix: str = "playroom/",
                repeat: tuple[float, float] = (1.0, 1.0), rgba=(1.0, 1.0, 1.0, 1.0),
                specular: float = 0.1, shininess: float = 0.1) -> str:
    """Put texture ``name`` of :data:`TEXTURES` in ``spec`` with a material of the same name
    (``repeat``: repeats per metre, ``texuniform``); returns the material's name."""
    img = TEXTURES[name]()
    h, w, _ = img.shape
    full = prefix + name
    tex = spec.add_texture(name=full, type=mujoco.mjtTexture.mjTEXTURE_2D, width=w, height=h,
                           nchannel=3)
    tex.data = np.ascontiguousarray(img[::-1]).tobytes()   # MuJoCo's rows run bottom-up
    mat = spec.add_material(name=full, texrepeat=list(repeat), texuniform=True, rgba=list(rgba),
                            specular=specular, shininess=shininess, reflectance=0.0)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = full
    return full
