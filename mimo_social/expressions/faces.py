"""Cartoon infant face textures, drawn in code with numpy only.

Each face is built on a coordinate grid with implicit shapes (ellipses, thick
curves given as ``y = f(x)`` with round caps, regions between two curves) and
painted layer by layer onto a plain skin background. Image row 0 is the top of
the face (forehead) and column 0 shows the face's own right side, as in a photo.
All features stay inside the central ~70 % of the square, so the border is
plain skin colour and the image can be wrapped onto the front of a sphere head.

The seven expressions follow Ekman's basic emotions plus neutral; their index in
:data:`EXPRESSIONS` is the expression id used by the environments.

On a head the eyes are the body's own eyeballs (white sclera, iris and pupil that turn with the
eye joints; :mod:`mimo_social.body.builder`), which bulge out of the head over the eyes painted
here: what others see of an expression is its brows, mouth, cheeks and marks (tears, wrinkles,
frown lines) and the lash lines drawn around each eyeball. The painted eyes (wide for surprise
and fear, lidded for sadness, anger and disgust) show in the flat face images (recordings).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

EXPRESSIONS: tuple[str, ...] = ("neutral", "happy", "sad", "surprised", "disgusted", "angry", "scared")
SKIN_RGB: tuple[int, int, int] = (240, 200, 170)
MIN_SIZE, MAX_SIZE = 16, 2048

_COLORS = {
    "line": (95, 55, 45), "brow": (150, 100, 70), "sclera": (255, 255, 255),
    "iris": (110, 75, 45), "pupil": (30, 20, 20), "mouth": (150, 45, 60),
    "tongue": (235, 115, 125), "teeth": (255, 252, 245), "lip": (185, 85, 85),
    "nose": (222, 168, 140), "blush": (248, 150, 145), "tear": (150, 205, 255),
}

# Per expression. brow: (inner y, outer y, arch, inner x).
# eye: (half width, half height, top lid (y at inner, y at outer) relative to the
#       eye centre or None, bottom lid (y offset, upward bulge) or None, iris radius, gaze dy).
# mouth: ("line", half width, centre y, corner lift, half thickness) or
#        ("open", half width, centre y, (upper lift left, right), depth, power p,
#         exponent q, extra) with the opening between cy + up*g and cy - depth*g,
#         g = (1 - |x/w|^p)^q, extra in {"", "tongue", "teeth"}.
# cheek: (blush centre y, blush half height, opacity); marks: extra details among
#        "tears", "nose_wrinkles" (also lifts the nose), "frown_lines".
_CHEEK = (-0.23, 0.08, 0.5)
_SPECS = {
    "neutral": dict(brow=(0.29, 0.28, 0.03, 0.13), eye=(0.13, 0.12, None, None, 0.085, 0.0),
                    mouth=("line", 0.10, -0.40, 0.02, 0.018), cheek=_CHEEK, marks=()),
    "happy": dict(brow=(0.33, 0.32, 0.05, 0.13), eye=(0.13, 0.12, None, (-0.035, 2.5), 0.085, 0.01),
                  mouth=("open", 0.23, -0.34, (-0.05, -0.05), 0.22, 2.0, 1.0, "tongue"),
                  cheek=(-0.17, 0.10, 0.85), marks=()),
    "sad": dict(brow=(0.41, 0.22, -0.01, 0.13), eye=(0.13, 0.12, (0.08, 0.0), None, 0.085, -0.03),
                mouth=("line", 0.15, -0.44, -0.13, 0.026), cheek=_CHEEK, marks=("tears",)),
    "surprised": dict(brow=(0.42, 0.41, 0.07, 0.13), eye=(0.14, 0.16, None, None, 0.07, 0.0),
                      mouth=("open", 0.10, -0.43, (0.12, 0.12), 0.12, 2.0, 0.5, ""), cheek=_CHEEK, marks=()),
    "disgusted": dict(brow=(0.19, 0.25, 0.0, 0.12), eye=(0.13, 0.12, (0.03, 0.05), (-0.06, 0.8), 0.08, 0.0),
                      mouth=("open", 0.17, -0.43, (0.02, 0.12), 0.05, 2.0, 0.7, "teeth"),
                      cheek=_CHEEK, marks=("nose_wrinkles",)),
    "angry": dict(brow=(0.13, 0.33, -0.01, 0.11), eye=(0.13, 0.12, (-0.01, 0.08), None, 0.085, 0.0),
                  mouth=("line", 0.14, -0.43, -0.05, 0.036), cheek=_CHEEK, marks=("frown_lines",)),
    "scared": dict(brow=(0.41, 0.31, 0.0, 0.08), eye=(0.14, 0.16, None, None, 0.065, 0.0),
                   mouth=("open", 0.22, -0.43, (0.05, 0.05), 0.08, 4.0, 0.5, "teeth"),
                   cheek=_CHEEK, marks=()),
}
_EYE_X, _EYE_Y, _BROW_OUTER_X = 0.31, 0.05, 0.47
_LASH_RADIUS = 0.145  # just outside an eyeball's outline on a head (drawing units)
_FEATURE_EXTENT = 0.7  # features lie within |x|, |y| < 0.6; outside the central 70 % is plain skin
# The drawing's own coordinates are scaled and shifted onto the image so that its eyes land at
# (+-0.377, 0.137): where the head's eye spheres sit when the image is projected onto the head
# sphere (direction (1, u, v) from the head centre meets the cube's front side at (u, v)).
_DRAW_SCALE, _DRAW_SHIFT_Y = 0.822, -0.0626


def _check_size(size: int) -> int:
    """Validate the texture edge length in pixels."""
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)):
        raise TypeError(f"size must be an int in [{MIN_SIZE}, {MAX_SIZE}], got {size!r}")
    if not MIN_SIZE <= size <= MAX_SIZE:
        raise ValueError(f"size must be in [{MIN_SIZE}, {MAX_SIZE}] pixels, got {size}")
    return int(size)


def _expression_id(expression: str | int) -> int:
    """Map an expression name or id to its id, with errors that list the allowed values."""
    allowed = f"allowed names {list(EXPRESSIONS)} or ids 0..{len(EXPRESSIONS) - 1}"
    if isinstance(expression, str):
        if expression in EXPRESSIONS:
            return EXPRESSIONS.index(expression)
        raise ValueError(f"unknown expression {expression!r}; {allowed}")
    if isinstance(expression, (int, np.integer)) and not isinstance(expression, bool):
        if 0 <= expression < len(EXPRESSIONS):
            return int(expression)
        raise ValueError(f"expression id {expression} out of range; {allowed}")
    raise TypeError(f"expression must be a str or int, got {type(expression).__name__}; {allowed}")


def _ellipse_sdf(x, y, cx, cy, a, b):
    """Approximate signed distance to an axis-aligned ellipse (negative inside)."""
    u, v = (x - cx) / a, (y - cy) / b
    r = np.sqrt(u * u + v * v) + 1e-9
    grad = np.sqrt((u / a) ** 2 + (v / b) ** 2) / r + 1e-9
    return (r - 1.0) / grad


def _stroke(x, y, x0, x1, f, df, half_width):
    """Mask of a thick curve ``y = f(x)`` for x in [x0, x1] with round caps.

    Inside the range the distance is the first-order distance to the graph;
    beyond the ends it is the distance to the end points. ``half_width`` is a
    number or a function of the clipped x.
    """
    xc = np.clip(x, x0, x1)
    fy = f(xc)
    d_in = np.abs(y - fy) / np.sqrt(1.0 + df(xc) ** 2)
    d_end = np.hypot(x - xc, y - fy)
    hw = half_width(xc) if callable(half_width) else half_width
    return np.where(x == xc, d_in, d_end) < hw


def _draw_eyes(paint, X, y, spec):
    """Both eyes (mirrored through ``X = |x|``): outline, sclera, iris, pupil, highlight."""
    a, b, top, bottom, r_iris, gaze = spec
    ex, ey = _EYE_X, _EYE_Y
    f = _ellipse_sdf(X, y, ex, ey, a, b)
    if top is not None:  # upper lid: straight line from inner (ex - a) to outer (ex + a) corner
        slope = (top[1] - top[0]) / (2 * a)
        line_y = ey + top[0] + slope * (X - (ex - a))
        f = np.maximum(f, (y - line_y) / np.hypot(1.0, slope))
    if bottom is not None:  # lower lid pushed up in the middle (raised cheek or squint)
        off, bulge = bottom
        f = np.maximum(f, ey + off - bulge * (X - ex) ** 2 - y)
    eye = f < 0
    paint((f < 0.016) & ~eye, "line")
    paint(eye, "sclera")
    ix, iy = ex, ey + gaze
    d_iris = np.hypot(X - ix, y - iy)
    paint(eye & (d_iris < r_iris), "iris")
    paint(eye & (d_iris < 0.55 * r_iris), "pupil")
    paint(eye & (np.hypot(X - (ix - 0.3 * r_iris), y - (iy + 0.35 * r_iris)) < 0.28 * r_iris), "sclera")


def _draw_lash_lines(paint, X, y):
    """A dark line around each eyeball where it meets the skin, thicker above (the lashes). The
    eyeballs (:mod:`mimo_social.body.builder`) bulge out of the head over the painted eyes,
    ``_LASH_RADIUS`` around their centres on this image; the line frames them."""
    dx, dy = X - _EYE_X, y - _EYE_Y
    d = np.hypot(dx, dy)
    up = np.clip(dy / (d + 1e-9), 0.0, 1.0)          # 1 straight above the eye, 0 below its middle
    paint((d >= _LASH_RADIUS) & (d < _LASH_RADIUS + 0.012 + 0.022 * up), "line")


def _draw_brows(paint, X, y, spec):
    """Both brows as tapered strokes, thick at the inner end."""
    yi, yo, arch, x0 = spec
    x1 = _BROW_OUTER_X
    span = x1 - x0

    def f(t):
        s = (t - x0) / span
        return yi + (yo - yi) * s + 4.0 * arch * s * (1.0 - s)

    def df(t):
        s = (t - x0) / span
        return ((yo - yi) + 4.0 * arch * (1.0 - 2.0 * s)) / span

    paint(_stroke(X, y, x0, x1, f, df, lambda t: 0.026 - 0.012 * (t - x0) / span), "brow")


def _draw_mouth(paint, x, y, spec):
    """A closed mouth (a thick curve) or an open one (a region between two curves, with lip rim)."""
    if spec[0] == "line":
        _, w, cy, lift, hw = spec
        paint(_stroke(x, y, -w, w, lambda t: cy + lift * (t / w) ** 2, lambda t: 2 * lift * t / w**2, hw), "lip")
        return
    _, w, cy, (up_l, up_r), depth, p, q, extra = spec

    def region(w, lift, depth):
        g = np.clip(1.0 - np.abs(x / w) ** p, 0.0, 1.0) ** q
        up = lift[0] + (lift[1] - lift[0]) * np.clip((x / w + 1.0) / 2.0, 0.0, 1.0)
        return cy + up * g, cy - depth * g, (np.abs(x) < w) & (y < cy + up * g) & (y > cy - depth * g)

    t = 0.02  # lip outline thickness: the same shape grown by t
    upper, _, inside = region(w, (up_l, up_r), depth)
    paint(region(w + t, (up_l + t, up_r + t), depth + t)[2] & ~inside, "lip")
    paint(inside, "mouth")
    if extra == "tongue":
        paint(inside & (_ellipse_sdf(x, y, 0.0, cy - depth + 0.02, 0.6 * w, 0.45 * depth) < 0), "tongue")
    elif extra == "teeth":
        paint(inside & (y > upper - 0.03), "teeth")


def _render(index: int, size: int) -> np.ndarray:
    """Draw expression ``index`` on a size x size grid; returns uint8 RGB."""
    spec = _SPECS[EXPRESSIONS[index]]
    out = np.empty((size, size, 3), dtype=np.uint8)
    out[:] = SKIN_RGB
    lo = int(size * (1.0 - _FEATURE_EXTENT) / 2.0)  # features live in [lo, size - lo)
    coords = ((np.arange(lo, size - lo) + 0.5) / size * 2.0 - 1.0).astype(np.float32)
    x = _DRAW_SCALE * coords[None, :]  # viewer's left -> right (face's right -> left)
    y = -_DRAW_SCALE * coords[:, None] + _DRAW_SHIFT_Y  # top rows have the largest y
    x, y = np.broadcast_arrays(x, y)
    X = np.abs(x)  # mirrored coordinate for the symmetric features
    img = np.empty(x.shape + (3,), dtype=np.float32)
    img[:] = SKIN_RGB

    def paint(mask, color, alpha=1.0):
        """Blend ``color`` over the image where ``mask`` holds, with opacity ``alpha``."""
        c = np.asarray(_COLORS[color], dtype=np.float32)
        if np.ndim(alpha) == 0 and alpha == 1.0:
            img[mask] = c
            return
        a = (np.asarray(mask, dtype=np.float32) * np.float32(alpha))[..., None]
        img[:] = img * (1.0 - a) + c * a

    cheek_y, cheek_b, cheek_alpha = spec["cheek"]
    r = np.hypot((X - 0.48) / 0.12, (y - cheek_y) / cheek_b)
    paint(np.ones_like(r), "blush", np.clip(1.0 - r**2, 0.0, 1.0) * cheek_alpha)
    marks = spec["marks"]
    if "tears" in marks:  # one under each eye
        paint(_ellipse_sdf(X, y, 0.38, -0.17, 0.03, 0.05) < 0, "tear")
    nose_y = -0.14 if "nose_wrinkles" in marks else -0.16
    paint(_ellipse_sdf(x, y, 0.0, nose_y, 0.065, 0.04) < 0, "nose")
    paint(_ellipse_sdf(X, y, 0.028, nose_y - 0.012, 0.014, 0.01) < 0, "line", 0.6)  # nostrils
    if "nose_wrinkles" in marks:  # two arcs across the bridge of the nose
        for y0 in (-0.06, -0.01):
            paint(_stroke(x, y, -0.06, 0.06, lambda t, y0=y0: y0 - 3.0 * t**2, lambda t: -6.0 * t, 0.008), "line", 0.7)
    if "frown_lines" in marks:  # two short vertical creases between the brows
        paint((np.abs(X - 0.035) < 0.007) & (np.abs(y - 0.16) < 0.035), "line", 0.6)
    _draw_eyes(paint, X, y, spec["eye"])
    _draw_lash_lines(paint, X, y)
    _draw_brows(paint, X, y, spec["brow"])
    _draw_mouth(paint, x, y, spec["mouth"])
    out[lo:size - lo, lo:size - lo] = np.clip(np.rint(img), 0, 255)
    return out


def face_image(expression: str | int, size: int = 128) -> np.ndarray:
    """Return the face texture for ``expression`` (name or id) as a new (size, size, 3) uint8 array."""
    return _render(_expression_id(expression), _check_size(size))


@lru_cache(maxsize=8)
def _face_images_cached(size: int) -> np.ndarray:
    arr = np.stack([_render(i, size) for i in range(len(EXPRESSIONS))])
    arr.flags.writeable = False
    return arr


def face_images(size: int = 128) -> np.ndarray:
    """All expressions as a read-only (7, size, size, 3) uint8 array, cached per size."""
    return _face_images_cached(_check_size(size))
