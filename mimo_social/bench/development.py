"""What the developing body costs: build time per age (and for the adult), and the cost per step
of sensorimotor delays and of the acuity filter, each measured against the same env without it.

``mimo-social bench development`` runs it (:mod:`mimo_social.cli.bench_development`); the numbers
go to BENCHMARKS.md. Variants that are compared run in turns of 100 steps under the same smooth
random actions (:func:`mimo_social.bench.vision_cost.bench_env`; 100 untimed steps each first),
so a change of the machine's speed touches them alike; each figure is the mean over every step.

A comparison (``+x % vs base``) is a ratio of two timings, and one turn's timing moves by tens of
percent on a shared machine (a scheduler's slice, another process's burst), far more than the
timer's resolution. So each comparison also gives the noise of that ratio turn by turn (two
standard errors of the mean of the per-turn ratios, ``+-``), and it needs at least
:data:`MIN_TURNS` turns of each configuration: with a per-turn spread of 15 % that bounds the
noise near 10 %; fewer turns give no comparison (the ms per step are still shown). The delay
configurations get ``sim_seconds`` each and the acuity ones two thirds of it, so
:func:`min_sim_seconds` (15 s at 10 ms a step, the default) is what gives every comparison its
turns. (From 0.06 simulated s, one turn of 6 steps, delays once read as making steps 48-53 %
faster.)
"""

from __future__ import annotations

import math
import time
from typing import Sequence

import numpy as np

from ..body.tables import load_body
from ..core.config import PhysicsConfig
from ..core.random_actions import random_action_block
from ..envs import free_play_v0
from ..senses import SENSES
from .vision_cost import TURN_STEPS, bench_env

__all__ = ["BUILD_BODIES", "ALL_DELAYS_MS", "MIN_TURNS", "build_times", "delay_cost",
           "acuity_cost", "measure", "format_results", "min_sim_seconds", "turns_of",
           "compare_turns", "hearing_cost", "format_hearing", "HEARING_CONFIGS",
           "hearing_paths", "format_hearing_paths"]

#: turns of :data:`~mimo_social.bench.vision_cost.TURN_STEPS` steps a comparison needs
MIN_TURNS = 10
#: the acuity configurations run this share of ``sim_seconds``
ACUITY_SHARE = 2 / 3

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


def _control_dt() -> float:
    return PhysicsConfig().timestep * PhysicsConfig().frame_skip


def turns_of(sim_seconds: float) -> int:
    """Turns of :data:`TURN_STEPS` steps that ``sim_seconds`` simulated seconds make (the last
    one may be shorter)."""
    return math.ceil(int(round(sim_seconds / _control_dt())) / TURN_STEPS)


def min_sim_seconds() -> float:
    """The fewest ``sim_seconds`` of :func:`measure` that give every comparison (the acuity
    ones run :data:`ACUITY_SHARE` of it) :data:`MIN_TURNS` turns."""
    return round(MIN_TURNS * TURN_STEPS * _control_dt() / ACUITY_SHARE, 6)


def compare_turns(turn_s: Sequence[float], base_turn_s: Sequence[float]) -> dict:
    """``turns`` and ``noise_pct``: two standard errors of the mean of the per-turn ratios of
    ``turn_s`` over ``base_turn_s`` (the same turns of the same steps), in percent; NaN with
    fewer than two turns."""
    r = np.asarray(turn_s, float) / np.asarray(base_turn_s, float)
    noise = 200 * float(np.std(r, ddof=1)) / math.sqrt(len(r)) if len(r) > 1 else math.nan
    return {"turns": len(r), "noise_pct": noise}


def _ms_per_step(configs: dict[str, dict], sim_seconds: float) -> tuple[dict, dict]:
    """Milliseconds per env step of each free-play configuration, measured by
    :func:`~mimo_social.bench.vision_cost.bench_env` (the configurations take turns of 100
    steps under the same smooth random actions), and each one's seconds per turn."""
    rows = bench_env(configs, sim_seconds)
    return ({r["config"]: 1e3 * r["total"] * _control_dt() for r in rows},
            {r["config"]: r["turn_s"] for r in rows})


def delay_cost(sim_seconds: float = 15.0) -> tuple[dict, dict]:
    """ms per step of two infants with touch, no delays vs every sense delayed 100 ms
    (:data:`ALL_DELAYS_MS`), and with vision (64x64 eyes) too; and the seconds of each turn."""
    eyes = {"width": 64, "height": 64}
    return _ms_per_step({
        "touch": dict(n_agents=2, touch=True),
        "touch + delays": dict(n_agents=2, touch=True, delays=ALL_DELAYS_MS),
        "touch + vision": dict(n_agents=2, touch=True, vision=eyes),
        "touch + vision + delays": dict(n_agents=2, touch=True, vision=eyes,
                                        delays=ALL_DELAYS_MS)}, sim_seconds)


