"""Configuration of agents and physics, validated with errors that say what is allowed.

Every env factory takes keyword arguments that apply to every agent plus an optional
``per_agent=[{...}, {...}]`` list of overrides. Senses are switched the same way for every
sense: ``False`` (off), ``True`` (defaults) or a mapping of settings of the sense's own config
class (found through the registry :data:`mimo_social.senses.SENSES`; the config classes are
re-exported here).
"""

from __future__ import annotations

import dataclasses
from functools import partial
from dataclasses import dataclass, fields
from typing import Any, Mapping, Sequence

import numpy as np

from ..body.tables import AGE_RANGE, BODY_KINDS, HAND_VERSIONS, SCALE_RANGE, STRENGTH_RANGE
from ..senses import SENSES
from ..senses.audition import AuditionConfig
from ..senses.delays import CHANNELS
from ..senses.faces import FacesConfig
from ..senses.proprioception import ProprioceptionConfig
from ..senses.touch import TouchConfig
from ..senses.vestibular import VestibularConfig
from ..senses.vision import VisionConfig
from ..util.checks import (ConfigError, check_bool, check_choice, check_int, check_number,
                           check_numbers, show)
from ..util.names import agent_names

__all__ = [
    "ProprioceptionConfig", "VestibularConfig", "TouchConfig", "VisionConfig", "AgentConfig",
    "AuditionConfig", "FacesConfig",
    "PhysicsConfig", "ConfigError", "resolve_agents", "parse_physics", "ACTUATION_MODELS",
    "POSTURES", "BODIES", "AGE_RANGE", "DELAY_CHANNELS", "DELAY_LIMIT_MS", "env_settings",
    "RENDER_SIZE_RANGE", "MAX_STEPS_LIMIT",
]

ACTUATION_MODELS = ("spring_damper", "muscle", "positional")
FLOOR_HALF = 10.0      # m: the floor plane's half size (an agent placed beyond it falls forever)
FACING_LIMIT = 100.0   # m: how far the point an agent faces may be
POSTURES = ("standing", "sitting", "kneeling", "lying")
#: body kinds: the infant (its age from ``age_months``) and an adult caregiver
BODIES = BODY_KINDS
#: what can be delayed (``delays``): each sense of the registry and the motor command
DELAY_CHANNELS = CHANNELS
#: the longest delay allowed per channel, milliseconds
DELAY_LIMIT_MS = 1000.0


def _from_mapping(cls, what: str, value: Mapping[str, Any]):
    names = [f.name for f in fields(cls)]
    unknown = sorted(set(value) - set(names), key=str)
    if unknown:
        raise ConfigError(f"{what}: unknown setting(s) {unknown}; allowed: {names}")
    return cls(**value)


