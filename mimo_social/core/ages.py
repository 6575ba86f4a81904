"""The env's side of an infant's age change at reset (``env.set_age``, ``reset(options=...)``):
which agents change and to what (checked as their configs check them), and, once
:mod:`mimo_social.core.regrow` has written the world, their motors, senses and skins.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Mapping, Sequence

import numpy as np

from ..body.growth import segment_factors
from ..body.tables import BodyTables
from ..senses import SENSES
from ..senses.skin_growth import regrown_skin
from ..util.checks import show
from .config import ConfigError
from .regrow import check_same_model

__all__ = ["AGE_OPTIONS", "IGNORED_OPTIONS", "age_options", "age_changes", "grow",
           "regrow_senses", "frame_ratios"]

#: the options ``reset(options=...)`` takes: each a number (every infant) or {agent: number}
AGE_OPTIONS = ("age_months", "motor_age_months")
#: option keys accepted and ignored: PettingZoo's API test checks that reset takes options with
#: ``options={"options": 1}``
IGNORED_OPTIONS = ("options",)


def age_options(options) -> dict:
    """The age settings of ``reset``'s ``options`` (None or a mapping of :data:`AGE_OPTIONS`);
    a ConfigError naming an unknown key and the keys allowed."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise ConfigError(f"reset: options={show(options)} not allowed; allowed: None or a dict "
                          f"with keys {list(AGE_OPTIONS)}")
    unknown = sorted((k for k in options if k not in AGE_OPTIONS + IGNORED_OPTIONS), key=str)
    if unknown:
        raise ConfigError(f"reset: unknown option(s) {unknown}; allowed: {list(AGE_OPTIONS)} "
                          "(each a number of months, 0 to 33, for every infant, or a dict "
                          "agent -> months)")
    return {k: options[k] for k in AGE_OPTIONS if k in options}


def age_changes(names: Sequence[str], configs: Sequence, values: Mapping, agent=None,
                where: str = "set_age") -> dict[int, dict]:
    """Agent index -> {setting: months} of the infants that ``values`` (setting -> None (no
    change), a number (``agent``, or every infant when ``agent`` is None) or a dict agent ->
    number) changes, each checked as the agent's config checks it; a ConfigError (an unknown
    agent: a KeyError) naming the agent, the setting, the value and what is allowed."""
    infants = [n for n, c in zip(names, configs) if c.body == "infant"]

    def index(name) -> int:
        if name not in names:
            raise KeyError(f"{where}: unknown agent {name!r}; agents of this env: {list(names)}")
        i = list(names).index(name)
        if configs[i].body != "infant":
            raise ConfigError(f"{where}: agent {name} is an adult (body='adult'); "
                              f"{' and '.join(AGE_OPTIONS)} are for infants: {infants}")
        return i

    if agent is not None:
        targets = [index(agent)]
    else:
        targets = [names.index(n) for n in infants]
    out: dict[int, dict] = {}
    for key, value in values.items():
        if value is None:
            continue
        if isinstance(value, Mapping):
            for name, v in value.items():
                out.setdefault(index(name), {})[key] = v
            continue
        if not targets:
            raise ConfigError(f"{where}: {key}={show(value)}: this env has no infant (agents "
                              f"{list(names)}); ages are for infants")
        for i in targets:
            out.setdefault(i, {})[key] = value
    for i, fields in out.items():
        try:
            replace(configs[i], **fields)
        except ConfigError as e:
            raise ConfigError(f"{where}: agent {names[i]}: {e}") from None
    return out


def frame_ratios(old_age: float, new_age: float, segments: Sequence[str]) -> np.ndarray:
    """(n, 3) per segment the ratio of its frame's x, y, z length factors at ``new_age`` to
    those at ``old_age`` (:func:`~mimo_social.body.growth.segment_factors`; a ``left_``
    segment takes its right twin's)."""
    def factors(age):
        table = segment_factors(age)
        out = []
        for name in segments:
            key = name if name in table or not name.startswith("left_") else "right_" + name[5:]
            radial, axial, axis = table.get(key, (1.0, 1.0, "z"))
            out.append([axial if a == axis else radial for a in "xyz"])
        return np.array(out)
    return factors(new_age) / factors(old_age)


