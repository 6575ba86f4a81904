"""What an infant's age change costs: at reset, in place (``env.set_age`` then ``reset``,
:mod:`mimo_social.core.regrow`), against building the env afresh at that age and resetting it.

For each configuration (the high five, two infants, and free play, one infant, each with mitten
or five-fingered hands, without or with the whole body's skin: :data:`AGE_CONFIGS`) the same
ages are visited in turn, ``repeats`` times:

* **change at reset**: ``set_age(age_months=a, motor_age_months=a)`` on one env, then
  ``reset(seed=0)``: the reset that applies the change, the reset itself included;
* **plain reset**: ``reset(seed=0)`` of that env without a change (what any reset costs);
* **fresh build**: ``high_five_v0.parallel_env(age_months=a, ...)`` then ``reset(seed=0)``
  (the skin's disk cache warm: every age is built once before the timed builds; the tables of
  each age are cached in the process too): the best case of a rebuild;
* **fresh build at a new age**: the same at an age built nowhere before (``a`` plus a few
  hundredths of a month, as a curriculum drawing ages from a continuum meets them), the skin's
  disk cache in an empty temporary folder: what a rebuild costs a growth curriculum (at most 3
  per configuration).

Each is timed with the process's CPU clock and the wall clock; reported: the median, the
smallest and the largest over the repeats, in milliseconds.
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from dataclasses import dataclass

from ..envs import free_play_v0, high_five_v0

__all__ = ["AgeConfig", "AGE_CONFIGS", "AGES", "measure", "format_results"]

#: the ages visited in turn (months)
AGES = (3.0, 6.0, 9.0, 12.0, 24.0, 30.0)


@dataclass(frozen=True)
class AgeConfig:
    """One configuration: the hands and the skin (``whole_skin``: the whole body's, else the
    task's default: the right hand's in the high five, none in free play); ``task``:
    ``"high_five"`` (two infants; the task places the pair and points their heads at each
    other by their sizes, on measuring copies it compiles: tasks/dyad.py) or ``"free_play"``
    (one infant, no planning)."""

    hands: str
    whole_skin: bool
    task: str = "high_five"

    @property
    def name(self) -> str:
        task = "high five" if self.task == "high_five" else "free play (1 infant)"
        return f"{task}, {self.hands}, " + ("whole-body skin" if self.whole_skin
                                            else "hand skin" if self.task == "high_five"
                                            else "no skin")

    def env(self, **kw):
        if self.whole_skin:
            kw["touch"] = True
        if self.task == "free_play":
            return free_play_v0.parallel_env(n_agents=1, hands=self.hands, **kw)
        return high_five_v0.parallel_env(hands=self.hands, **kw)


AGE_CONFIGS = tuple(AgeConfig(h, w, t) for t in ("high_five", "free_play")
                    for h in ("mitten", "five_fingers") for w in (False, True))


def _timed(fn) -> tuple[float, float]:
    c, w = time.process_time(), time.perf_counter()
    fn()
    return time.process_time() - c, time.perf_counter() - w


def _stats(samples: list[tuple[float, float]]) -> dict:
    out = {}
    for k, clock in enumerate(("cpu", "wall")):
        ms = [1000.0 * s[k] for s in samples]
        out[clock] = {"median": statistics.median(ms), "min": min(ms), "max": max(ms)}
    return out


def measure(configs=AGE_CONFIGS, repeats: int = 6, progress: bool = False) -> list[dict]:
    """One result per configuration: ``{"config", "change", "reset", "build", "new_age"}``,
    each timing ``{"cpu"|"wall": {"median", "min", "max"}}`` in ms over ``repeats`` visits
    (``new_age``: at most 3)."""
    before = os.environ.get(CACHE_VARIABLE)
    with tempfile.TemporaryDirectory() as cache:
        os.environ[CACHE_VARIABLE] = cache
        try:
            return _measure(configs, repeats, progress)
        finally:
            if before is None:
                os.environ.pop(CACHE_VARIABLE, None)
            else:
                os.environ[CACHE_VARIABLE] = before


#: the environment variable that moves the skin's disk cache (senses/skin.py)
CACHE_VARIABLE = "MIMO_SOCIAL_CACHE"


def _measure(configs, repeats: int, progress: bool) -> list[dict]:
    results = []
    for c, cfg in enumerate(configs):
        env = cfg.env()
        env.reset(seed=0)
        for age in AGES:                      # every age's skin in the (temporary) disk cache
            cfg.env(age_months=age).close()
        change, plain, build, new_age = [], [], [], []
        for r in range(repeats):
            age = AGES[r % len(AGES)]

            def grow(age=age):
                env.set_age(age_months=age, motor_age_months=age)
                env.reset(seed=0)
            change.append(_timed(grow))
            plain.append(_timed(lambda: env.reset(seed=0)))

            def fresh(age=age):
                other = cfg.env(age_months=age)
                other.reset(seed=0)
                other.close()
            build.append(_timed(fresh))
            if r < 3:
                new_age.append(_timed(lambda: fresh(age + 0.1 * c + 0.01 * (r + 1))))
        env.close()
        row = {"config": cfg.name, "change": _stats(change), "reset": _stats(plain),
               "build": _stats(build), "new_age": _stats(new_age), "repeats": repeats}
        results.append(row)
        if progress:
            print(f"  {cfg.name}: change {row['change']['cpu']['median']:.1f} ms CPU, build "
                  f"{row['build']['cpu']['median']:.0f} ms CPU", flush=True)
    return results


def format_results(results: list[dict]) -> str:
    """A table: per configuration the medians (min-max) of each, CPU and wall clock, ms."""
    def cell(t):
        return f"{t['median']:.1f} ({t['min']:.1f}-{t['max']:.1f})"

    lines = ["| configuration | change at reset, CPU ms | wall ms | plain reset, CPU ms | "
             "fresh build + reset, CPU ms | wall ms | at a new age, CPU ms | wall ms |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in results:
        lines.append(f"| {r['config']} | {cell(r['change']['cpu'])} | "
                     f"{cell(r['change']['wall'])} | {cell(r['reset']['cpu'])} | "
                     f"{cell(r['build']['cpu'])} | {cell(r['build']['wall'])} | "
                     f"{cell(r['new_age']['cpu'])} | {cell(r['new_age']['wall'])} |")
    return "\n".join(lines)