@dataclass(frozen=True)
class AgentConfig:
    """Everything that can differ between agents."""

    # "mitten" (44 actuated DoF) or "five_fingers" (88: 22 finger joints per hand, two-toe
    # feet); agents in one world may differ
    hands: str = "mitten"
    # "spring_damper" (a motor per axis, controls in [-1, 1]), "muscle" (two opposing muscles
    # per axis, controls in [0, 1]) or "positional" (controls are target angles across each
    # joint's range, tracked by a servo within its torque limits)
    actuation: str = "spring_damper"
    # joint angles, velocities, torques, limit sensors, the actuation's state
    proprioception: ProprioceptionConfig | None = ProprioceptionConfig()
    vestibular: VestibularConfig | None = VestibularConfig()   # the head's gyro and accel
    touch: TouchConfig | None = None     # the full-body skin: a force vector per point
    vision: VisionConfig | None = None   # two eye cameras: RGB, optionally depth
    # Two ears on the head hearing every agent with voice on: per source its kind, the level
    # at each ear, ILD and ITD (docs/senses.md, "Hearing and voice")
    audition: AuditionConfig | None = None
    # The other agents' faces while in view: seen, where, turned where, looking where
    # (docs/senses.md, "Faces"): what a trained face perception reads, not the pixels
    faces: FacesConfig | None = None
    expressions: bool = True   # the face is part of the action: 7 expressions
    # The voice is part of the action: "voice" (a kind of expressions.voice.SOUNDS: silence,
    # coo, babble, cry, laugh, speech) and "loudness" in [0, 1] (the kind's quietest to
    # loudest level, docs/senses.md "Hearing and voice"); a sound lasts its control step.
    voice: bool = False
    posture: str = "standing"   # the start posture
    position: tuple[float, float] | None = None   # (x, y) on the floor; None: the task decides
    facing: tuple[float, float] | None = None     # a point (x, y) to face; None: the task decides
    clothes_rgba: tuple[float, float, float, float] | None = None  # None: distinct colours
    # Body size factor: every length of the body times `scale` (1: the 18-month-old, 77.8 cm;
    # 1.3: about a 3-year-old's height; 2.2: a caregiver's, 1.7 m); masses, torques and the rest
    # follow the scaling laws of docs/bodies.md.
    scale: float = 1.0
    # Multiplies every motor's maximum torque (muscles: maximum force) on top of the size law.
    strength: float = 1.0
    # "infant" or "adult" (a caregiver from adult anthropometry, docs/bodies.md)
    body: str = "infant"
    # The infant's age in months (0 to 33): every segment from the growth curves; None: the
    # published 18-month-old, unchanged. Only for body="infant".
    age_months: float | None = None
    # The infant's motor age in months (0 to 33): motor strength (each motor's torque limits,
    # each muscle's fmax) and the sensorimotor delays of delays="developmental". A joint's
    # strength at body age B and motor age M is the volume-law strength of the body grown to M
    # (what a fresh build at age M has): the motor develops as in a typical infant of age M.
    # None: follows age_months (18 for the published body). Only for body="infant".
    motor_age_months: float | None = None
    # Sensorimotor delays: None (none), "developmental" (published figures for the agent's age,
    # docs/bodies.md) or a mapping channel -> milliseconds for channels of DELAY_CHANNELS
    # (missing channels: 0); applied in whole control steps.
    delays: Any = None

    def __post_init__(self):
        put = partial(object.__setattr__, self)
        check_choice("", "hands", self.hands, HAND_VERSIONS)
        check_choice("", "actuation", self.actuation, ACTUATION_MODELS)
        check_choice("", "posture", self.posture, POSTURES)
        put("expressions", check_bool("", "expressions", self.expressions))
        put("voice", check_bool("", "voice", self.voice))
        for sense in SENSES:   # each sense: None (off) or its config (True / a mapping: parsed)
            put(sense, _parse_sense(sense, getattr(self, sense)))
        if self.position is not None:
            put("position", check_numbers("", "position", self.position, 2, -FLOOR_HALF,
                                          FLOOR_HALF, f"None or (x, y) in metres on the floor, "
                                          f"each from {-FLOOR_HALF:g} to {FLOOR_HALF:g}"))
        if self.facing is not None:
            put("facing", check_numbers("", "facing", self.facing, 2, -FACING_LIMIT,
                                        FACING_LIMIT, f"None or a point (x, y) in metres to "
                                        f"face, each from {-FACING_LIMIT:g} to {FACING_LIMIT:g}"))
        if self.clothes_rgba is not None:
            put("clothes_rgba", check_numbers("", "clothes_rgba", self.clothes_rgba, 4, 0.0, 1.0,
                                              "None or (red, green, blue, alpha), each from 0 "
                                              "to 1"))
        put("scale", check_number("", "scale", self.scale, *SCALE_RANGE))
        put("strength", check_number("", "strength", self.strength, *STRENGTH_RANGE))
        check_choice("", "body", self.body, BODIES)
        if self.age_months is not None:
            if self.body != "infant":
                raise ConfigError(f"age_months={show(self.age_months)} is for infant bodies; "
                                  f"body={self.body!r} takes None")
            put("age_months", check_number("", "age_months", self.age_months, *AGE_RANGE))
        if self.motor_age_months is not None:
            if self.body != "infant":
                raise ConfigError(f"motor_age_months={show(self.motor_age_months)} is for "
                                  f"infant bodies; body={self.body!r} takes None")
            put("motor_age_months", check_number("", "motor_age_months",
                                                  self.motor_age_months, *AGE_RANGE))
        put("delays", _parse_delays(self.delays))

    @property
    def age(self) -> float | None:
        """The age in months the senses and delays follow: ``age_months``, 18 for the
        published infant (``age_months=None``), None for an adult."""
        if self.body == "adult":
            return None
        return 18.0 if self.age_months is None else self.age_months

    @property
    def motor_age(self) -> float | None:
        """The age in months the motors and the developmental delays follow:
        ``motor_age_months``, else :attr:`age`; None for an adult."""
        if self.body == "adult":
            return None
        return self.age if self.motor_age_months is None else self.motor_age_months


