"""PNG files without an imaging library: one encoder for eye images in recordings, skin and
anaglyph pictures, and figures."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

__all__ = ["encode_png", "write_png"]


def _png_chunk(kind: bytes, payload: bytes) -> bytes:
    return (struct.pack(">I", len(payload)) + kind + payload
            + struct.pack(">I", zlib.crc32(payload, zlib.crc32(kind)) & 0xFFFFFFFF))


_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_PNG_END = _png_chunk(b"IEND", b"")


def encode_png(image: np.ndarray, level: int = 1) -> bytes:
    """An (h, w, 3) or (h, w) uint8 image as PNG bytes (lossless; no imaging library needed).

    Every row uses PNG's "up" filter (the difference to the row above): with zlib level 1 it
    keeps rendered eye images small and fast to encode (``mimo-social bench recording``).
    """
    img = np.asarray(image)
    if img.dtype != np.uint8 or img.ndim not in (2, 3) or (img.ndim == 3 and img.shape[2] != 3):
        raise ValueError(f"encode_png takes (h, w, 3) or (h, w) uint8 images, got "
                         f"{img.dtype} {img.shape}")
    h, w = img.shape[:2]
    rows = img.reshape(h, -1)
    raw = np.empty((h, rows.shape[1] + 1), np.uint8)
    raw[:, 0] = 2                                    # filter type "up"
    raw[0, 1:] = rows[0]
    np.subtract(rows[1:], rows[:-1], out=raw[1:, 1:])   # uint8: wraps modulo 256, as PNG wants
    header = struct.pack(">IIBBBBB", w, h, 8, 2 if img.ndim == 3 else 0, 0, 0, 0)
    return b"".join((_PNG_SIGNATURE, _png_chunk(b"IHDR", header),
                     _png_chunk(b"IDAT", zlib.compress(raw.data, level)), _PNG_END))


def write_png(path, image: np.ndarray, level: int = 6) -> Path:
    """Write an (h, w, 3) or (h, w) uint8 image as a PNG file (see :func:`encode_png`)."""
    path = Path(path)
    path.write_bytes(encode_png(np.ascontiguousarray(image, dtype=np.uint8), level))
    return path