def regrow_senses(env, i: int, old: BodyTables, old_size: np.ndarray,
                  old_pos: np.ndarray, old_age: float) -> None:
    """After :meth:`World.regrow` of agent ``i``: its motors take the new torques, its senses'
    spaces the new bounds (the same space objects), its skin follows its geoms (as many
    points: :func:`~mimo_social.senses.skin.regrown_skin`) and its eyes' acuity the body age.
    ``old``: its tables before; ``old_size``, ``old_pos``: every geom's size and position
    before; ``old_age``: its body age before."""
    w, cfg = env.world, env.agent_configs[i]
    t = w.tables[i]
    by_name = {j.name: j for j in t.joints}
    act = env.actuation[i]
    act.retune([by_name[n] for n in w.agents[i].actuated_names])
    for sense in env.senses[i]:
        entry = SENSES[sense.name]
        if entry.per_agent is None:
            continue
        fresh = entry.per_agent(getattr(cfg, sense.name), w, i, act)
        for key, space in sense.spaces.items():
            if hasattr(space, "low"):
                np.copyto(space.low, fresh.spaces[key].low)
                np.copyto(space.high, fresh.spaces[key].high)
    touch = env.systems.get("touch")
    if touch is not None and touch.skins[i] is not None:
        skin = touch.skins[i]
        ratio = np.array([t.touch_spacing[n] / old.touch_spacing[n] for n in skin.part_names])
        touch.skins[i] = regrown_skin(skin, w.model, old_size, old_pos, ratio,
                                      frame_ratios(old_age, cfg.age, skin.part_names))
        touch.concatenate(w.model)
        for sense in env.senses[i]:
            if sense.name == "touch":
                sense.skin = touch.skins[i]
    vision = env.systems.get("vision")
    if vision is not None and i in vision.agents:
        vision.set_age(w.model, i, cfg.age)


def grow(env, changes: Mapping[int, Mapping]) -> list[int] | None:
    """Age changes (agent index -> {setting: months}) applied to ``env``'s world, motors,
    senses and props; returns the agents whose config changed (their delays and the task are
    the env's to redo), None when no config changes. The task's setups and props are taken
    again for the new configs (a task may place agents, hold joints and size props by their
    sizes) and checked before anything is written; then the world is reset to its new start
    state (what a task binds to) and the props' welds are anchored there."""
    w = env.world
    size, pos = w.model.geom_size.copy(), w.model.geom_pos.copy()
    before = list(env.agent_configs)
    configs = [replace(c, **changes.get(i, {})) for i, c in enumerate(before)]
    if configs == before:
        return None
    env.task.configs = tuple(configs)
    try:
        setups = [env.task.setup(i, c) for i, c in enumerate(configs)]
        props, tables = tuple(env.task.props()), list(w.tables)
        moved = [i for i, setup in enumerate(setups) if setup != w.agent_setups[i]]
        for i in moved:
            check_same_model(w, i, setups[i], env.dt)
    except Exception:
        env.task.configs = tuple(before)
        raise
    for i in moved:
        w.regrow(i, setups[i])
    if props != w.props:
        w.regrow_props(props)
    w.reset()
    w.hold_welds()
    changed = []
    for i, config in enumerate(configs):
        if config != before[i]:
            env.agent_configs[i] = config
            regrow_senses(env, i, tables[i], size, pos, before[i].age)
            changed.append(i)
        elif i in moved:     # a partner the task moved: its motors adapt to the model again
            env.actuation[i].retune(env.actuation[i].joints)
    return changed
