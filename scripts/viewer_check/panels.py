"""Which panels of a viewer screenshot show data (:mod:`viewer_check.check`).

Rerun's web viewer draws everything, text included, into one WebGL canvas: the page has no DOM
text to read. A panel that has nothing to show at the time cursor (its entity not logged yet, or
not in the file) shows only a short grey line of text in its middle ("No data available"), or
nothing at all. So the check reads the pixels: the page is cut into panels along the viewer's
one-pixel separator lines (:func:`panel_boxes`), and a panel whose body (below its title bar)
holds nothing but its background and at most one short line of text is empty
(:func:`is_empty_panel`). A face or an eye image fills its panel, a plot has axes across it, a
text log has rows, a legend has its colour bar: none of them is one short line.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MIN_PANEL", "SEPARATOR_RGB", "TITLE_BAR", "empty_panels", "has_title",
           "is_empty_panel", "long_runs", "panel_boxes", "separator_regions"]

#: the colour of the viewer's one-pixel panel separators (light theme)
SEPARATOR_RGB = (223, 223, 223)
#: a panel's title bar (its name and buttons), in page pixels from the panel's top
TITLE_BAR = 26
#: regions smaller than this (either side, pixels) are bars and gaps, not panels
MIN_PANEL = 60
#: a pixel differs from the panel's background when a channel differs by more than this
_INK = 40
#: the tallest and widest a panel's lone message may be (one line of text), in pixels
_MESSAGE_HEIGHT, _MESSAGE_WIDTH = 22, 260


def long_runs(mask: np.ndarray, length: int) -> np.ndarray:
    """The pixels of ``mask`` in horizontal runs of at least ``length`` pixels."""
    padded = np.zeros((mask.shape[0], mask.shape[1] + 2), dtype=np.int8)
    padded[:, 1:-1] = mask
    d = np.diff(padded, axis=1)
    out = np.zeros(mask.shape, dtype=bool)
    for y, x in zip(*np.nonzero(d == 1)):
        end = x + np.argmax(d[y, x:] == -1)
        if end - x >= length:
            out[y, x:end] = True
    return out


def separator_regions(img: np.ndarray) -> tuple[np.ndarray, int]:
    """The page cut along the viewer's long one-pixel separator lines (gaps at their junctions
    closed): a label image (0 on the lines) and the number of regions."""
    from scipy import ndimage

    sep = np.abs(img[..., :3].astype(np.int16) - np.array(SEPARATOR_RGB)).max(axis=-1) <= 1
    lines = long_runs(sep, 60) | long_runs(sep.T, 60).T
    lines = ndimage.binary_dilation(lines, iterations=3)
    return ndimage.label(~lines)


def panel_boxes(img: np.ndarray, min_size: int = MIN_PANEL) -> list[tuple[int, int, int, int]]:
    """The boxes (x0, y0, x1, y1) of the panels of the viewer page in ``img``, largest first:
    the regions between separator lines at least ``min_size`` pixels each way (the page's top
    bar and the collapsed time panel are thinner)."""
    from scipy import ndimage

    labels, n = separator_regions(img)
    if n == 0:
        return []
    sizes = np.bincount(labels.ravel())[1:]
    boxes = []
    for k, (ys, xs) in enumerate(ndimage.find_objects(labels)):
        if xs.stop - xs.start >= min_size and ys.stop - ys.start >= min_size:
            boxes.append((int(sizes[k]), (int(xs.start), int(ys.start), int(xs.stop),
                                          int(ys.stop))))
    return [b for _, b in sorted(boxes, key=lambda sb: -sb[0])]


def _ink(pixels: np.ndarray) -> np.ndarray:
    """Where ``pixels`` (H x W x 3) differ from their most common colour (the background)."""
    flat = pixels.reshape(-1, 3)
    colours, counts = np.unique(flat, axis=0, return_counts=True)
    background = colours[np.argmax(counts)]
    return np.abs(pixels.astype(np.int16) - background).max(axis=-1) > _INK


def has_title(img: np.ndarray, box, title_bar: int = TITLE_BAR) -> bool:
    """Whether the region ``box`` of ``img`` starts with a title bar (a name, buttons): a panel,
    not the blank space a grid leaves where it has fewer views than cells."""
    x0, y0, x1, y1 = box
    bar = img[y0 + 2:y0 + title_bar - 2, x0 + 2:x1 - 2, :3]
    return bar.size > 0 and int(_ink(bar).sum()) >= 20


def is_empty_panel(img: np.ndarray, box, title_bar: int = TITLE_BAR) -> bool:
    """Whether the panel ``box`` of ``img`` shows no data: below its title bar, nothing but its
    background (the most common colour) and at most one short line of text (a message such as
    "No data available")."""
    x0, y0, x1, y1 = box
    body = img[y0 + title_bar:y1 - 2, x0 + 2:x1 - 2, :3]
    if body.size == 0:
        return True
    ink = _ink(body)
    if not ink.any():
        return True
    ys, xs = np.nonzero(ink)
    return (ys.max() - ys.min() < _MESSAGE_HEIGHT and xs.max() - xs.min() < _MESSAGE_WIDTH)


def empty_panels(img: np.ndarray, boxes=None) -> list[tuple[int, int, int, int]]:
    """The panels of ``img`` (``boxes``, default :func:`panel_boxes`; regions without a title
    bar are not panels) that show no data."""
    boxes = panel_boxes(img) if boxes is None else boxes
    return [b for b in boxes if has_title(img, b) and is_empty_panel(img, b)]
