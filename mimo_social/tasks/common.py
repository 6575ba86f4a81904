"""Helpers shared by the tasks: placement, contacts, skin settings, postures, settling, the
summary of a paradigm's conditions.

Tasks import these (and :mod:`mimo_social.body.joint_groups`, :mod:`mimo_social.core.kinematics`);
no task imports another task's module.
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

import mujoco
import numpy as np

from ..body.tables import HAND_VERSIONS, subtree
from ..util.checks import ConfigError

__all__ = ["CROSS_LEGGED_DEG", "HAND_TOUCH_DENSITY", "face_to_face", "geoms_touching",
           "ContactProbe", "parts_outside", "skin_parts", "right_hand_parts", "touch_only_on",
           "require_skin", "hands_setting", "settle", "condition_means",
           "condition_rows", "condition_effects", "format_condition_effects"]

#: sitting cross-legged, the trunk bent forward, the left hand on the lap (the self-body pose;
#: social touch uses its legs)
CROSS_LEGGED_DEG = {
    "right_hip_flexion": -120.0, "left_hip_flexion": -120.0,
    "right_hip_abduction": -51.0, "left_hip_abduction": -51.0,
    "right_hip_rotation": 40.0, "left_hip_rotation": 40.0,
    "right_knee": -130.0, "left_knee": -130.0,
    "right_ankle_flexion": 20.0, "left_ankle_flexion": 20.0,
    # the left hand rests on the lap, within the right hand's reach
    "left_shoulder_horizontal": 52.0, "left_shoulder_abduction": 41.0,
    "left_shoulder_rotation": 0.0, "left_elbow": -64.0,
    "lower_trunk_bend": 30.0,
}
# a tenth of the published point density: the right hand's skin is 232 points (25 on the palm
# part, 207 on the fingers) for the mitten body, 1 float each (normal force)
HAND_TOUCH_DENSITY = 0.1


# -- placement ---------------------------------------------------------------------------------
def face_to_face(i: int, distance: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """Position and point to face of agent ``i`` of a pair ``distance`` apart on the x axis."""
    pos = (0.0, 0.0) if i == 0 else (float(distance), 0.0)
    facing = (float(distance), 0.0) if i == 0 else (0.0, 0.0)
    return pos, facing


# -- contacts ----------------------------------------------------------------------------------
def geoms_touching(data, geom: int) -> np.ndarray:
    """The geoms in active contact (distance <= 0) with ``geom`` this step (one gather over the
    contacts, no loop)."""
    n = data.ncon
    if n == 0:
        return np.zeros(0, dtype=np.intp)
    c = data.contact
    g1, g2 = c.geom1[:n], c.geom2[:n]
    on = ((g1 == geom) | (g2 == geom)) & (c.dist[:n] <= 0.0)
    return np.where(g1 == geom, g2, g1)[on]


class ContactProbe:
    """Tells whether any active contact joins a geom of set a with a geom of set b.

    Boolean masks over all geoms are built once, so a query is two gathers over the contacts.
    """

    def __init__(self, ngeom: int, geoms_a, geoms_b):
        self.a = np.zeros(ngeom, bool)
        self.b = np.zeros(ngeom, bool)
        self.a[np.asarray(geoms_a, dtype=np.intp)] = True
        self.b[np.asarray(geoms_b, dtype=np.intp)] = True

    def __call__(self, data) -> bool:
        n = data.ncon
        if n == 0:
            return False
        c = data.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        hit = (self.a[g1] & self.b[g2]) | (self.a[g2] & self.b[g1])
        return bool(np.any(hit & (c.dist[:n] <= 0.0)))


# -- skin --------------------------------------------------------------------------------------
def skin_parts(tables) -> tuple[str, ...]:
    """Every body part that has geoms, in table order (the parts a skin may cover)."""
    parts: list[str] = []
    for g in tables.geoms:
        if g.body not in parts:
            parts.append(g.body)
    return tuple(parts)


def parts_outside(tables, roots: tuple[str, ...]) -> tuple[str, ...]:
    """Every body part with geoms that is not in the subtree of one of ``roots``: the touch
    ``exclude`` list that leaves skin on those subtrees only."""
    keep = set()
    for r in roots:
        keep |= set(subtree(tables, r))
    return tuple(p for p in skin_parts(tables) if p not in keep)


def right_hand_parts(tables) -> tuple[str, ...]:
    """The right hand's body parts: ``right_hand`` and every part below it (the mitten's
    fingers, or the five fingers' segments)."""
    return tuple(subtree(tables, "right_hand"))


def touch_only_on(tables, parts: Sequence[str], density: float = HAND_TOUCH_DENSITY,
                  normal_only: bool = True) -> dict:
    """A ``touch`` setting whose skin covers only ``parts`` (every other part is excluded)."""
    keep = set(parts)
    return {"density": float(density), "normal_only": bool(normal_only),
            "exclude": tuple(p for p in skin_parts(tables) if p not in keep)}


