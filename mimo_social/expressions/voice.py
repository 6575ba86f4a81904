"""The voice: the kinds of sound an agent can make, as data, and how loudness maps to a level.

:data:`SOUNDS` names the kinds; their index is the ``"voice"`` id of an agent's action
(``AgentConfig(voice=True)``). :data:`VOICE_TABLE` holds per kind its level range in dB SPL at
1 m from the mouth, for an infant and for an adult (``(quietest, loudest)``), its fundamental
frequency range and a typical spectral centroid in Hz, and where each figure comes from. A
figure marked "our choice" is a plausible value picked for the simulation where no published
figure was found.

**Loudness**: the action's ``"loudness"`` in [0, 1] maps linearly in dB onto the kind's range:
``level = quietest + loudness * (loudest - quietest)`` (:func:`level_db`); 0 is the kind's
quietest, 1 its loudest. ``"silence"`` makes no sound whatever the loudness (level 0 dB, below
every hearing threshold).

Levels at 1 m from published figures at other distances use the free-field law
``L(1 m) = L(d) + 20 log10(d / 1 m)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SOUNDS", "VoiceKind", "VOICE_TABLE", "level_db", "level_ranges", "MAX_LEVEL_DB"]

SOUNDS: tuple[str, ...] = ("silence", "coo", "babble", "cry", "laugh", "speech")


@dataclass(frozen=True)
class VoiceKind:
    """One kind of sound: levels (dB SPL at 1 m), pitch (Hz) and sources."""

    name: str
    infant_db: tuple[float, float]   # (quietest, loudest) at 1 m, an infant
    adult_db: tuple[float, float]    # (quietest, loudest) at 1 m, an adult
    f0_hz: tuple[float, float]       # fundamental frequency range (0, 0: none)
    centroid_hz: float               # a typical spectral centroid (0: none)
    source: str                      # where the figures come from


VOICE_TABLE: tuple[VoiceKind, ...] = (
    VoiceKind("silence", (0.0, 0.0), (0.0, 0.0), (0.0, 0.0), 0.0,
              "no sound: 0 dB, below the hearing threshold"),
    VoiceKind("coo", (55.0, 70.0), (50.0, 65.0), (250.0, 500.0), 1000.0,
              "levels our choice (quiet comfort sounds, below a cry, about conversational); "
              "infant f0 near 300-450 Hz in pre-linguistic vocalisations (Kent & Murray 1982, "
              "J Acoust Soc Am 72:353-365); centroid our choice"),
    VoiceKind("babble", (60.0, 75.0), (55.0, 70.0), (250.0, 500.0), 1500.0,
              "levels our choice (between cooing and raised speech); f0 as coo (Kent & Murray "
              "1982); centroid our choice"),
    VoiceKind("cry", (75.0, 100.0), (60.0, 80.0), (250.0, 650.0), 2000.0,
              "infant loudest: 117 dB peak at 15 cm (Bostrom & Swanson 1983, N Engl J Med "
              "309:1194) is 100.5 dB at 1 m; quietest, adult levels and centroid our choice; "
              "infant cry f0 about 250-650 Hz (hyperphonation above: not modelled)"),
    VoiceKind("laugh", (60.0, 80.0), (60.0, 80.0), (200.0, 500.0), 1500.0,
              "levels our choice; adult laugh f0 means 282 Hz (men) and 421 Hz (women) "
              "(Bachorowski, Smoski & Owren 2001, J Acoust Soc Am 110:1581-1597)"),
    VoiceKind("speech", (55.0, 70.0), (55.0, 76.0), (85.0, 255.0), 1000.0,
              "adult: casual 55 to loud 76 dB(A) at 1 m (Pearsons, Bennett & Fidell 1977, "
              "'Speech levels in various noise environments', EPA-600/1-77-025), "
              "conversational about 60 dB; adult f0 85-255 Hz (men and women); an infant's "
              "first words: levels our choice"),
)

if tuple(k.name for k in VOICE_TABLE) != SOUNDS:   # one table, in the order of SOUNDS
    raise TypeError("VOICE_TABLE must list the kinds of SOUNDS in order")

#: the loudest level of any kind at 1 m (dB SPL)
MAX_LEVEL_DB = max(max(k.infant_db[1], k.adult_db[1]) for k in VOICE_TABLE)


#: per kind (quietest, loudest) at 1 m as plain floats: an infant's, an adult's
_RANGES = {adult: tuple((float(lo), float(hi)) for lo, hi in (
    (k.adult_db if adult else k.infant_db) for k in VOICE_TABLE)) for adult in (False, True)}


def level_ranges(adult: bool) -> np.ndarray:
    """``(len(SOUNDS), 2)`` float64: per kind (quietest, loudest) dB SPL at 1 m."""
    return np.array(_RANGES[bool(adult)], float)


def level_db(kind: int, loudness: float, adult: bool = False) -> float:
    """The level at 1 m (dB SPL) of ``kind`` (an index of :data:`SOUNDS`) at ``loudness``
    in [0, 1]: linear in dB from the kind's quietest (0) to its loudest (1)."""
    lo, hi = _RANGES[bool(adult)][int(kind)]
    return lo + float(loudness) * (hi - lo)
