"""Echoic memory: what an agent heard from each source over the last second or two.

Auditory sensory memory holds a sound for a few seconds after it ends (about 2 s in adults:
Darwin, Turvey & Crowder 1972, Cognitive Psychology 3:255-267; Cowan 1984, Psychological
Bulletin 96:341-370); infants keep a sound's trace too (Cowan, Suomi & Morse 1982, Child
Development 53:984-990: 8-month-olds discriminated vowels across silent gaps of up to 400 ms, our
reading of their abstract). A policy without memory of its own cannot time a turn (how long it has
spoken, how long since it stopped, whether an answer came); this keeps that trace as part of the
sense, so that a standard feed-forward learner can.

With ``AuditionConfig(memory_s=S, memory_bin_s=B)`` (``S`` > 0) a listener observes
``"audition_memory"``: float32 ``(frames, n_sources)``, ``frames = ceil(S / B)``; frame 0 holds the
last ``B`` seconds (this control step included), frame 1 the ``B`` before, and so on; each value
is the loudest level (dB SPL, the louder ear, 0: not heard) at which the source was heard within
its frame. Cleared at every reset.
"""

from __future__ import annotations

import numpy as np

__all__ = ["EchoicMemory"]


class EchoicMemory:
    """One listener's trace: ``frames`` bins of ``bin_steps`` control steps each, per source."""

    def __init__(self, n_sources: int, frames: int, bin_steps: int):
        self.frames, self.bin_steps = int(frames), int(bin_steps)
        self.ring = np.zeros((self.frames * self.bin_steps, n_sources), np.float32)
        self.pos = 0                       # where the next step is written

    def reset(self) -> None:
        self.ring[:] = 0.0
        self.pos = 0

    def push(self, levels: np.ndarray) -> None:
        """This control step's level per source (dB, 0: not heard)."""
        self.ring[self.pos] = levels
        self.pos = (self.pos + 1) % len(self.ring)

    def read(self) -> np.ndarray:
        """``(frames, n_sources)``, the newest frame first: each bin's loudest level."""
        n = len(self.ring)
        newest_first = self.ring[(self.pos - 1 - np.arange(n)) % n]
        return newest_first.reshape(self.frames, self.bin_steps, -1).max(axis=1)
