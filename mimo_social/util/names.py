"""Agent names: infants are ``infant_<i>``, adult caregivers ``caregiver_<i>``.

Each kind counts on its own, in world order: a world of an infant and a kneeling adult holds
``infant_0`` and ``caregiver_0``; two infants are ``infant_0`` and ``infant_1``; two adults
``caregiver_0`` and ``caregiver_1``. The name is the agent's key in every dict of the envs and
the prefix of its bodies in the MuJoCo model (``caregiver_0/head``).

Before this rule every agent was ``infant_<world index>``, the adult too. :func:`old_name_hint`
turns such an old name, where it now means nothing or another agent's kind, into a sentence
that names the agent's new name, for the errors that reject it."""

from __future__ import annotations

import re
from typing import Sequence

__all__ = ["KIND_PREFIX", "agent_names", "old_names", "old_name_hint", "reject_old_names"]

#: the name prefix of each body kind (``AgentConfig.body``)
KIND_PREFIX = {"infant": "infant", "adult": "caregiver"}

_OLD = re.compile(r"infant_(\d+)")


def agent_names(bodies: Sequence[str]) -> list[str]:
    """The agents' names from their body kinds in world order (``["infant", "adult"]`` ->
    ``["infant_0", "caregiver_0"]``); anything but the string ``"adult"`` counts as an infant
    (a malformed body, e.g. an array, is named so and then refused by the config's check)."""
    counts: dict[str, int] = {}
    names = []
    for body in bodies:
        adult = isinstance(body, str) and body == "adult"
        prefix = KIND_PREFIX["adult"] if adult else KIND_PREFIX["infant"]
        names.append(f"{prefix}_{counts.get(prefix, 0)}")
        counts[prefix] = counts.get(prefix, 0) + 1
    return names


def old_names(names: Sequence[str]) -> dict[str, str]:
    """Old name -> new name of every agent whose name changed (``{"infant_1": "caregiver_0"}``
    for an infant and an adult)."""
    return {f"infant_{i}": n for i, n in enumerate(names) if n != f"infant_{i}"}


def old_name_hint(name, names: Sequence[str]) -> str:
    """``""`` unless ``name`` is not one of ``names`` but is the old name (``infant_<world
    index>``) of one of them; then a sentence that says its new name, e.g. ``"agent 'infant_1'
    is the adult caregiver: it is now named 'caregiver_0'"``."""
    if not isinstance(name, str) or name in names or not _OLD.fullmatch(name):
        return ""
    new = old_names(names).get(name)
    if new is None:
        return ""
    who = "the adult caregiver" if new.startswith(KIND_PREFIX["adult"] + "_") else "an infant"
    return (f"agent {name!r} is {who}: it is now named {new!r} (infants are infant_<i>, adults "
            f"caregiver_<i>, each counted in world order)")


def reject_old_names(given, names: Sequence[str]) -> None:
    """A ValueError that says the new name if any of ``given`` (one name or several) is an old
    name of one of ``names`` (:func:`old_name_hint`); else nothing (other unknown names are
    the caller's to reject)."""
    for name in [given] if isinstance(given, str) else list(given):
        hint = old_name_hint(name, names)
        if hint:
            raise ValueError(f"{hint}; agents: {list(names)}")