def acuity_cost(sizes: Sequence[int] = (128, 256), sim_seconds: float = 10.0
                ) -> tuple[dict, dict]:
    """ms per step of two newborns with vision, acuity off vs on (the newborn's blur), per eye
    image size; and the seconds of each turn."""
    return _ms_per_step({
        f"{size}x{size} eyes, acuity {'on' if acuity else 'off'}": dict(
            n_agents=2, age_months=0.0,
            vision={"width": size, "height": size, "acuity": acuity})
        for size in sizes for acuity in (None, "age")}, sim_seconds)


#: the hearing comparisons: two infants without vision, voices on, audition off vs on; with
#: the default senses (proprioception, vestibular: the cheapest step) and with touch too
HEARING_CONFIGS = {
    "2 infants, voice": dict(n_agents=2, voice=True),
    "2 infants, voice + audition": dict(n_agents=2, voice=True, audition=True),
    "2 infants, touch, voice": dict(n_agents=2, voice=True, touch=True),
    "2 infants, touch, voice + audition": dict(n_agents=2, voice=True, touch=True,
                                               audition=True)}


def hearing_cost(sim_seconds: float = 15.0, seed: int = 0) -> dict:
    """ms per step of two infants with voices (no vision), audition off vs on, in turns of
    :data:`TURN_STEPS` steps under the same smooth random actions and sounds
    (:func:`~mimo_social.core.random_actions.random_action_block`, 100 untimed steps first);
    ``audition_ms``: the audition's own ms per step (``env.timing``); ``comparison``: turns
    and noise (:func:`compare_turns`)."""
    runs = {}
    for name, kw in HEARING_CONFIGS.items():
        env = free_play_v0.parallel_env(max_steps=10 ** 9, **kw)
        env.reset(seed=seed)
        n = int(round(sim_seconds / env.dt))
        runs[name] = {"env": env, "acts": random_action_block(env, 100 + n, seed), "n": n,
                      "k": 0, "turns": []}
    for r in runs.values():
        for a in r["acts"][:100]:
            r["env"].step(a)
        r["env"].timing.update(dict.fromkeys(r["env"].timing, 0.0))
    while any(r["k"] < r["n"] for r in runs.values()):
        for r in runs.values():
            stop = min(r["n"], r["k"] + TURN_STEPS)
            env, acts = r["env"], r["acts"]
            t0 = time.perf_counter()
            for k in range(100 + r["k"], 100 + stop):
                env.step(acts[k])
            r["turns"].append(time.perf_counter() - t0)
            r["k"] = stop
    ms = {name: 1e3 * sum(r["turns"]) / r["n"] for name, r in runs.items()}
    comparisons = {}
    for name, r in runs.items():
        base = name.replace(" + audition", "")
        if base != name:
            comparisons[name] = {
                "base": base, "audition_ms": 1e3 * r["env"].timing["audition"] / r["n"],
                **compare_turns(r["turns"], runs[base]["turns"])}
    return {"ms_per_step": ms, "comparisons": comparisons}


def format_hearing(h: dict) -> str:
    """A Markdown table of :func:`hearing_cost`."""
    ms = h["ms_per_step"]
    lines = ["Hearing (two infants, no vision, voices on), ms per step (+-: two standard errors "
             "of the per-turn ratio; audition: its own time in env.timing, as a share of the "
             "step without it):", "", "| env | ms/step |", "| --- | --- |"]
    for name, t in ms.items():
        c = h["comparisons"].get(name)
        extra = "" if c is None else (
            f" ({100 * (t / ms[c['base']] - 1):+.1f} % +- {c['noise_pct']:.1f} % vs "
            f"{c['base']}, {c['turns']} turns; audition {c['audition_ms']:.3f} ms = "
            f"{100 * c['audition_ms'] / ms[c['base']]:.1f} %)")
        lines.append(f"| {name} | {t:.3f}{extra} |")
    return "\n".join(lines)


