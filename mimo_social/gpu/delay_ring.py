"""A sense's delay for every world at once, as the CPU env's
:class:`~mimo_social.core.delays.SenseDelay`: a delay of ``k`` control steps hands out the
reading of ``k`` steps before, and the reading at reset until then."""

from __future__ import annotations

__all__ = ["DelayRing"]


class DelayRing:
    """``delay`` control steps of ``(nworld, size)`` readings on ``device`` (``dtype``: torch's
    float32 unless given, e.g. uint8 for images)."""

    def __init__(self, delay: int, nworld: int, size: int, torch, device, dtype=None):
        self.delay = int(delay)
        self.ring = torch.zeros((self.delay + 1, nworld, size),
                                dtype=torch.float32 if dtype is None else dtype, device=device)
        self._next = 0

    def reset(self, reading, worlds=None):
        """The reading at reset in every slot (``worlds``: a bool mask of the worlds reset;
        None: all); returns the observation."""
        if worlds is None:
            self.ring[:] = reading
            self._next = 0
        else:
            self.ring[:, worlds] = reading[worlds]
        return self.ring[self._next].clone()

    def push(self, reading):
        """This step's reading in; the observation (the reading of ``delay`` steps before)
        out."""
        if not self.delay:
            return reading
        self.ring[self._next] = reading
        self._next = (self._next + 1) % (self.delay + 1)
        return self.ring[self._next].clone()
