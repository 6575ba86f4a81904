"""When the turn-taking caregiver speaks: pure, seeded scheduling on control steps.

Nothing here reads a world: each schedule is fed, step by step, whether the infant vocalises
(:meth:`ContingentSchedule.step`) or nothing at all (:class:`TimedSchedule`), and says whether
the caregiver speaks on that step. Every random draw comes from the generator given at
``reset``. The task's caregiver turns these answers into its ``"voice"`` action.

**Latency** (:class:`Latency`): a lognormal distribution of seconds given by its mean and sd
(``sigma^2 = ln(1 + sd^2 / mean^2)``, ``mu = ln(mean) - sigma^2 / 2``); ``sd = 0`` is the
constant ``mean``. It is measured from the **offset** of the infant's vocalisation (mothers
vocalise contingent on the offset of their infants' non-distress vocalising: Bornstein et al.
2015, Child Dev). A latency of ``x`` s becomes ``round(x / dt)`` control steps.

**Contingent** (:class:`ContingentSchedule`): at each offset of an infant vocalisation (the
infant vocal on the step before, silent now) that finds the caregiver silent with no answer
pending (*eligible*), two draws are made, always both and in this order: ``u`` (uniform) and a
latency; the offset is answered when ``u < probability``, by an utterance of ``duration``
steps that starts ``round(latency / dt)`` steps after the offset step (0: on the offset step
itself), whatever the infant does meanwhile. Offsets that are not eligible draw nothing.
``events`` logs every eligible offset (``step``, ``answered``, ``latency_steps``) and
``onsets`` every utterance's first step.

**Timed** (:class:`TimedSchedule`): utterances at given onset steps, read from nothing but
the list: the replay of a recorded session (its ``onsets``) and the non-contingent caregiver,
whose onsets are drawn at reset (:func:`yoked_onsets`: as many utterances as a recorded
session had, at uniformly random non-overlapping times; :func:`poisson_onsets`: a Poisson
process of a given rate). An onset inside a running utterance restarts it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...util.checks import ConfigError, check_int, check_number

__all__ = ["Latency", "ContingentSchedule", "TimedSchedule", "yoked_onsets", "poisson_onsets",
           "steps_of"]


def steps_of(seconds: float, dt: float) -> int:
    """``seconds`` as whole control steps of ``dt`` (rounded, at least 0)."""
    return max(0, int(round(float(seconds) / float(dt))))


@dataclass(frozen=True)
class Latency:
    """A lognormal latency in seconds with ``mean_s`` (> 0) and ``sd_s`` (>= 0)."""

    mean_s: float = 0.7
    sd_s: float = 0.3

    def __post_init__(self):
        check_number("turn_taking", "latency_mean_s", self.mean_s, 0.01, 10.0)
        check_number("turn_taking", "latency_sd_s", self.sd_s, 0.0, 10.0)

    @property
    def sigma(self) -> float:
        return math.sqrt(math.log1p((self.sd_s / self.mean_s) ** 2))

    @property
    def mu(self) -> float:
        return math.log(self.mean_s) - self.sigma ** 2 / 2

    def draw(self, rng: np.random.Generator, size=None):
        """One latency (``size=None``) or an array of them, in seconds."""
        if self.sigma == 0.0:
            return self.mean_s if size is None else np.full(size, self.mean_s)
        return rng.lognormal(self.mu, self.sigma, size)

    def cdf(self, seconds) -> np.ndarray:
        """The distribution function at ``seconds`` (for tests of the draws)."""
        x = np.asarray(seconds, float)
        if self.sigma == 0.0:
            return (x >= self.mean_s).astype(float)
        from math import erf
        z = (np.log(np.maximum(x, 1e-300)) - self.mu) / (self.sigma * math.sqrt(2.0))
        out = 0.5 * (1.0 + np.vectorize(erf)(z))
        return np.where(x > 0, out, 0.0)


class ContingentSchedule:
    """Answers the infant's vocalisation offsets (see the module docstring)."""

    def __init__(self, latency: Latency, probability: float, duration_steps: int, dt: float):
        self.latency = latency
        self.probability = check_number("turn_taking", "response_probability", probability,
                                        0.0, 1.0)
        self.duration = check_int("turn_taking", "utterance steps", duration_steps, 1)
        self.dt = check_number("turn_taking", "dt", dt, 1e-6)
        self.rng = None

    def reset(self, rng: np.random.Generator) -> None:
        self.rng = rng
        self.t = -1
        self._prev = False
        self._due: int | None = None       # step the pending answer starts
        self._until = -1                   # last step of the running utterance
        self.events: list[dict] = []
        self.onsets: list[int] = []

    def step(self, infant_vocal: bool) -> bool:
        """One control step: ``infant_vocal`` (the infant's sound this step); returns whether
        the caregiver speaks on this step."""
        if self.rng is None:
            raise RuntimeError("ContingentSchedule.step() before reset(rng)")
        self.t += 1
        t = self.t
        offset = self._prev and not infant_vocal
        self._prev = bool(infant_vocal)
        if offset and self._due is None and t > self._until:
            u = float(self.rng.random())
            lat = steps_of(self.latency.draw(self.rng), self.dt)
            answered = u < self.probability
            self.events.append({"step": t, "answered": answered, "latency_steps": lat})
            if answered:
                self._due = t + lat
        if self._due is not None and t >= self._due:
            self._due = None
            self._until = t + self.duration - 1
            self.onsets.append(t)
        return t <= self._until