def _parse_delays(value):
    """None, "developmental", or a dict channel -> milliseconds (float) for the channels given."""
    if value is None or (isinstance(value, str) and value == "developmental"):
        return value
    if not isinstance(value, Mapping):
        raise ConfigError(f"delays={show(value)} not allowed; allowed: None, 'developmental' or a "
                          f"mapping of {list(DELAY_CHANNELS)} to milliseconds, each from 0 to "
                          f"{DELAY_LIMIT_MS:g}")
    unknown = sorted((k for k in value if k not in DELAY_CHANNELS), key=str)
    if unknown:
        raise ConfigError(f"delays: unknown channel(s) {unknown}; allowed: {list(DELAY_CHANNELS)}")
    return {k: check_number("delays", k, value[k], 0.0, DELAY_LIMIT_MS)
            for k in DELAY_CHANNELS if k in value}


_NO_FIELD = sorted(set(SENSES) - {f.name for f in fields(AgentConfig)})
if _NO_FIELD:  # a registered sense is switched by an AgentConfig field of its name
    raise TypeError(f"senses {_NO_FIELD} are registered but AgentConfig has no field for them")


def _parse_sense(name: str, value):
    cls = SENSES[name].config
    if value is None or (isinstance(value, (bool, np.bool_)) and not value):
        return None
    if isinstance(value, (bool, np.bool_)):
        return cls()
    if isinstance(value, cls):
        return value
    if isinstance(value, Mapping):
        return _from_mapping(cls, name, value)
    raise ConfigError(f"{name}={show(value)}; allowed: False, True or a mapping of "
                      f"{[f.name for f in fields(cls)]}")


def _agent_config(settings: Mapping[str, Any], where: str) -> AgentConfig:
    names = [f.name for f in fields(AgentConfig)]
    unknown = sorted(set(settings) - set(names), key=str)
    if unknown:
        raise ConfigError(f"{where}: unknown agent setting(s) {unknown}; allowed: {names}")
    try:
        return AgentConfig(**settings)
    except ConfigError as e:
        raise ConfigError(f"{where}: {e}") from None


def resolve_agents(n_agents: int, common: Mapping[str, Any],
                   per_agent: Sequence[Mapping[str, Any]] | None = None,
                   task_defaults: Sequence[Mapping[str, Any]] | None = None) -> list[AgentConfig]:
    """Agent configs from task defaults, then settings for all agents, then per-agent ones."""
    if per_agent is not None:
        if isinstance(per_agent, (str, bytes, Mapping)) or not isinstance(per_agent, Sequence) \
                or len(per_agent) != n_agents:
            raise ConfigError(f"per_agent must be a list of {n_agents} mappings (one per agent), "
                              f"got {show(per_agent)}")
    out = []
    for i in range(n_agents):
        settings = dict(task_defaults[i]) if task_defaults else {}
        settings.update(common)
        if per_agent is not None:
            if not isinstance(per_agent[i], Mapping):
                raise ConfigError(f"per_agent[{i}] must be a mapping, got {show(per_agent[i])}")
            settings.update(per_agent[i])
        who = agent_names([c.body for c in out] + [settings.get("body")])[-1]
        out.append(_agent_config(settings, f"agent {who}"))
    return out


#: The physics settings that hold: beyond them a body at the largest allowed strength (3) diverged
#: under bang-bang actions (docs/reliability.md, "Instability": every case of
#: tests/body/test_hand_stability.py, 600 control steps, seeds 0-2, each setting at its limit
#: alone and all at their limits together: 0 divergences; e.g. 4 Newton iterations, 16 CG
#: iterations, a timestep of 0.0125 s or a tolerance of 1 diverged).
TIMESTEP_MAX = 0.006                                   # s
TOLERANCE_MAX = 1e-3
MIN_ITERATIONS = {"newton": 10, "cg": 32, "pgs": 1}    # solver iterations per physics step
UNSTABLE = ("outside it a body at strength 3 diverged under bang-bang actions: "
            "docs/reliability.md, 'Instability'")


