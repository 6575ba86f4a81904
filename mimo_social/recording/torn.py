"""Recordings cut off in the middle of a write, and the whole part of them.

A run killed (``SIGKILL``, the machine going down) while Rerun's file writer was writing leaves
a file whose last frame is torn: its header promises more bytes than the file holds. Rerun's own
reader (``rerun.chunk.RrdReader``) then refuses the whole file ("Message payload ... exceeds file
size"), although every frame before it, and so every row up to :attr:`Recorder.flushed_step`, is
there. :func:`whole_length` finds where the last whole frame ends; :func:`salvage` writes that
prefix to a file Rerun reads (without a footer, as for any run that was not closed), and
:func:`readable_copy` hands a reader such a copy only when the file is torn.

The framing read here is Rerun 0.41's ``.rrd`` stream (the version the project pins): a
12-byte stream header (``RRF2``, the writer's version, the encoding options), then frames of a
little-endian ``u64`` kind and ``u64`` payload length followed by the payload; kind 0 ends the
stream and is followed by a 32-byte trailer ending in ``RRF2FOOT`` and its version. Another
stream header may follow (files appended to).
"""

from __future__ import annotations

import contextlib
import struct
import tempfile
from collections.abc import Iterator
from pathlib import Path

__all__ = ["STREAM_MAGIC", "readable_copy", "salvage", "whole_length"]

STREAM_MAGIC = b"RRF2"
_STREAM_HEADER = 12          # magic, version (4 bytes), options (4 bytes)
_FRAME_HEADER = struct.Struct("<QQ")
_END = 0
_TRAILER = 32                # after the end frame: offsets, a checksum, "RRF2FOOT", a version
_TRAILER_MAGIC = b"RRF2FOOT"


def whole_length(path: str | Path) -> int:
    """The number of leading bytes of ``path`` that are whole frames (the file's size when
    nothing is torn; 0 when not even the stream header is whole).

    Raises ValueError when the file does not start as a Rerun stream.
    """
    path = Path(path)
    size = path.stat().st_size
    with path.open("rb") as f:
        magic = f.read(len(STREAM_MAGIC))
        if size and magic != STREAM_MAGIC[:len(magic)]:
            raise ValueError(f"{path}: not a Rerun recording (starts with {magic!r}, "
                             f"expected {STREAM_MAGIC!r})")
        whole = pos = 0
        while pos < size:
            f.seek(pos)
            head = f.read(_FRAME_HEADER.size)
            if pos == 0 or head[:len(STREAM_MAGIC)] == STREAM_MAGIC:   # a stream (re)starts
                if len(head) < _STREAM_HEADER:
                    return whole
                pos = whole = pos + _STREAM_HEADER
                continue
            if len(head) < _FRAME_HEADER.size:
                return whole
            kind, length = _FRAME_HEADER.unpack(head)
            end = pos + _FRAME_HEADER.size + length
            if kind == _END:                 # the end frame and the footer's trailer: one unit
                end += _TRAILER
                if end <= size:
                    f.seek(end - len(_TRAILER_MAGIC) - 4)
                    if f.read(len(_TRAILER_MAGIC)) != _TRAILER_MAGIC:
                        raise ValueError(f"{path}: the stream's end at byte {pos} is not "
                                         f"followed by Rerun's footer ({_TRAILER_MAGIC!r})")
            if end > size:
                return whole
            pos = whole = end
        return whole


def _salvageable(path: Path) -> int:
    """``whole_length(path)``; ValueError when not even the stream header is whole."""
    keep = whole_length(path)
    if keep == 0:
        raise ValueError(f"{path}: {path.stat().st_size} bytes, fewer than a Rerun stream "
                         f"header ({_STREAM_HEADER} bytes): nothing to salvage")
    return keep


def _copy_prefix(path: Path, out: Path, keep: int) -> None:
    with path.open("rb") as src, out.open("wb") as dst:
        remaining = keep
        while remaining:
            block = src.read(min(remaining, 1 << 20))
            dst.write(block)
            remaining -= len(block)


def salvage(path: str | Path, out: str | Path) -> int:
    """Write the whole frames of ``path`` to ``out`` and return how many bytes of a torn last
    frame were left out (0 when the file was not torn; ``out`` is then a plain copy).

    Raises ValueError when not even the stream header is whole.
    """
    path, out = Path(path), Path(out)
    keep = _salvageable(path)
    if out.resolve() == path.resolve():
        raise ValueError(f"salvage: out={str(out)!r} is the recording itself; allowed: "
                         f"another path (the original stays as it is)")
    _copy_prefix(path, out, keep)
    return path.stat().st_size - keep


@contextlib.contextmanager
def readable_copy(path: str | Path) -> Iterator[tuple[Path, int]]:
    """``(file to read, torn bytes left out)``: ``path`` itself when it is not torn, else a
    temporary salvaged copy that lives as long as the ``with`` block."""
    path = Path(path)
    torn = path.stat().st_size - whole_length(path)
    if torn == 0:
        yield path, 0
        return
    keep = _salvageable(path)
    with tempfile.TemporaryDirectory(prefix="mimo_rrd_") as tmp:
        out = Path(tmp) / path.name
        _copy_prefix(path, out, keep)
        yield out, torn
