"""Sensorimotor delays by age: the published latencies of ``senses/data/delays.csv`` and the
defaults of ``AgentConfig(delays="developmental")``.

**Data** (sources in ``senses/data/README.md``), one row per channel and age, and an adult row
per channel:

* vision: the pattern-reversal visual evoked potential's first positive peak (P1/P100), about
  260 ms in neonates, falling fastest near 6 weeks and reaching the adult 104 ms at about 15
  weeks (3.5 months) for large patterns;
* touch and proprioception: the cortical median-nerve somatosensory evoked potential (N1/N20),
  38.9 ms in term newborns, 20 ms at 6 months, about 20 ms in adults (the median nerve carries
  both cutaneous and muscle afferents, so the two senses share the figures);
* vestibular: the adult vestibulo-ocular reflex latency, 8.6 ms, held at every age (no infant
  latency was found);
* motor: the adult corticomuscular latency to a hand muscle at rest, 23.3 ms, held at every age
  (no figure for the first year was found, and the literature disagrees on whether the central
  delay changes with age).

**Law**: :func:`developmental_delays` interpolates each channel's infant rows linearly in age
(months) and holds the first row's value before it and the last row's after it; an adult
(``age_months=None``) takes the adult row.
"""

from __future__ import annotations

import csv
from functools import lru_cache
from importlib import resources

import numpy as np

from . import SENSES

__all__ = ["CHANNELS", "delay_table", "developmental_delays"]

#: the delayed channels: each sense of the registry (:data:`mimo_social.senses.SENSES`, in its
#: order) and the motor command (the order of ``AgentConfig.delays``)
CHANNELS = (*SENSES, "motor")


@lru_cache(maxsize=None)
def delay_table() -> dict[str, dict]:
    """``{channel: {"ages": (months, ...), "ms": (...), "adult": ms}}`` from ``delays.csv``
    (infant rows sorted by age)."""
    with resources.files("mimo_social.senses").joinpath("data", "delays.csv").open() as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    table = {c: {"rows": [], "adult": None} for c in CHANNELS}
    for r in rows:
        channel, age, ms = r["channel"], r["age_months"].strip(), float(r["delay_ms"])
        if channel not in table:
            raise ValueError(f"delays.csv: unknown channel {channel!r}; known: {list(CHANNELS)}")
        if age == "adult":
            table[channel]["adult"] = ms
        else:
            table[channel]["rows"].append((float(age), ms))
    out = {}
    for channel, t in table.items():
        if not t["rows"] or t["adult"] is None:
            raise ValueError(f"delays.csv: channel {channel!r} needs infant rows and an adult row")
        ages, ms = zip(*sorted(t["rows"]))
        out[channel] = {"ages": ages, "ms": ms, "adult": t["adult"]}
    return out


def developmental_delays(age_months: float | None) -> dict[str, float]:
    """Each channel's delay in milliseconds at ``age_months`` (None: an adult), from
    :func:`delay_table`: linear in age between rows, the end rows held beyond them."""
    table = delay_table()
    if age_months is None:
        return {c: float(table[c]["adult"]) for c in CHANNELS}
    return {c: float(np.interp(float(age_months), table[c]["ages"], table[c]["ms"]))
            for c in CHANNELS}