def require_skin(task: str, agent: str, config, parts: Sequence[str], what: str) -> None:
    """Raise a :class:`ConfigError` unless ``config.touch`` covers every part of ``parts``."""
    if config.touch is None:
        raise ConfigError(f"{task}: {agent} has touch=False, but the task senses {what} through "
                          f"the skin; turn touch on (the default covers {list(parts)}, "
                          "touch=True the whole body)")
    missing = [p for p in parts if p in config.touch.exclude]
    if missing:
        raise ConfigError(f"{task}: {agent}'s touch excludes {missing}, but the task senses "
                          f"{what} through the skin there; remove them from touch 'exclude'")


def hands_setting(settings: Mapping[str, Any]) -> str:
    """The hand version in an agent's user settings (``hands=...``; ``"mitten"`` when absent).
    A malformed value gives ``"mitten"`` here: the env's config check then reports it."""
    hands = settings.get("hands", "mitten")
    return hands if isinstance(hands, str) and hands in HAND_VERSIONS else "mitten"


# -- running -----------------------------------------------------------------------------------
def settle(env, steps: int, gravity: bool = True) -> None:
    """Run ``steps`` physics steps with the current controls through the env's own physics path
    (:meth:`~mimo_social.core.env.MimoParallelEnv.advance`: actuation updates, the state checked
    after every step), optionally without gravity; ``data.time`` restarts at 0."""
    w = env.world
    m, d = w.model, w.data
    saved = m.opt.gravity.copy()
    if not gravity:
        m.opt.gravity[:] = 0.0
    try:
        env.advance(steps)
    finally:
        m.opt.gravity[:] = saved
    d.time = 0.0
    mujoco.mj_forward(m, d)


def condition_means(finals: Sequence[Mapping[str, Any]], conditions: Sequence[str],
                    measures: Sequence[str]) -> dict[str, dict[str, tuple[float, float]]]:
    """Per condition, each of ``measures``' mean and sd over the episodes, from each episode's
    last-step info (its ``condition`` code is the index in ``conditions``); conditions without
    an episode are left out; ``"episodes"``: their count."""
    out: dict[str, dict[str, tuple[float, float]]] = {}
    for code, cond in enumerate(conditions):
        got = [f for f in finals if int(f["condition"]) == code]
        if not got:
            continue
        out[cond] = {m: (float(np.mean([float(r[m]) for r in got])),
                         float(np.std([float(r[m]) for r in got]))) for m in measures}
        out[cond]["episodes"] = (float(len(got)), 0.0)
    return out


def condition_rows(summaries: Sequence[Mapping], conditions: Sequence[str],
                   measures: Sequence[str]) -> list[tuple[str, list[str]]]:
    """The lines of a table of :func:`condition_means` results, a cell per learner: per
    condition (those every summary has) each measure, mean +- sd over episodes."""
    out = []
    for cond in conditions:
        if not all(cond in s for s in summaries):
            continue
        for m in measures:
            out.append((f"{cond}: {m}", [f"{s[cond][m][0]:.2f} +- {s[cond][m][1]:.2f}"
                                         for s in summaries]))
    return out


def condition_effects(finals: Sequence[Mapping[str, Any]], blocks: int,
                      conditions: Sequence[str], measures: Sequence[str]) -> dict:
    """A paradigm's effect from ``blocks`` blocks of one episode per condition (``finals``:
    the last-step infos, block by block, in the order of ``conditions``): per other condition
    ``"<first>_minus_<other>"``, each measure's per-block difference of the first condition
    minus that one, mean and sd over blocks; ``"episodes"``: ``blocks``."""
    v = np.array([[float(f[m]) for m in measures] for f in finals], float)
    v = v.reshape(blocks, len(conditions), len(measures))     # block x condition x measure
    out: dict[str, Any] = {"episodes": blocks}
    for k, other in enumerate(conditions[1:], start=1):
        d = v[:, 0] - v[:, k]
        out[f"{conditions[0]}_minus_{other}"] = {
            m: (float(mean), float(sd)) for m, mean, sd in zip(measures, d.mean(axis=0),
                                                              d.std(axis=0))}
    return out


def format_condition_effects(result: Mapping, title: str, conditions: Sequence[str],
                             measures: Sequence[str]) -> str:
    """:func:`condition_effects`' result as a markdown table: a row per measure, a column per
    difference (mean +- sd over blocks)."""
    cols = [f"{conditions[0]}_minus_{c}" for c in conditions[1:]]
    lines = [f"{title} effects over {result['episodes']} blocks (mean +- sd)",
             "| measure | " + " | ".join(c.replace("_", " ") for c in cols) + " |",
             "|---" * (len(cols) + 1) + "|"]
    for m in measures:
        cells = [f"{result[c][m][0]:+.3f} +- {result[c][m][1]:.3f}" for c in cols]
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