class TimedSchedule:
    """Utterances of ``duration_steps`` starting at ``onsets`` (control steps from 0), blind to
    everything else."""

    def __init__(self, onsets, duration_steps: int):
        self.onsets = sorted(int(o) for o in onsets)
        self.duration = check_int("turn_taking", "utterance steps", duration_steps, 1)

    def reset(self, rng=None) -> None:
        self.t = -1
        self._k = 0
        self._until = -1

    def step(self, infant_vocal: bool = False) -> bool:
        """One control step; ``infant_vocal`` is ignored (kept for the same call as
        :meth:`ContingentSchedule.step`). Returns whether the caregiver speaks."""
        self.t += 1
        while self._k < len(self.onsets) and self.onsets[self._k] <= self.t:
            self._until = self.onsets[self._k] + self.duration - 1
            self._k += 1
        return self.t <= self._until


def yoked_onsets(n: int, steps: int, duration_steps: int, rng: np.random.Generator) -> list[int]:
    """``n`` utterance onsets in ``[0, steps)`` at uniformly random times that do not overlap
    (each ``duration_steps`` long, a gap of at least one step between them): the free room
    left is spread by sorted uniform draws. A ConfigError when they cannot fit."""
    n, steps = int(n), int(steps)
    free = steps - n * (duration_steps + 1)
    if n < 0 or free < 0:
        raise ConfigError(f"turn_taking: {n} utterances of {duration_steps} steps do not fit "
                          f"in {steps} steps; allowed: n * (utterance steps + 1) <= steps")
    gaps = np.sort(rng.integers(0, free + 1, size=n))
    return [int(g + k * (duration_steps + 1)) for k, g in enumerate(gaps)]


def poisson_onsets(rate_hz: float, steps: int, dt: float, duration_steps: int,
                   rng: np.random.Generator) -> list[int]:
    """Utterance onsets of a Poisson process of ``rate_hz`` onsets per second of silence (a
    Bernoulli draw per silent step, none during an utterance), over ``steps`` steps."""
    rate = check_number("turn_taking", "timer_rate_hz", rate_hz, 0.0, 10.0)
    p = 1.0 - math.exp(-rate * float(dt))
    draws = rng.random(int(steps))
    out, until = [], -1
    for t in range(int(steps)):
        if t > until and draws[t] < p:
            out.append(t)
            until = t + duration_steps - 1
    return out
