"""``VocalInfant``: the scripted infant's vocal learning rule, as pure, seeded code.

Fed each control step whether the caregiver speaks, it returns the sound kind the infant makes
(an id of :data:`mimo_social.expressions.voice.SOUNDS`: 0 silence, 1 coo, 2 babble).

acts:
    while the caregiver speaks it is silent (it listens: Bloom 1988's speak-listen pattern
    under turn-taking), and for up to ``window_s`` after each of its vocalisations it waits
    for an answer, silent; otherwise, from silence, it begins a vocalisation with probability
    ``1 - exp(-rate * dt)`` per step; the vocalisation is "babble" with probability
    ``p_babble``, else "coo", and lasts a duration drawn uniformly from ``duration_s``
    (0.3-0.8 s, our choice)
learns:
    a caregiver onset within ``window_s`` (1 s) of the offset of its vocalisation is an
    answer: ``rate += learn * (max_rate - rate)`` and ``p_babble += learn * (1 - p_babble)``;
    no answer: ``rate += forget * (base_rate - rate)`` and ``p_babble += forget *
    (base_babble - p_babble)``. So contingent answers raise both its volubility and the share
    of its speech-like (babble) sounds, as in Goldstein, King and West (2003, PNAS
    100:8030-8035: 8-month-olds whose mothers answered their babbling contingently, against
    yoked controls, produced more mature vocalisations); utterances independent of it change
    less (an utterance within a second of an offset by chance still counts as an answer)
defaults:
    ``base_rate`` 0.3 /s (from silence), ``max_rate`` 2.0 /s, ``base_babble`` 0.2, ``learn``
    0.3, ``forget`` 0.05: our choice (a learning rule of this package, not a fitted model);
    every episode starts from the base values (``reset``)
"""

from __future__ import annotations

import math

import numpy as np

from ...util.checks import ConfigError, check_number, check_numbers, show

__all__ = ["VocalInfant", "COO", "BABBLE"]

COO, BABBLE = 1, 2


class VocalInfant:
    """The rule of the module docstring; ``dt`` the control step (s)."""

    def __init__(self, dt: float = 0.01, base_rate=0.3, max_rate=2.0, base_babble=0.2,
                 learn=0.3, forget=0.05, duration_s=(0.3, 0.8), window_s=1.0):
        who = "VocalInfant"
        self.dt = check_number(who, "dt", dt, 1e-4, 1.0)
        self.base_rate = check_number(who, "base_rate", base_rate, 0.0, 10.0)
        self.max_rate = check_number(who, "max_rate", max_rate, 0.0, 10.0)
        self.base_babble = check_number(who, "base_babble", base_babble, 0.0, 1.0)
        self.learn = check_number(who, "learn", learn, 0.0, 1.0)
        self.forget = check_number(who, "forget", forget, 0.0, 1.0)
        self.duration_s = check_numbers(who, "duration_s", duration_s, 2, 0.01, 10.0,
                                        "(min, max) seconds, 0.01 <= min <= max <= 10")
        if self.duration_s[1] < self.duration_s[0]:
            raise ConfigError(f"{who}: duration_s={show(duration_s)} not allowed; allowed: "
                              "(min, max) seconds, 0.01 <= min <= max <= 10")
        self.window_s = check_number(who, "window_s", window_s, 0.0, 10.0)
        self.rng = None

    def __repr__(self):
        return (f"VocalInfant(base_rate={self.base_rate}, max_rate={self.max_rate}, "
                f"base_babble={self.base_babble}, learn={self.learn}, forget={self.forget})")

    def reset(self, rng: np.random.Generator, dt: float | None = None) -> None:
        if dt is not None:
            self.dt = float(dt)
        self.rng = rng
        self.rate, self.p_babble = self.base_rate, self.base_babble
        self.t = -1
        self._window = max(0, int(round(self.window_s / self.dt)))
        self._left = 0               # steps of the running vocalisation left
        self._kind = 0
        self._open: int | None = None
        self._care_prev = False
        self.answers = self.misses = 0

    def _learn(self, answered: bool) -> None:
        if answered:
            self.answers += 1
            self.rate += self.learn * (self.max_rate - self.rate)
            self.p_babble += self.learn * (1.0 - self.p_babble)
        else:
            self.misses += 1
            self.rate += self.forget * (self.base_rate - self.rate)
            self.p_babble += self.forget * (self.base_babble - self.p_babble)

    def step(self, caregiver_vocal: bool) -> int:
        """One step: ``caregiver_vocal`` (whether the caregiver's sound, as the last step left
        it, is not silence); returns this step's sound kind."""
        if self.rng is None:
            raise RuntimeError("VocalInfant.step() before reset(rng)")
        self.t += 1
        care_on = bool(caregiver_vocal) and not self._care_prev
        self._care_prev = bool(caregiver_vocal)
        if self._open is not None:
            if care_on and self._left == 0:
                self._learn(True)
                self._open = None
            elif self.t - self._open > self._window:
                self._learn(False)
                self._open = None
        if self._left > 0:
            self._left -= 1
            if self._left == 0:          # this step is the offset: silent
                self._open = self.t
                return 0
            return self._kind
        if caregiver_vocal or self._open is not None:   # listening, or waiting for an answer
            return 0
        if self.rng.random() < 1.0 - math.exp(-self.rate * self.dt):
            self._kind = BABBLE if self.rng.random() < self.p_babble else COO
            lo, hi = self.duration_s
            self._left = max(1, int(round(self.rng.uniform(lo, hi) / self.dt)))
            return self._kind
        return 0
