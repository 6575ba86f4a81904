"""What the developing body costs: build time per age (and for the adult), and the cost per step
of sensorimotor delays and of the acuity filter, each measured against the same env without it.

``mimo-social bench development`` runs it (:mod:`mimo_social.cli.bench_development`); the numbers
go to BENCHMARKS.md. Variants that are compared run in turns of 100 steps under the same smooth
random actions (:func:`mimo_social.bench.vision_cost.bench_env`), so a change of the machine's
speed touches them alike; each figure is the mean over every step.
"""

from __future__ import annotations

import time
from typing import Callable, Sequence

import numpy as np

from ..body.tables import load_body
from ..core.config import PhysicsConfig
from ..envs import free_play_v0
from ..senses import SENSES
from .vision_cost import bench_env

__all__ = ["BUILD_BODIES", "ALL_DELAYS_MS", "build_times", "delay_cost",
           "acuity_cost", "measure", "format_results"]

#: The bodies whose build time is measured: (label, agent settings).
BUILD_BODIES = (
    ("0 months", {"age_months": 0.0}),
    ("6 months", {"age_months": 6.0}),
    ("12 months", {"age_months": 12.0}),
    ("18 months (published)", {}),
    ("24 months", {"age_months": 24.0}),
    ("adult", {"body": "adult"}),
)

#: Every sense delayed by 100 ms (10 control steps at the default 10 ms control step). The motor
#: command is left undelayed: a motor delay changes the trajectory, so its steps would compare
#: different physics, not the cost of the buffers.
ALL_DELAYS_MS = dict.fromkeys(SENSES, 100.0)


def build_times(hands: Sequence[str] = ("mitten", "five_fingers"), repeats: int = 3) -> list[dict]:
    """Per body of :data:`BUILD_BODIES` and hand version: seconds to compute its tables from the
    CSV files (cache cleared first) and seconds to build a one-agent free-play env from cached
    tables (the MjSpec, its compile, the senses), median of ``repeats``."""
    out = []
    for hand in hands:
        for label, settings in BUILD_BODIES:
            tables_s, env_s = [], []
            for _ in range(repeats):
                load_body.cache_clear()
                t0 = time.perf_counter()
                load_body(hand, age_months=settings.get("age_months"),
                          body=settings.get("body", "infant"))
                tables_s.append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                env = free_play_v0.parallel_env(n_agents=1, hands=hand, **settings)
                env_s.append(time.perf_counter() - t0)
                env.close()
            out.append({"hands": hand, "body": label, "tables_ms": 1e3 * float(np.median(tables_s)),
                        "env_ms": 1e3 * float(np.median(env_s))})
    return out


def _ms_per_step(configs: dict[str, dict], sim_seconds: float) -> dict[str, float]:
    """Milliseconds per env step of each free-play configuration, measured by
    :func:`~mimo_social.bench.vision_cost.bench_env` (the configurations take turns of 100
    steps under the same smooth random actions)."""
    dt = PhysicsConfig().timestep * PhysicsConfig().frame_skip
    return {r["config"]: 1e3 * r["total"] * dt for r in bench_env(configs, sim_seconds)}


def delay_cost(sim_seconds: float = 15.0) -> dict[str, float]:
    """ms per step of two infants with touch, no delays vs every sense delayed 100 ms
    (:data:`ALL_DELAYS_MS`), and with vision (64x64 eyes) too."""
    eyes = {"width": 64, "height": 64}
    return _ms_per_step({
        "touch": dict(n_agents=2, touch=True),
        "touch + delays": dict(n_agents=2, touch=True, delays=ALL_DELAYS_MS),
        "touch + vision": dict(n_agents=2, touch=True, vision=eyes),
        "touch + vision + delays": dict(n_agents=2, touch=True, vision=eyes,
                                        delays=ALL_DELAYS_MS)}, sim_seconds)


def acuity_cost(sizes: Sequence[int] = (128, 256), sim_seconds: float = 10.0) -> dict[str, float]:
    """ms per step of two newborns with vision, acuity off vs on (the newborn's blur), per eye
    image size."""
    return _ms_per_step({
        f"{size}x{size} eyes, acuity {'on' if acuity else 'off'}": dict(
            n_agents=2, age_months=0.0,
            vision={"width": size, "height": size, "acuity": acuity})
        for size in sizes for acuity in (None, "age")}, sim_seconds)


def measure(sim_seconds: float = 15.0, repeats: int = 3) -> dict:
    """Every figure of this module, as a dict for JSON (``sim_seconds`` per delay
    configuration, two thirds of it per acuity one)."""
    return {"build": build_times(repeats=repeats), "delays": delay_cost(sim_seconds),
            "acuity": acuity_cost(sim_seconds=sim_seconds * 2 / 3)}


def _relative(costs: dict[str, float], base_of: Callable[[str], str]) -> list[str]:
    lines = []
    for name, ms in costs.items():
        base = base_of(name)
        extra = "" if base == name else f" ({100 * (ms / costs[base] - 1):+.1f} % vs {base})"
        lines.append(f"| {name} | {ms:.2f}{extra} |")
    return lines


def format_results(results: dict) -> str:
    """Markdown tables of :func:`measure`'s results."""
    lines = ["Build time per body (tables from CSV, cache cleared; one-agent free-play env from "
             "cached tables), median ms:", "", "| hands | body | tables | env |",
             "| --- | --- | --- | --- |"]
    for r in results["build"]:
        lines.append(f"| {r['hands']} | {r['body']} | {r['tables_ms']:.1f} | {r['env_ms']:.1f} |")
    lines += ["", "Delays (every sense 100 ms), two infants, ms per step:", "",
              "| env | ms/step |", "| --- | --- |"]
    lines += _relative(results["delays"], lambda n: n.replace(" + delays", ""))
    lines += ["", "Acuity filter (newborns, age 0), two infants, ms per step:", "",
              "| env | ms/step |", "| --- | --- |"]
    lines += _relative(results["acuity"], lambda n: n.replace("acuity on", "acuity off"))
    return "\n".join(lines)
