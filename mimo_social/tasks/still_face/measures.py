"""The still-face paradigm's measures over episodes: per phase (interaction, still face,
reunion) the share of the phase's steps with a smile, with the gaze on the caregiver's face and
with self-touch, from each episode's last learner info; and the paradigm's effect for any policy.

:func:`run` is what ``mimo-social paradigm still_face`` calls for each learner (the catalogue
entry's ``measures``); :func:`rows` its lines in the side-by-side table. :func:`effects` runs a
policy (a scripted partner, a function of the observation, or an SB3 model: :func:`as_learner`)
for seeded episodes and returns the still-face effect: per episode, the still phase's drop of
smiling and of gaze at the face from the interaction, their recovery in reunion and the rise of
self-touch, as mean and sd over episodes (:data:`EFFECTS`); :func:`format_effects` prints them.
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from ...core.episodes import run_episodes
from ...partners.policy_adapter import as_learner
from ...util.checks import check_int
from .task import MEASURES, PHASES, scripted_env

__all__ = ["UNIT", "AGENT", "EFFECTS", "still_face_summary", "format_still_face_summary", "run",
           "rows", "as_learner", "effects", "format_effects"]

#: what one of :func:`run`'s ``episodes`` is
UNIT = "episodes"
#: the learner: the infant; the caregiver is scripted
AGENT = "infant_0"


def still_face_summary(infos: Iterable[Mapping]) -> dict:
    """Per phase and measure, the mean and standard deviation over episodes of the fraction of
    the phase's steps with it, from each episode's last learner info (``infos``: one mapping per
    episode with the ``<measure>_<phase>`` keys of the task's infos). Returns ``{"episodes": n,
    "success": share of episodes with is_success, "phases": {phase: {measure: (mean, sd)}}}``;
    a ValueError names a missing key."""
    rows = [dict(x) for x in infos]
    if not rows:
        raise ValueError("still_face_summary: no episodes; allowed: one info mapping per episode")
    out = {}
    for phase in PHASES:
        out[phase] = {}
        for key in MEASURES:
            name = f"{key}_{phase}"
            missing = [k for k, r in enumerate(rows) if name not in r]
            if missing:
                raise ValueError(f"still_face_summary: episode {missing[0]} has no {name!r}; "
                                 "allowed: the last info of a still_face_v0 episode")
            v = np.array([float(r[name]) for r in rows])
            out[phase][key] = (float(v.mean()), float(v.std()))
    success = float(np.mean([bool(r.get("is_success", False)) for r in rows]))
    return {"episodes": len(rows), "success": success, "phases": out}


def format_still_face_summary(summary: Mapping) -> str:
    """:func:`still_face_summary` as a text table (phase rows, measure columns)."""
    lines = [f"episodes {summary['episodes']}, success {100 * summary['success']:.0f} %",
             f"{'phase':<12}" + "".join(f"{k:>18}" for k in MEASURES)]
    for phase, row in summary["phases"].items():
        lines.append(f"{phase:<12}" + "".join(f"{m:>11.2f} +-{s:>4.2f}" for m, s in row.values()))
    return "\n".join(lines)


def run(learner, episodes: int, seed: int, env) -> dict:
    """``learner`` (a policy for ``infant_0``: ``act(env, agent, obs)``, optional ``reset``) in
    ``episodes`` episodes of ``env``, the scripted still face
    (:func:`~mimo_social.tasks.still_face.task.scripted_env`, which the caller made and closes;
    seeds ``seed``, ``seed + 1``, ...): :func:`still_face_summary` of the last infos, plus
    ``return``: (mean, sd) over episodes."""
    return _summary(*_episodes(learner, episodes, seed, env))


def _episodes(learner, episodes: int, seed: int, env) -> tuple[list[dict], list[float]]:
    """Each episode's last learner info and return."""
    done = run_episodes(env, {AGENT: learner}, episodes, seed)
    return [dict(e.last_infos[AGENT]) for e in done], [e.returns[AGENT] for e in done]


def _summary(finals: list[dict], returns: list[float]) -> dict:
    out = still_face_summary(finals)
    out["return"] = (float(np.mean(returns)), float(np.std(returns)))
    return out


def _ms(pair) -> str:
    mean, sd = pair
    return f"{mean:.2f} +- {sd:.2f}"


def rows(summaries: Sequence[Mapping]) -> list[tuple[str, list[str]]]:
    """The table's lines for :func:`run`'s summaries, a cell per learner: success, return, and
    per phase each measure (mean +- sd over episodes)."""
    out = [("success", [f"{100 * s['success']:.0f} %" for s in summaries]),
           ("return", [f"{s['return'][0]:.1f} +- {s['return'][1]:.1f}" for s in summaries])]
    for phase in PHASES:
        for m in MEASURES:
            out.append((f"{phase}: {m}", [_ms(s["phases"][phase][m]) for s in summaries]))
    return out


# -- the paradigm's effect, for any policy ------------------------------------------------------
#: the effects, each a per-episode difference of two phases' shares of steps:
#: name -> (measure, phase counted positive, phase counted negative)
EFFECTS = {"smile_still_drop": ("smile", "interaction", "still"),
           "smile_reunion_recovery": ("smile", "reunion", "still"),
           "gaze_still_drop": ("gaze", "interaction", "still"),
           "gaze_reunion_recovery": ("gaze", "reunion", "still"),
           "self_touch_still_rise": ("self_touch", "still", "interaction")}


def effects(policy, episodes: int = 10, seed: int = 0,
            env_kwargs: Mapping[str, Any] | None = None, deterministic: bool = True) -> dict:
    """``policy`` (:func:`as_learner`) as ``infant_0`` in ``episodes`` episodes of the scripted
    still face (:func:`~mimo_social.tasks.still_face.task.scripted_env` with ``env_kwargs``;
    seeds ``seed``, ``seed + 1``, ...). Returns ``{"episodes": n, "effects": {name: (mean, sd)},
    "summary": still_face_summary, "return": (mean, sd)}``; each effect (:data:`EFFECTS`) is
    a difference of two phases' shares of steps, taken per episode: a drop of smiling or gaze
    in the still face is positive, and so is their recovery in reunion and the rise of
    self-touch."""
    episodes = check_int("effects", "episodes", episodes, 1)
    env = scripted_env(**dict(env_kwargs or {}))
    try:
        finals, returns = _episodes(as_learner(policy, deterministic), episodes, seed, env)
    finally:
        env.close()
    summary = _summary(finals, returns)
    plus = np.array([[float(r[f"{k}_{p}"]) for k, p, _ in EFFECTS.values()] for r in finals])
    minus = np.array([[float(r[f"{k}_{m}"]) for k, _, m in EFFECTS.values()] for r in finals])
    d = plus - minus                                   # episode x effect
    out = {name: (float(mean), float(sd))
           for name, mean, sd in zip(EFFECTS, d.mean(axis=0), d.std(axis=0))}
    return {"episodes": episodes, "effects": out, "summary": summary,
            "return": summary["return"]}


def format_effects(result: Mapping) -> str:
    """:func:`effects`' result as lines ``name: mean +- sd``."""
    lines = [f"still-face effects over {result['episodes']} episodes (mean +- sd)"]
    lines += [f"{name}: {m:+.3f} +- {sd:.3f}" for name, (m, sd) in result["effects"].items()]
    return "\n".join(lines)
