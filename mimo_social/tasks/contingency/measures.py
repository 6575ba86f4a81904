"""The contingency paradigm's measures: blocks of a live, a replay (of that block's live
episode) and a non-contingent episode; per condition the learner's smile rate, the share of the
steps smiling, gaze on the caregiver's face, response and baseline rates, the contingency index
and shared smiling (mean and sd over blocks), from each episode's last learner info; and the
paradigm's effect for any policy.

:func:`run` is what ``mimo-social paradigm contingency`` calls for each learner (the catalogue
entry's ``measures``); :func:`rows` its lines in the side-by-side table. :func:`effects` runs a
policy (a scripted partner, a function of the observation, or an SB3 model: :func:`as_learner`)
for seeded blocks and returns the live-minus-replay and live-minus-non-contingent differences
of each block's measures (:data:`EFFECT_MEASURES`), mean and sd over blocks;
:func:`format_effects` prints them.
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

from ...core.episodes import run_episodes
from ...partners.policy_adapter import as_learner
from ...util.checks import ConfigError, check_choice, check_int
from .controller import ContingencyDetectorController
from ..common import (condition_effects, condition_means, condition_rows,
                      format_condition_effects)
from .task import CONDITIONS, MEASURES, scripted_env

__all__ = ["UNIT", "AGENT", "EFFECT_MEASURES", "summarize", "condition_summary",
           "format_summary", "run", "rows", "as_learner", "effects", "format_effects"]

#: what one of :func:`run`'s ``episodes`` is: a block of one episode per condition
UNIT = "blocks (live, replay, non-contingent)"
#: the learner: the infant; the caregiver is scripted
AGENT = "infant_0"


def summarize(finals: Sequence[Mapping[str, Any]]) -> dict[str, dict[str, tuple[float, float]]]:
    """Per condition, each :data:`MEASURES` entry's mean and sd over episodes, from each
    episode's last-step info (its ``condition`` code says the condition)."""
    return condition_means(finals, CONDITIONS, MEASURES)


def condition_summary(episodes: int = 5, seed: int = 0, controller: Any = None,
                      conditions: Sequence[str] = CONDITIONS,
                      env_kwargs: Mapping[str, Any] | None = None) -> dict:
    """Blocks of one episode per condition (``conditions``, in that order; "replay" needs a
    "live" before it in a block and replays it), ``episodes`` blocks, the env (the scripted
    form, :func:`~mimo_social.tasks.contingency.task.scripted_env`) reset with seed
    ``seed + block``; the learner is ``controller`` (a policy for ``infant_0``: ``act(env,
    agent, obs)`` and optionally ``reset(env, agent, rng)``; by default
    :class:`~mimo_social.tasks.contingency.controller.ContingencyDetectorController`), reset
    with a generator seeded ``[seed + block, k]`` for the block's k-th condition, so that it
    does not repeat its live actions in the replay. Returns :func:`summarize` of the
    episodes."""
    conditions = tuple(conditions)
    for c in conditions:
        check_choice("contingency", "conditions", c, CONDITIONS)
    if "replay" in conditions and ("live" not in conditions
                                   or conditions.index("live") > conditions.index("replay")):
        raise ConfigError("contingency: conditions list 'replay' without a 'live' before it; "
                          "allowed: e.g. ('live', 'replay', 'non_contingent')")
    learner = ContingencyDetectorController() if controller is None else controller
    env = scripted_env(**dict(env_kwargs or {}))
    try:
        return summarize(_blocks(env, learner, episodes, seed, conditions))
    finally:
        env.close()


def _blocks(env, learner, episodes: int, seed: int, conditions: Sequence[str]) -> list[dict]:
    """Each episode's last learner info, block by block, in ``env``, the scripted form
    (conditions checked; see :func:`condition_summary`)."""
    task = env.unwrapped.task
    finals = []
    for block in range(int(episodes)):
        for k, cond in enumerate(conditions):
            task.set_condition(cond)
            [episode] = run_episodes(env, {AGENT: learner}, 1, seed + block,
                                     policy_seeds=[[seed + block, k]])
            finals.append(dict(episode.last_infos[AGENT]))
    return finals


def run(learner, episodes: int, seed: int, env) -> dict:
    """``learner`` in ``episodes`` blocks of live, replay and non-contingent episodes of
    ``env`` (the scripted form, :func:`~mimo_social.tasks.contingency.task.scripted_env`, which
    the caller made and closes), as :func:`condition_summary`."""
    return summarize(_blocks(env, learner, episodes, seed, CONDITIONS))


def format_summary(table: Mapping[str, Mapping[str, tuple[float, float]]]) -> str:
    """A markdown table: one row per measure, one column per condition (mean +- sd)."""
    conds = list(table)
    lines = ["| measure | " + " | ".join(conds) + " |", "|---" * (len(conds) + 1) + "|"]
    for m in ("episodes", *MEASURES):
        cells = []
        for c in conds:
            mean, sd = table[c][m]
            cells.append(f"{mean:.0f}" if m == "episodes" else f"{mean:.3f} +- {sd:.3f}")
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def rows(summaries: Sequence[Mapping]) -> list[tuple[str, list[str]]]:
    """The table's lines for :func:`run`'s summaries, a cell per learner: per condition each
    measure (mean +- sd over blocks)."""
    return condition_rows(summaries, CONDITIONS, MEASURES)


# -- the paradigm's effect, for any policy ------------------------------------------------------
#: the measures whose live-minus-other difference per block is the paradigm's effect
EFFECT_MEASURES = ("smiling_fraction", "learner_smile_rate", "gaze_fraction",
                   "contingency_index", "shared_fraction")


def effects(policy, episodes: int = 10, seed: int = 0,
            env_kwargs: Mapping[str, Any] | None = None, deterministic: bool = True) -> dict:
    """``policy`` (:func:`as_learner`) as ``infant_0`` in ``episodes`` blocks of a live, a
    replay (of that block's live episode) and a non-contingent episode of the scripted
    contingency (:func:`~mimo_social.tasks.contingency.task.scripted_env` with ``env_kwargs``;
    block ``b`` reset with seed ``seed + b``, as :func:`condition_summary`). Returns
    ``{"episodes": n, "live_minus_replay": {measure: (mean, sd)}, "live_minus_non_contingent":
    {...}, "summary": summarize}``: per block, each :data:`EFFECT_MEASURES` entry of the live
    episode minus that of the replay (Murray and Trevarthen's double video: more smiling and
    gaze at the face live) or of the non-contingent episode, mean and sd over blocks."""
    episodes = check_int("effects", "episodes", episodes, 1)
    env = scripted_env(**dict(env_kwargs or {}))
    try:
        finals = _blocks(env, as_learner(policy, deterministic), episodes, seed, CONDITIONS)
    finally:
        env.close()
    out = condition_effects(finals, episodes, CONDITIONS, EFFECT_MEASURES)
    out["summary"] = summarize(finals)
    return out


def format_effects(result: Mapping) -> str:
    """:func:`effects`' result as a markdown table: a row per measure, a column per
    difference (mean +- sd over blocks)."""
    return format_condition_effects(result, "contingency", CONDITIONS, EFFECT_MEASURES)
