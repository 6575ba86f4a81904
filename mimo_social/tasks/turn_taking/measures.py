"""The turn-taking paradigm's measures: blocks of a contingent, a non-contingent (as many
utterances as the block's contingent episode, at random times) and a replay episode (the
contingent episode's utterances at the same steps); per condition the infant's vocalisations
per minute, the share of speech-like ones, the caregiver's response latency and answered
share, the turns and their mean gap (mean and sd over blocks, from each episode's last learner
info); and the paradigm's effect for any policy: per block, the contingent episode's measure
minus the non-contingent one's and minus the replay's.

:func:`run` is what ``mimo-social paradigm turn_taking`` calls (the catalogue entry's
``measures``), :func:`rows` its lines in the side-by-side table, :func:`effects` the effect
(the paradigm command reports it), :func:`latencies` the caregiver's answer latencies of
contingent episodes (s).
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

from ...core.episodes import run_episodes
from ...partners.policy_adapter import as_learner
from ...util.checks import check_int
from ..common import (condition_effects, condition_means, condition_rows,
                      format_condition_effects)
from .task import CONDITIONS, MEASURES, scripted_env

__all__ = ["UNIT", "AGENT", "EFFECT_MEASURES", "summarize", "run", "rows", "effects",
           "format_effects", "latencies"]

#: what one of :func:`run`'s ``episodes`` is: a block of one episode per condition
UNIT = "blocks (contingent, noncontingent, replay)"
#: the learner: the infant; the caregiver is scripted
AGENT = "infant_0"
#: the measures whose contingent-minus-other difference per block is the paradigm's effect
EFFECT_MEASURES = ("infant_rate_per_min", "speech_like_fraction", "answered_fraction", "turns")


def summarize(finals: Sequence[Mapping[str, Any]]) -> dict[str, dict[str, tuple[float, float]]]:
    """Per condition, each :data:`MEASURES` entry's mean and sd over episodes, from each
    episode's last-step info (its ``condition`` code says the condition)."""
    return condition_means(finals, CONDITIONS, MEASURES)


def _blocks(env, learner, episodes: int, seed: int) -> list[dict]:
    """Each episode's last learner info, block by block (contingent, noncontingent, replay),
    block ``b`` reset with seed ``seed + b``, the learner with ``[seed + b, k]`` for the
    block's k-th condition."""
    task = env.unwrapped.task
    finals = []
    for block in range(int(episodes)):
        for k, cond in enumerate(CONDITIONS):
            task.set_condition(cond)
            [episode] = run_episodes(env, {AGENT: learner}, 1, seed + block,
                                     policy_seeds=[[seed + block, k]])
            finals.append(dict(episode.last_infos[AGENT]))
    task.set_condition("contingent")
    return finals


def run(learner, episodes: int, seed: int, env) -> dict:
    """``learner`` in ``episodes`` blocks of ``env`` (the scripted form, which the caller made
    and closes): :func:`summarize` of the episodes."""
    return summarize(_blocks(env, learner, episodes, seed))


def rows(summaries: Sequence[Mapping]) -> list[tuple[str, list[str]]]:
    """The table's lines for :func:`run`'s summaries, a cell per learner: per condition each
    measure (mean +- sd over blocks)."""
    return condition_rows(summaries, CONDITIONS, MEASURES)


def effects(policy, episodes: int = 10, seed: int = 0,
            env_kwargs: Mapping[str, Any] | None = None, deterministic: bool = True) -> dict:
    """``policy`` (:func:`~mimo_social.partners.policy_adapter.as_learner`) as ``infant_0`` in
    ``episodes`` blocks of the scripted env made with ``env_kwargs``; returns ``{"episodes":
    n, "contingent_minus_noncontingent": {measure: (mean, sd)},
    "contingent_minus_replay": {...}, "summary": summarize}`` over blocks, for
    :data:`EFFECT_MEASURES`."""
    episodes = check_int("effects", "episodes", episodes, 1)
    env = scripted_env(**dict(env_kwargs or {}))
    try:
        finals = _blocks(env, as_learner(policy, deterministic), episodes, seed)
    finally:
        env.close()
    out = condition_effects(finals, episodes, CONDITIONS, EFFECT_MEASURES)
    out["summary"] = summarize(finals)
    return out


def format_effects(result: Mapping) -> str:
    """:func:`effects`' result as a markdown table: a row per measure, a column per
    difference (mean +- sd over blocks)."""
    return format_condition_effects(result, "turn-taking", CONDITIONS, EFFECT_MEASURES)


def latencies(episodes: int = 5, seed: int = 0, controller: Any = None,
              env_kwargs: Mapping[str, Any] | None = None) -> list[float]:
    """The caregiver's answer latencies (s, from the offset of the infant's vocalisation to
    its answer's onset as the caregiver scheduled it: the drawn latency rounded to control
    steps; the caregiver hears the offset one control step after it happens) of ``episodes``
    contingent episodes with ``controller`` (default: the scripted infant)."""
    from .controller import TurnTakingInfantController
    learner = TurnTakingInfantController() if controller is None else controller
    env = scripted_env(**dict(env_kwargs or {}))
    try:
        out = []
        care = next(iter(env.partners.values()))
        dt = float(env.unwrapped.dt)
        for e in range(int(episodes)):
            run_episodes(env, {AGENT: learner}, 1, seed + e)
            out += [ev["latency_steps"] * dt for ev in care.events if ev["answered"]]
        return out
    finally:
        env.close()
