"""Configuration of agents and physics, validated with errors that say what is allowed.

Every env factory takes keyword arguments that apply to every agent plus an optional
``per_agent=[{...}, {...}]`` list of overrides. Senses are switched the same way for every
sense: ``False`` (off), ``True`` (defaults) or a mapping of settings.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass, fields
from typing import Any, Mapping, Sequence

from ..body.tables import HAND_VERSIONS, SCALE_RANGE, STRENGTH_RANGE
from ..util.checks import ConfigError

__all__ = [
    "ProprioceptionConfig", "VestibularConfig", "AgentConfig", "PhysicsConfig",
    "ConfigError", "resolve_agents", "parse_physics", "ACTUATION_MODELS", "POSTURES",
]

ACTUATION_MODELS = ("spring_damper", "muscle")
POSTURES = ("standing", "sitting", "lying")
PROPRIOCEPTION_COMPONENTS = ("qpos", "qvel", "torque", "limits", "actuation")
VESTIBULAR_COMPONENTS = ("gyro", "accel")


def _from_mapping(cls, what: str, value: Mapping[str, Any]):
    names = [f.name for f in fields(cls)]
    unknown = sorted(set(value) - set(names))
    if unknown:
        raise ConfigError(f"{what}: unknown setting(s) {unknown}; allowed: {names}")
    return cls(**value)


def _components(what: str, given, allowed: Sequence[str]) -> tuple[str, ...]:
    given = tuple(given)
    bad = [c for c in given if c not in allowed]
    if bad or not given:
        raise ConfigError(f"{what}: components {list(given)} not allowed; choose a non-empty "
                          f"subset of {list(allowed)}")
    return tuple(c for c in allowed if c in given)


@dataclass(frozen=True)
class ProprioceptionConfig:
    """Joint positions, velocities, actuator torques, limit proximity, actuation state."""

    components: tuple[str, ...] = PROPRIOCEPTION_COMPONENTS
    limit_margin_deg: float = 5.0  # a limit sensor rises from 0 to 1 over this last stretch

    def __post_init__(self):
        object.__setattr__(self, "components", _components(
            "proprioception", self.components, PROPRIOCEPTION_COMPONENTS))
        if not 0 < self.limit_margin_deg <= 90:
            raise ConfigError(f"proprioception: limit_margin_deg={self.limit_margin_deg} "
                              "must be in (0, 90] degrees")


@dataclass(frozen=True)
class VestibularConfig:
    """Angular velocity (gyro, rad/s) and linear acceleration (accel, m/s^2) at the head centre."""

    components: tuple[str, ...] = VESTIBULAR_COMPONENTS

    def __post_init__(self):
        object.__setattr__(self, "components", _components(
            "vestibular", self.components, VESTIBULAR_COMPONENTS))


TOUCH_RESPONSES = ("spread_linear", "nearest")
TOUCH_FRAMES = ("body", "world")


@dataclass(frozen=True)
class TouchConfig:
    """The full-body skin: sensor points over every body part, each sensing a force vector.

    ``density`` multiplies the published per-part point density (spacing / sqrt(density));
    ``exclude`` lists body parts without skin; ``response`` spreads each contact over nearby
    points; ``frame`` is the frame of the force vectors; ``normal_only`` keeps 1 value a point.
    """

    density: float = 1.0
    response: str = "spread_linear"
    frame: str = "body"
    normal_only: bool = False
    exclude: tuple[str, ...] = ()
    cache: bool = True

    def __post_init__(self):
        if not 0.05 <= float(self.density) <= 8.0:
            raise ConfigError(f"touch: density={self.density}; allowed: 0.05 to 8 (a multiplier "
                              "of the published point density)")
        if self.response not in TOUCH_RESPONSES:
            raise ConfigError(f"touch: response={self.response!r}; allowed: {list(TOUCH_RESPONSES)}")
        if self.frame not in TOUCH_FRAMES:
            raise ConfigError(f"touch: frame={self.frame!r}; allowed: {list(TOUCH_FRAMES)}")
        object.__setattr__(self, "exclude", tuple(self.exclude))


@dataclass(frozen=True)
class VisionConfig:
    """Two eye cameras (60 degree field of view) rendering RGB images, optionally depth."""

    width: int = 256
    height: int = 256
    depth: bool = False
    every: int = 1          # render every k-th control step, holding the last images between

    def __post_init__(self):
        for key in ("width", "height"):
            v = getattr(self, key)
            if not isinstance(v, int) or not 8 <= v <= 2048:
                raise ConfigError(f"vision: {key}={v!r}; allowed: an integer 8 to 2048 pixels")
        if not isinstance(self.every, int) or not 1 <= self.every <= 1000:
            raise ConfigError(f"vision: every={self.every!r}; allowed: an integer 1 to 1000")


_SENSES = {"proprioception": ProprioceptionConfig, "vestibular": VestibularConfig,
           "touch": TouchConfig, "vision": VisionConfig}
_NOT_YET: dict = {}


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
        if self.hands not in HAND_VERSIONS:
            raise ConfigError(f"hands={self.hands!r} not allowed; allowed: {list(HAND_VERSIONS)}")
        if self.actuation not in ACTUATION_MODELS:
            raise ConfigError(
                f"actuation={self.actuation!r} not allowed; allowed: {list(ACTUATION_MODELS)}")
        if self.posture not in POSTURES:
            raise ConfigError(f"posture={self.posture!r} not allowed; allowed: {list(POSTURES)}")
        if not isinstance(self.expressions, bool):
            raise ConfigError(f"expressions={self.expressions!r}; allowed: True or False")
        for key in ("position", "facing"):
            v = getattr(self, key)
            if v is not None and (len(v) != 2 or not all(abs(float(c)) < 1e3 for c in v)):
                raise ConfigError(f"{key}={v!r}; expected (x, y) in metres or None")
        for key, (lo, hi), what in (("scale", SCALE_RANGE, "body size factor"),
                                    ("strength", STRENGTH_RANGE, "strength factor")):
            v = getattr(self, key)
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
                raise ConfigError(f"{key}={v!r} not allowed; allowed: a number from {lo:g} to "
                                  f"{hi:g} ({what})")
            if not lo <= v <= hi:
                raise ConfigError(f"{key}={v!r} is out of range; allowed: {lo:g} to {hi:g} "
                                  f"({what})")
            object.__setattr__(self, key, float(v))


def _parse_sense(name: str, value):
    if name in _NOT_YET:
        if value in (False, None):
            return None
        raise ConfigError(f"{name}={value!r}: {_NOT_YET[name]}; allowed now: False")
    cls = _SENSES[name]
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
    for sense in ("proprioception", "vestibular", "touch", "vision"):
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
