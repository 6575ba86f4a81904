"""Configuration of agents and physics, validated with errors that say what is allowed.

Every env factory takes keyword arguments that apply to every agent plus an optional
``per_agent=[{...}, {...}]`` list of overrides. Senses are switched the same way for every
sense: ``False`` (off), ``True`` (defaults) or a mapping of settings of the sense's own config
class (found through the registry :data:`mimo_social.senses.SENSES`; the config classes are
re-exported here).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, fields
from typing import Any, Mapping, Sequence

from ..body.tables import HAND_VERSIONS, SCALE_RANGE, STRENGTH_RANGE
from ..senses import SENSES
from ..senses.proprioception import ProprioceptionConfig
from ..senses.touch import TouchConfig
from ..senses.vestibular import VestibularConfig
from ..senses.vision import VisionConfig
from ..util.checks import ConfigError, check_bool, check_choice, check_number

__all__ = [
    "ProprioceptionConfig", "VestibularConfig", "TouchConfig", "VisionConfig", "AgentConfig",
    "PhysicsConfig", "ConfigError", "resolve_agents", "parse_physics", "ACTUATION_MODELS",
    "POSTURES",
]

ACTUATION_MODELS = ("spring_damper", "muscle")
POSTURES = ("standing", "sitting", "lying")


def _from_mapping(cls, what: str, value: Mapping[str, Any]):
    names = [f.name for f in fields(cls)]
    unknown = sorted(set(value) - set(names))
    if unknown:
        raise ConfigError(f"{what}: unknown setting(s) {unknown}; allowed: {names}")
    return cls(**value)


@dataclass(frozen=True)
class AgentConfig:
    """Everything that can differ between agents."""

    hands: str = "mitten"
    actuation: str = "spring_damper"
    proprioception: ProprioceptionConfig | None = ProprioceptionConfig()
    vestibular: VestibularConfig | None = VestibularConfig()
    touch: TouchConfig | None = None
    vision: VisionConfig | None = None
    expressions: bool = True
    posture: str = "standing"
    position: tuple[float, float] | None = None   # (x, y) on the floor; None: the task decides
    facing: tuple[float, float] | None = None     # a point (x, y) to face; None: the task decides
    clothes_rgba: tuple[float, float, float, float] | None = None
    # Body size factor: every length of the body times `scale` (1: the 18-month-old, 77.8 cm;
    # 1.3: about a 3-year-old's height; 2.2: a caregiver's, 1.7 m); masses, torques and the rest
    # follow the scaling laws of docs/bodies.md.
    scale: float = 1.0
    # Multiplies every motor's maximum torque (muscles: maximum force) on top of the size law.
    strength: float = 1.0

    def __post_init__(self):
        check_choice("", "hands", self.hands, HAND_VERSIONS)
        check_choice("", "actuation", self.actuation, ACTUATION_MODELS)
        check_choice("", "posture", self.posture, POSTURES)
        check_bool("", "expressions", self.expressions)
        for key in ("position", "facing"):
            v = getattr(self, key)
            if v is not None and (len(v) != 2 or not all(abs(float(c)) < 1e3 for c in v)):
                raise ConfigError(f"{key}={v!r}; expected (x, y) in metres or None")
        object.__setattr__(self, "scale", check_number("", "scale", self.scale, *SCALE_RANGE))
        object.__setattr__(self, "strength",
                           check_number("", "strength", self.strength, *STRENGTH_RANGE))


_NO_FIELD = sorted(set(SENSES) - {f.name for f in fields(AgentConfig)})
if _NO_FIELD:  # a registered sense is switched by an AgentConfig field of its name
    raise TypeError(f"senses {_NO_FIELD} are registered but AgentConfig has no field for them")


def _parse_sense(name: str, value):
    cls = SENSES[name].config
    if value is False or value is None:
        return None
    if value is True:
        return cls()
    if isinstance(value, cls):
        return value
    if isinstance(value, Mapping):
        return _from_mapping(cls, name, value)
    raise ConfigError(f"{name}={value!r}; allowed: False, True or a mapping of "
                      f"{[f.name for f in fields(cls)]}")


def _agent_config(settings: Mapping[str, Any], where: str) -> AgentConfig:
    names = [f.name for f in fields(AgentConfig)]
    unknown = sorted(set(settings) - set(names))
    if unknown:
        raise ConfigError(f"{where}: unknown agent setting(s) {unknown}; allowed: {names}")
    values = dict(settings)
    for sense in SENSES:
        if sense in values:
            try:
                values[sense] = _parse_sense(sense, values[sense])
            except ConfigError as e:
                raise ConfigError(f"{where}: {e}") from None
    try:
        return AgentConfig(**values)
    except ConfigError as e:
        raise ConfigError(f"{where}: {e}") from None


def resolve_agents(n_agents: int, common: Mapping[str, Any],
                   per_agent: Sequence[Mapping[str, Any]] | None = None,
                   task_defaults: Sequence[Mapping[str, Any]] | None = None) -> list[AgentConfig]:
    """Agent configs from task defaults, then settings for all agents, then per-agent ones."""
    if per_agent is not None:
        if isinstance(per_agent, Mapping) or len(per_agent) != n_agents:
            raise ConfigError(f"per_agent must be a list of {n_agents} mappings (one per agent), "
                              f"got {per_agent!r}")
    out = []
    for i in range(n_agents):
        settings = dict(task_defaults[i]) if task_defaults else {}
        settings.update(common)
        if per_agent is not None:
            if not isinstance(per_agent[i], Mapping):
                raise ConfigError(f"per_agent[{i}] must be a mapping, got {per_agent[i]!r}")
            settings.update(per_agent[i])
        out.append(_agent_config(settings, f"agent infant_{i}"))
    return out


@dataclass(frozen=True)
class PhysicsConfig:
    timestep: float = 0.005        # s per physics step
    frame_skip: int = 2            # physics steps per control step (control at 100 Hz)
    jacobian: str = "sparse"       # measured faster than dense for these models (BENCHMARKS.md)
    solver: str = "newton"
    cone: str = "pyramidal"
    iterations: int = 50
    tolerance: float = 1e-8
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)

    def __post_init__(self):
        if not 1e-4 <= self.timestep <= 0.02:
            raise ConfigError(f"physics timestep={self.timestep} s; allowed: 0.0001 to 0.02 s")
        if not isinstance(self.frame_skip, int) or not 1 <= self.frame_skip <= 100:
            raise ConfigError(f"physics frame_skip={self.frame_skip!r}; allowed: integer 1 to 100")
        for key, allowed in (("jacobian", ("dense", "sparse", "auto")),
                             ("solver", ("newton", "cg", "pgs")),
                             ("cone", ("pyramidal", "elliptic"))):
            if getattr(self, key) not in allowed:
                raise ConfigError(f"physics {key}={getattr(self, key)!r}; allowed: {list(allowed)}")
        if not 1 <= self.iterations <= 1000:
            raise ConfigError(f"physics iterations={self.iterations}; allowed: 1 to 1000")


def parse_physics(value, task_overrides: Mapping[str, Any] | None = None) -> PhysicsConfig:
    base = dict(task_overrides or {})
    if value is None:
        pass
    elif isinstance(value, PhysicsConfig):
        base.update(dataclasses.asdict(value))
    elif isinstance(value, Mapping):
        names = [f.name for f in fields(PhysicsConfig)]
        unknown = sorted(set(value) - set(names))
        if unknown:
            raise ConfigError(f"physics: unknown setting(s) {unknown}; allowed: {names}")
        base.update(value)
    else:
        raise ConfigError(f"physics={value!r}; expected a mapping of physics settings")
    return PhysicsConfig(**base)