def hearing_paths(agents: Sequence[int] = (2, 3, 4, 6, 8), steps: int = 600,
                  seed: int = 0) -> list[dict]:
    """The audition update's µs per step inside the env (right after the physics), computed
    with Python floats and with numpy arrays (``AuditionSystem.scalar``), per number of agents
    in free play (every agent voiced and hearing: agents^2 pairs), the two taking turns of
    :data:`TURN_STEPS` steps under the same random actions and sounds, 100 untimed steps
    first; ``default``: the way the env takes for that many pairs."""
    rows = []
    for n in agents:
        env = free_play_v0.parallel_env(max_steps=10 ** 9, n_agents=n, voice=True,
                                        audition=True)
        env.reset(seed=seed)
        system = env.unwrapped.systems["audition"]
        default = system.scalar
        acts = random_action_block(env, 100 + 2 * steps, seed)
        for a in acts[:100]:
            env.step(a)
        spent = {True: 0.0, False: 0.0}
        update = type(system).update

        def timed(model, data):
            t = time.perf_counter()
            update(system, model, data)
            spent[system.scalar] += time.perf_counter() - t

        system.update = timed
        for k in range(100, 100 + 2 * steps, TURN_STEPS):
            system.scalar = (k // TURN_STEPS) % 2 == 0
            for a in acts[k:k + TURN_STEPS]:
                env.step(a)
        del system.update
        system.scalar = default
        rows.append({"agents": n, "pairs": len(system.listeners) * len(system.sources),
                     "floats_us": 1e6 * spent[True] / steps,
                     "arrays_us": 1e6 * spent[False] / steps,
                     "default": "floats" if default else "arrays"})
        env.close()
    return rows


def format_hearing_paths(rows: list[dict]) -> str:
    """A Markdown table of :func:`hearing_paths`."""
    lines = ["The audition update inside the step, µs, Python floats vs numpy arrays:", "",
             "| agents | pairs | floats | arrays | the env takes |",
             "| --- | --- | --- | --- | --- |"]
    lines += [f"| {r['agents']} | {r['pairs']} | {r['floats_us']:.1f} | {r['arrays_us']:.1f} | "
              f"{r['default']} |" for r in rows]
    return "\n".join(lines)


def _delay_base(name: str) -> str:
    return name.replace(" + delays", "")


def _acuity_base(name: str) -> str:
    return name.replace("acuity on", "acuity off")


def measure(sim_seconds: float = 15.0, repeats: int = 3) -> dict:
    """Every figure of this module, as a dict for JSON (``sim_seconds`` per delay
    configuration, two thirds of it per acuity one): ``build``, ``delays`` and ``acuity`` (ms
    per step) and ``comparisons`` (per compared configuration: its base, ``turns`` and
    ``noise_pct``, :func:`compare_turns`)."""
    delays, delay_turns = delay_cost(sim_seconds)
    acuity, acuity_turns = acuity_cost(sim_seconds=sim_seconds * ACUITY_SHARE)
    comparisons = {}
    for turns, base_of in ((delay_turns, _delay_base), (acuity_turns, _acuity_base)):
        for name, t in turns.items():
            base = base_of(name)
            if base != name:
                comparisons[name] = {"base": base, **compare_turns(t, turns[base])}
    return {"build": build_times(repeats=repeats), "delays": delays, "acuity": acuity,
            "comparisons": comparisons, "min_turns": MIN_TURNS}


def _relative(costs: dict[str, float], comparisons: dict) -> list[str]:
    lines = []
    for name, ms in costs.items():
        c = comparisons.get(name)
        if c is None:
            extra = ""
        elif c["turns"] < MIN_TURNS:
            extra = (f" (no comparison with {c['base']}: {c['turns']} turn(s) of up to "
                     f"{TURN_STEPS} steps, fewer than {MIN_TURNS}; give --sim-seconds >= "
                     f"{min_sim_seconds():g})")
        else:
            extra = (f" ({100 * (ms / costs[c['base']] - 1):+.1f} % +- {c['noise_pct']:.1f} % "
                     f"vs {c['base']})")
        lines.append(f"| {name} | {ms:.2f}{extra} |")
    return lines


def format_results(results: dict) -> str:
    """Markdown tables of :func:`measure`'s results."""
    lines = ["Build time per body (tables from CSV, cache cleared; one-agent free-play env from "
             "cached tables), median ms:", "", "| hands | body | tables | env |",
             "| --- | --- | --- | --- |"]
    for r in results["build"]:
        lines.append(f"| {r['hands']} | {r['body']} | {r['tables_ms']:.1f} | {r['env_ms']:.1f} |")
    lines += ["", "Delays (every sense 100 ms), two infants, ms per step (+-: two standard "
              "errors of the per-turn ratio):", "", "| env | ms/step |", "| --- | --- |"]
    lines += _relative(results["delays"], results["comparisons"])
    lines += ["", "Acuity filter (newborns, age 0), two infants, ms per step:", "",
              "| env | ms/step |", "| --- | --- |"]
    lines += _relative(results["acuity"], results["comparisons"])
    return "\n".join(lines)
