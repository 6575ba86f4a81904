"""The imitation paradigm's measures: per demonstrated act (and over all), the learner's
success rate, mean return and which act it answered with, from each episode's last learner
info.

:func:`run` is what ``mimo-social paradigm imitation`` calls for each learner (the catalogue
entry's ``measures``); :func:`rows` its lines in the side-by-side table.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np

from ...core.episodes import run_episodes
from .task import ACTIONS

__all__ = ["UNIT", "AGENT", "records", "summary", "run", "rows"]

#: what one of :func:`run`'s ``episodes`` is
UNIT = "episodes"
#: the learner: the infant; the demonstrator is scripted
AGENT = "infant_0"


def records(env, learner, episodes: int, seed: int = 0) -> list[dict]:
    """The learner's last infos, each with its ``return``, of ``episodes`` episodes of a
    one-learner ``env`` (``imitation_v0.scripted_env``) reset with seeds ``seed``, ``seed + 1``,
    ...; ``learner``: a policy for ``infant_0`` (``act(env, agent, obs)``, optionally
    ``reset(env, agent, rng)``, the generator seeded with the episode's seed)."""
    return [{**e.last_infos[AGENT], "return": e.returns[AGENT]}
            for e in run_episodes(env, {AGENT: learner}, episodes, seed)]


def summary(records) -> dict:
    """Per demonstrated action (and ``"all"``): the episodes, the success rate, the mean
    return and how often each response came (``"none"`` for no act in the turn,
    ``"several"`` for outcomes at once), from the learner's last infos of each episode
    (:func:`run_episodes`)."""
    names = list(ACTIONS) + ["several"]
    out: dict = {}
    for key in list(ACTIONS) + ["all"]:
        rows = [r for r in records if key == "all" or ACTIONS[int(r["demonstrated"])] == key]
        if not rows:
            continue
        responses = {n: 0 for n in names + ["none"]}
        for r in rows:
            k = int(r["response"])
            responses["none" if k < 0 else names[k]] += 1
        out[key] = {"episodes": len(rows),
                    "success": float(np.mean([bool(r["is_success"]) for r in rows])),
                    "return": float(np.mean([r.get("return", 0.0) for r in rows])),
                    "responses": responses}
    return out


def run(learner, episodes: int, seed: int, env) -> dict:
    """``learner`` in ``episodes`` episodes of ``env``, the scripted imitation env
    (:func:`~mimo_social.tasks.imitation.task.scripted_env`, which the caller made and closes):
    :func:`summary` of its :func:`records`."""
    return summary(records(env, learner, episodes, seed))


def rows(summaries: Sequence[Mapping]) -> list[tuple[str, list[str]]]:
    """The table's lines for :func:`run`'s summaries, a cell per learner: per demonstrated act
    (and all) the success rate, the mean return and the responses."""
    keys = [k for k in summaries[0] if all(k in s for s in summaries)]
    out = []
    for key in keys:
        out.append((f"{key}: success", [f"{100 * s[key]['success']:.0f} % of "
                                        f"{s[key]['episodes']}" for s in summaries]))
        out.append((f"{key}: return", [f"{s[key]['return']:.2f}" for s in summaries]))
        out.append((f"{key}: responses",
                    [", ".join(f"{n} {c}" for n, c in s[key]["responses"].items() if c)
                     for s in summaries]))
    return out
