"""The turn-taking measures on sound events: pure code, fed the sound kind of each agent step by
step (ids of :data:`mimo_social.expressions.voice.SOUNDS`; 0, "silence", is no vocalisation).

A **vocalisation** is a run of steps with a non-silent kind; its onset is its first step, its
offset the first silent step after it. Counted per episode:

* ``infant_vocalisations`` (onsets), ``infant_rate_per_min`` (onsets per minute),
  ``vocal_fraction`` (the share of the steps the infant vocalises), ``speech_like_fraction``
  (the share of its onsets that are "babble" or "speech": Bloom's syllabic against vocalic
  sounds, Goldstein et al.'s more mature babbling), ``cry_fraction``;
* ``caregiver_utterances``, ``caregiver_rate_per_min``;
* **response latency**: at each caregiver onset while the infant is silent, the time since
  the infant's last offset when no caregiver onset came between (``latencies``, seconds: the
  caregiver's answer or a chance utterance); ``mean_latency_s`` (0 when none);
* ``answered_fraction``: the share of the infant's vocalisations of at least ``min_vocal_s``
  (0.2 s) answered, i.e. followed by a caregiver onset within ``window_s`` (1 s) of their
  offset, before the infant vocalises again (a vocalisation is resolved when answered, when the
  window passes, or at the infant's next onset); shorter ones are never answers (a policy that
  flickers its voice on and off would otherwise find a recent offset before any utterance);
* **turns**: speaker switches within ``window_s``: a caregiver onset answering an infant
  vocalisation (as above) or an infant onset within ``window_s`` of a caregiver offset while
  the caregiver is silent; ``turns`` counts both, ``infant_turns`` the second kind,
  ``mean_turn_gap_s`` is the mean gap of all (0 when none).
"""

from __future__ import annotations

import numpy as np

__all__ = ["TurnMeasures", "measure", "SPEECH_LIKE", "CRY", "INFO_KEYS"]

#: the kinds that count as speech-like (ids of SOUNDS: "babble", "speech")
SPEECH_LIKE = (2, 5)
#: the id of "cry"
CRY = 3
#: the keys of :meth:`TurnMeasures.infos`
INFO_KEYS = ("infant_vocalisations", "infant_rate_per_min", "vocal_fraction",
             "speech_like_fraction", "cry_fraction", "caregiver_utterances",
             "caregiver_rate_per_min", "mean_latency_s", "answered_fraction", "turns",
             "infant_turns", "mean_turn_gap_s")


class TurnMeasures:
    """The measures of one episode (see the module docstring); ``dt`` the control step in
    seconds, ``window_s`` the turn window, ``min_vocal_s`` the shortest vocalisation that can be
    answered."""

    def __init__(self, dt: float, window_s: float = 1.0, min_vocal_s: float = 0.2):
        self.dt = float(dt)
        self.window = max(0, int(round(float(window_s) / self.dt)))
        self.min_vocal = max(1, int(round(float(min_vocal_s) / self.dt)))
        self._start = 0                       # the infant's current vocalisation's onset
        self.steps = 0
        self._prev = (False, False)
        self.vocal_steps = 0
        self.infant_onsets = self.speech_like = self.cries = 0
        self.caregiver_onsets = 0
        self.latencies: list[float] = []
        self._last_off: int | None = None     # the infant's last offset not yet followed
        self._open: int | None = None         # offset of the vocalisation awaiting an answer
        self._care_off: int | None = None     # the caregiver's last offset not yet followed
        self.answered = self.resolved = 0
        self.gaps: list[float] = []
        self.infant_turns = 0

    def update(self, infant_kind: int, caregiver_kind: int) -> dict:
        """One step; returns what happened on it: ``infant_onset``, ``caregiver_onset``,
        ``answer`` (a caregiver onset answering the infant within the window)."""
        t = self.steps
        self.steps += 1
        iv, cv = int(infant_kind) != 0, int(caregiver_kind) != 0
        i_on, i_off = iv and not self._prev[0], self._prev[0] and not iv
        c_on, c_off = cv and not self._prev[1], self._prev[1] and not cv
        self._prev = (iv, cv)
        self.vocal_steps += iv
        answer = False
        if self._open is not None and t - self._open > self.window:
            self.resolved += 1
            self._open = None
        if i_off:
            self._last_off = t
            if t - self._start >= self.min_vocal:
                self._open = t
        if c_off:
            self._care_off = t
        if c_on:
            self.caregiver_onsets += 1
            if not iv and self._last_off is not None:
                lat = (t - self._last_off) * self.dt
                self.latencies.append(lat)
                if self._open is not None:
                    answer = True
                    self.answered += 1
                    self.resolved += 1
                    self.gaps.append(lat)
                    self._open = None
            self._last_off = None
            self._care_off = None
        if i_on:
            self._start = t
            self.infant_onsets += 1
            kind = int(infant_kind)
            self.speech_like += kind in SPEECH_LIKE
            self.cries += kind == CRY
            if self._open is not None:          # vocal again before an answer
                self.resolved += 1
                self._open = None
            if self._care_off is not None and not cv and t - self._care_off <= self.window:
                self.infant_turns += 1
                self.gaps.append((t - self._care_off) * self.dt)
            self._care_off = None
            self._last_off = None
        return {"infant_onset": i_on, "caregiver_onset": c_on, "answer": answer}

    def infos(self) -> dict:
        minutes = max(self.steps, 1) * self.dt / 60.0
        n = max(self.infant_onsets, 1)
        return {"infant_vocalisations": self.infant_onsets,
                "infant_rate_per_min": self.infant_onsets / minutes,
                "vocal_fraction": self.vocal_steps / max(self.steps, 1),
                "speech_like_fraction": self.speech_like / n if self.infant_onsets else 0.0,
                "cry_fraction": self.cries / n if self.infant_onsets else 0.0,
                "caregiver_utterances": self.caregiver_onsets,
                "caregiver_rate_per_min": self.caregiver_onsets / minutes,
                "mean_latency_s": float(np.mean(self.latencies)) if self.latencies else 0.0,
                "answered_fraction": self.answered / self.resolved if self.resolved else 0.0,
                "turns": self.answered + self.infant_turns,
                "infant_turns": self.infant_turns,
                "mean_turn_gap_s": float(np.mean(self.gaps)) if self.gaps else 0.0}


def measure(infant, caregiver, dt: float, window_s: float = 1.0,
            min_vocal_s: float = 0.2) -> tuple[dict, list[float]]:
    """:class:`TurnMeasures` over two arrays of sound kinds (one per step): its infos and the
    response latencies (s)."""
    infant, caregiver = np.asarray(infant, int), np.asarray(caregiver, int)
    if infant.shape != caregiver.shape or infant.ndim != 1:
        raise ValueError(f"measure: infant {infant.shape} and caregiver {caregiver.shape} "
                         "must be 1-D arrays of the same length")
    m = TurnMeasures(dt, window_s, min_vocal_s)
    for a, b in zip(infant.tolist(), caregiver.tolist()):
        m.update(a, b)
    return m.infos(), list(m.latencies)
