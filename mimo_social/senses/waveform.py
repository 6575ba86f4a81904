"""A short binaural sound frame per listener (``AuditionConfig(waveform=True)``), synthesised in
numpy in the free field: what the two ears' pressure is over the control step just simulated.

Each kind of :data:`~mimo_social.expressions.voice.SOUNDS` but silence is one simple synthetic
source, a harmonic complex: the first :data:`HARMONICS` harmonics of one fundamental (the middle
of the kind's f0 range in the voice table), harmonic ``h`` at amplitude ``1 / h``, scaled to
unit RMS. At each ear it is scaled to the ear's level (``p = 20 µPa * 10^(level / 20)`` RMS, the
level of the audition features, head shadow included) and shifted by half the ITD: the left ear
hears ``s(t + itd / 2)``, the right ``s(t - itd / 2)`` (a source on the left reaches the left ear
first). The frame's samples are at :data:`SAMPLE_RATE` over the control step ending at
``data.time``; a listener's frame is the sum over the sources it hears. Our choice throughout:
a stand-in for voices with the right pitch, level and binaural cues, not recorded voices.
"""

from __future__ import annotations

import numpy as np

from ..expressions.voice import VOICE_TABLE

__all__ = ["SAMPLE_RATE", "HARMONICS", "P_REF", "frame_samples", "binaural_frames", "peak"]

SAMPLE_RATE = 16000.0    # Hz
HARMONICS = 5
P_REF = 20e-6            # Pa: 0 dB SPL
_H = np.arange(1, HARMONICS + 1, dtype=float)
_AMP = (1.0 / _H) / np.sqrt(np.sum((1.0 / _H) ** 2) / 2.0)      # unit RMS
#: per kind its fundamental (Hz; silence: 0)
F0 = np.array([0.5 * (k.f0_hz[0] + k.f0_hz[1]) for k in VOICE_TABLE])


def frame_samples(dt: float) -> int:
    """Samples in a frame of one control step of ``dt`` seconds."""
    return max(1, int(round(dt * SAMPLE_RATE)))


def peak(n_sources: int, max_level_db: float) -> float:
    """The largest |pressure| (Pa) a frame can hold: every source at ``max_level_db``."""
    return float(n_sources * _AMP.sum() * P_REF * 10.0 ** (max_level_db / 20.0))


def binaural_frames(kind: np.ndarray, level: np.ndarray, itd_ms: np.ndarray, t_end: float,
                    n: int) -> np.ndarray:
    """``(l, 2, n)`` float32 pressure (Pa) at each listener's left and right ear over the
    ``n`` samples before ``t_end``: ``kind`` (s,) ids, ``level`` (l, s, 2) dB SPL at the ears
    (0: not heard), ``itd_ms`` (l, s)."""
    t = t_end - (n - np.arange(n)) / SAMPLE_RATE                        # (n,)
    half = (0.5e-3 * itd_ms)[..., None] * np.array([1.0, -1.0])         # (l, s, 2): time shift
    phase = (2 * np.pi * F0[kind])[None, :, None, None, None] * _H[:, None] \
        * (t + half[..., None, None])                                    # (l, s, 2, H, n)
    wave = np.einsum("lsehn,h->lsen", np.sin(phase), _AMP)
    gain = np.where(level > 0.0, P_REF * 10.0 ** (level / 20.0), 0.0) * (F0[kind] > 0)[:, None]
    return np.einsum("lsen,lse->len", wave, gain).astype(np.float32)

