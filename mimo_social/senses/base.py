"""What a sense is, what a shared system is, and the registry entry that ties a sense to its
config and to how the env builds it.

A sense belongs to one agent: it names its timing key (``name``), the observation keys it fills
with their spaces (``spaces``), and writes them in ``observe(model, data, out)``; ``info()``, when
it has one, adds to the agent's ``infos``. A shared system is one per world (the skin reading the
contacts once for every agent, the eyes of every agent drawn on one renderer): the env calls
``reset(model, data)`` after every reset and ``update(model, data)`` once per step, after the
physics and before any agent observes; ``close()`` when it has one.

A sense is registered with one :class:`SenseEntry`: its name (also the :class:`AgentConfig` field
that switches it, ``False`` / ``True`` / a mapping of its config's settings), its config class,
and either a per-agent builder ``build(config, world, index, actuation) -> Sense`` or a shared
builder ``build(world, configs) -> (system, [Sense or None per agent])``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping, Protocol, Sequence, runtime_checkable

from ..util.checks import ConfigError, show

__all__ = ["Sense", "SharedSystem", "SenseEntry", "components"]


@runtime_checkable
class Sense(Protocol):
    """One agent's sense (``info()`` is optional)."""

    name: str                       # its timing key in ``env.timing``
    spaces: Mapping[str, Any]       # observation key -> gymnasium space

    def observe(self, model, data, out: dict) -> None:
        """Write this sense's observation keys into ``out``."""


@runtime_checkable
class SharedSystem(Protocol):
    """One per world, for every agent with the sense on (``close()`` is optional)."""

    name: str

    def reset(self, model, data) -> None:
        """Forget the last episode (called after ``mj_forward`` of a reset)."""

    def update(self, model, data) -> None:
        """Read the world once for every agent (called once per step, before they observe)."""


@dataclass(frozen=True)
class SenseEntry:
    """A sense in the registry: exactly one of ``per_agent`` and ``shared`` is given.

    ``per_agent(config, world, index, actuation)`` builds agent ``index``'s sense;
    ``shared(world, configs)`` builds the world's system and every agent's sense (None where
    the sense is off) from the configs of all agents (None where off). ``add_to_spec(spec,
    names, agent_configs)``, when given, adds what the sense needs to the world's MjSpec before
    it compiles (e.g. MuJoCo sensors), from every agent's name and ``AgentConfig``.
    """

    name: str
    config: type
    per_agent: Callable[..., Sense] | None = None
    shared: Callable[..., tuple[SharedSystem, list[Sense | None]]] | None = None
    add_to_spec: Callable[..., None] | None = None

    def __post_init__(self):
        if (self.per_agent is None) == (self.shared is None):
            raise TypeError(f"sense {self.name!r}: give exactly one of per_agent and shared")

    def build(self, world, configs: Sequence, actuation: Sequence):
        """The system (None for a per-agent sense) and one sense or None per agent."""
        if self.shared is not None:
            return self.shared(world, list(configs))
        return None, [self.per_agent(c, world, i, actuation[i]) if c else None
                      for i, c in enumerate(configs)]


def components(sense: str, given, allowed: Sequence[str]) -> tuple[str, ...]:
    """A sense's switched-on components, in the order of ``allowed``; a ConfigError saying what
    is allowed for an empty or unknown choice."""
    if isinstance(given, (str, bytes, Mapping)) or not isinstance(given, (Sequence, set,
                                                                         frozenset)):
        raise ConfigError(f"{sense}: components={show(given)} not allowed; allowed: a non-empty "
                          f"list of {list(allowed)}")
    given = tuple(given)
    bad = [c for c in given if not isinstance(c, str) or c not in allowed]
    if bad or not given:
        raise ConfigError(f"{sense}: components {list(given)} not allowed; choose a non-empty "
                          f"subset of {list(allowed)}")
    return tuple(c for c in allowed if c in given)