@dataclass(frozen=True)
class PhysicsConfig:
    timestep: float = 0.005        # s per physics step
    frame_skip: int = 2            # physics steps per control step (control at 100 Hz)
    # sparse: MuJoCo >= 4.0.1 (4.0.0's sparse Cholesky factorization, mujoco#3767, made the
    # Newton solver diverge when contacts coupled branches of a body tree, so "dense" was the
    # default then): 0 divergences in 27 bang-bang runs of 10k control steps (docs/reliability.md)
    # and the fastest physics: 0.88x dense's time for one infant, 0.59x for eight; MuJoCo Warp
    # takes no dense Jacobian above 60 degrees of freedom
    jacobian: str = "sparse"
    solver: str = "newton"         # MuJoCo's constraint solver
    cone: str = "pyramidal"        # the friction cone
    iterations: int = 50           # solver iterations per physics step, at most
    tolerance: float = 1e-8        # the solver stops early below this improvement
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)   # m/s^2

    def __post_init__(self):
        put = partial(object.__setattr__, self)
        put("timestep", check_number("physics", "timestep", self.timestep, 1e-4, TIMESTEP_MAX,
                                     why=UNSTABLE))
        put("frame_skip", check_int("physics", "frame_skip", self.frame_skip, 1, 100))
        for key, allowed in (("jacobian", ("dense", "sparse", "auto")),
                             ("solver", ("newton", "cg", "pgs")),
                             ("cone", ("pyramidal", "elliptic"))):
            check_choice("physics", key, getattr(self, key), allowed)
        low = MIN_ITERATIONS[self.solver]
        put("iterations", check_int("physics", "iterations", self.iterations, low, 1000,
                                    why=f"with solver={self.solver!r}" + (
                                        f"; {UNSTABLE}" if low > 1 else "")))
        put("tolerance", check_number("physics", "tolerance", self.tolerance, 0.0, TOLERANCE_MAX,
                                      why=UNSTABLE))
        put("gravity", check_numbers("physics", "gravity", self.gravity, 3, -100.0, 100.0,
                                     "(x, y, z) in m/s^2, each from -100 to 100"))


def parse_physics(value, task_overrides: Mapping[str, Any] | None = None) -> PhysicsConfig:
    base = dict(task_overrides or {})
    if value is None:
        pass
    elif isinstance(value, PhysicsConfig):
        base.update(dataclasses.asdict(value))
    elif isinstance(value, Mapping):
        names = [f.name for f in fields(PhysicsConfig)]
        unknown = sorted(set(value) - set(names), key=str)
        if unknown:
            raise ConfigError(f"physics: unknown setting(s) {unknown}; allowed: {names}")
        base.update(value)
    else:
        raise ConfigError(f"physics={show(value)} not allowed; allowed: None, a PhysicsConfig "
                          f"or a mapping of physics settings {[f.name for f in fields(PhysicsConfig)]}")
    return PhysicsConfig(**base)


RENDER_SIZE_RANGE = (8, 4096)   # pixels, each side of render()'s image
MAX_STEPS_LIMIT = 10**9


def env_settings(render_mode, max_steps, render_size, default_max_steps: int,
                 render_modes: Sequence[str]) -> tuple[str | None, int, tuple[int, int]]:
    """The env's own settings checked and made canonical: ``render_mode`` (None or one of
    ``render_modes``), ``max_steps`` (None: ``default_max_steps``; else an integer >= 1) and
    ``render_size`` ((height, width) in pixels, integers); a ConfigError naming the setting."""
    if render_mode is not None:
        check_choice("env", "render_mode", render_mode, tuple(render_modes))
    steps = default_max_steps if max_steps is None else max_steps
    steps = check_int("env", "max_steps", steps, 1, MAX_STEPS_LIMIT)
    lo, hi = RENDER_SIZE_RANGE
    if isinstance(render_size, (str, bytes, Mapping)) or not isinstance(render_size, Sequence) \
            or len(render_size) != 2:
        raise ConfigError(f"env: render_size={show(render_size)} not allowed; allowed: "
                          f"(height, width) in pixels, integers from {lo} to {hi}")
    size = tuple(check_int("env", f"render_size[{k}]", v, lo, hi)
                 for k, v in enumerate(render_size))
    return render_mode, steps, size
