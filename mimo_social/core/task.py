"""What a task is: scene additions, placement, held joints, reset randomisation, rewards, ends.

A task never touches MuJoCo names at run time: it reads the world's integer index tables.
One-agent tasks (reach ...) are tasks like any other; the Gymnasium adapter wraps the same env.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Callable, ClassVar, Mapping, Sequence

import mujoco
import numpy as np
from gymnasium import spaces

from ..util.checks import (ConfigError, check_bool, check_choice, check_int, check_number,
                           check_numbers)
from ..body.tables import load_body
from ..util.names import agent_names
from .config import AgentConfig
from .world import AgentSetup, Prop

__all__ = ["Task", "TaskOptions", "Plot", "REWARD", "agent_user_settings", "check_start_poses",
           "deepest_overlap", "OVERLAP_DEPTH"]

#: m: how deep any part of one agent may be inside any part of another when the env is made and
#: after every reset; deeper: a ConfigError (agents placed inside each other: MuJoCo pushes them
#: apart violently at the first step, and a head inside a thigh or crossed limbs are no start).
#: Contacts' own softness (millimetres) and a touch placed on purpose stay within it.
OVERLAP_DEPTH = 0.01

#: what a hook's ``env`` is: the :class:`~mimo_social.core.env.MimoParallelEnv` running the task
#: (its public view: ``world``, ``systems``, ``system(name)``, ``actuation``, ``controls``,
#: ``steps``, ``dt``, ``max_steps``, ``possible_agents``)
EnvView = Any


#: the name of the reward plot (:meth:`Plot.reward`)
REWARD = "reward"


@dataclasses.dataclass(frozen=True)
class Plot:
    """A time series that a task wants in a replay (:meth:`Task.plots`): the recorder logs it
    at every recorded step after an env step (none at reset) and its default layout shows it in a
    view of its own, one line per agent in the agent's clothes colour.

    ``name``: the series' name (the view's title, with ``unit``; logged at
    ``/plots/<name>/<agent>``, or ``/plots/<name>`` for one value). ``fn(env)``: the value(s)
    after the step just made (the task's state then, e.g. what ``rewards`` computed): with
    ``per_agent`` one number per agent (a sequence of ``n_agents``; NaN: none this step), else
    one number; keep it cheap (it runs at every recorded step). ``fn=None`` is the reward the env
    returned (:meth:`reward`, logged at ``/agents/<agent>/reward``). ``agents``: with
    ``per_agent``, the agent indices that get a line (None: all)."""

    name: str
    unit: str = ""
    fn: Callable[[Any], Any] | None = None
    per_agent: bool = True
    agents: tuple[int, ...] | None = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name or "/" in self.name:
            raise ConfigError(f"Plot: name={self.name!r}; allowed: a non-empty name without '/'")
        if self.fn is None and self.name != REWARD:
            raise ConfigError(f"Plot {self.name!r}: fn=None; allowed: a function env -> value(s) "
                              f"(None only for the reward plot, Plot.reward())")
        if self.fn is not None and not callable(self.fn):
            raise ConfigError(f"Plot {self.name!r}: fn={self.fn!r}; allowed: a function "
                              "env -> value(s)")
        if self.agents is not None:
            agents = tuple(self.agents)
            if not self.per_agent or not agents or not all(
                    isinstance(i, (int, np.integer)) and i >= 0 for i in agents):
                raise ConfigError(f"Plot {self.name!r}: agents={self.agents!r}; allowed: None, "
                                  "or with per_agent a non-empty list of agent indices")
            object.__setattr__(self, "agents", tuple(int(i) for i in agents))

    @property
    def title(self) -> str:
        """The view's title: the name and the unit."""
        return f"{self.name} ({self.unit})" if self.unit else self.name

    @classmethod
    def reward(cls, shared: bool = False) -> "Plot":
        """The reward the env returned, one line per agent; ``shared``: the agents always get
        the same reward, shown as one line (two equal lines would hide each other)."""
        return cls(REWARD, "", None, per_agent=not shared)


@dataclasses.dataclass(frozen=True)
class TaskOptions:
    """A task's options: a frozen dataclass, one field per option with its default.

    A task declares ``Options = <its TaskOptions subclass>``; the subclass names its task in
    ``task`` and checks (and normalises) every field in ``__post_init__`` with the helpers below,
    so a bad value raises a :class:`~mimo_social.util.checks.ConfigError` naming the task, the
    option, the value and what is allowed when the options are made.
    ``dataclasses.replace(options, x=...)`` checks again.
    """

    task: ClassVar[str] = "task"
    #: the options that give a learner a privileged cue: something of its partner or of its
    #: target that its own senses would not tell it (e.g. ``assisted_gaze``: the task aims the
    #: learner's head and eyes at the partner's hand, so the hand's place is in its
    #: proprioception). Each is a bool, off by default; the task table's ``privileged cues`` row
    #: names each one (tests/conformance/test_privileged.py checks both).
    privileged: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def of(cls, given: "TaskOptions | Mapping[str, Any] | None" = None) -> "TaskOptions":
        """These options from an instance, or from a mapping option name -> value (missing ones
        take their defaults; an unknown name raises, listing the allowed ones)."""
        if isinstance(given, cls):
            return given
        if given is None:
            given = {}
        if not isinstance(given, Mapping):
            raise ConfigError(f"{cls.task}: task_options={given!r} not allowed; allowed: a dict "
                              f"of option name -> value, or a {cls.__qualname__}")
        allowed = sorted(f.name for f in dataclasses.fields(cls))
        unknown = sorted(set(given) - set(allowed), key=str)
        if unknown:
            raise ConfigError(f"{cls.task}: task_options: unknown task option(s) {unknown}; allowed: {allowed}")
        return cls(**given)

    def as_dict(self) -> dict[str, Any]:
        """Option name -> value."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    # -- checks for __post_init__: each stores the checked value --------------------------------
    def _put(self, name: str, value: Any) -> None:
        object.__setattr__(self, name, value)

    def _label(self, name: str) -> str:
        return f"task option {name}"

    def _number(self, name: str, lo: float | None = None, hi: float | None = None) -> None:
        self._put(name, check_number(self.task, self._label(name), getattr(self, name), lo, hi))

    def _int(self, name: str, lo: int | None = None, hi: int | None = None) -> None:
        self._put(name, check_int(self.task, self._label(name), getattr(self, name), lo, hi))

    def _bool(self, name: str) -> None:
        self._put(name, check_bool(self.task, self._label(name), getattr(self, name)))

    def _choice(self, name: str, allowed: Sequence) -> None:
        check_choice(self.task, self._label(name), getattr(self, name), allowed)

    def _numbers(self, name: str, n: int, lo: float | None = None, hi: float | None = None,
                 rising: bool = False, allowed: str = "") -> None:
        """A sequence of ``n`` numbers in [lo, hi] (``rising``: each >= the one before),
        stored as a tuple of floats; ``allowed`` says what they mean in the error."""
        value = getattr(self, name)
        what = allowed or f"{n} numbers" + (" from low to high" if rising else "")
        out = check_numbers(self.task, self._label(name), value, n, lo, hi, what)
        if rising and any(b < a for a, b in zip(out, out[1:])):
            raise ConfigError(f"{self.task}: {self._label(name)}={value!r} not allowed; "
                              f"allowed: {what}")
        self._put(name, out)

    def _names(self, name: str, what: str) -> None:
        """None or a non-empty sequence of distinct strings (stored as a tuple)."""
        value = getattr(self, name)
        if value is None:
            return
        if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, Sequence) \
                or not len(value) or not all(isinstance(x, str) for x in value) \
                or len(set(value)) != len(value):
            raise ConfigError(f"{self.task}: {self._label(name)}={value!r} not allowed; "
                              f"allowed: None or a non-empty list of distinct {what}")
        self._put(name, tuple(value))

    def _name(self, name: str, what: str) -> None:
        """None or a string."""
        value = getattr(self, name)
        if value is not None and not isinstance(value, str):
            raise ConfigError(f"{self.task}: {self._label(name)}={value!r} not allowed; "
                              f"allowed: None or {what}")


def agent_user_settings(n_agents: int, common: Mapping[str, Any],
                        per_agent: Sequence[Mapping[str, Any]] | None) -> list[dict]:
    """Each agent's settings as the user gave them, unchecked: the settings for all agents, then
    its ``per_agent`` entry (what :meth:`Task.agent_defaults` sees). A malformed ``per_agent``
    counts as absent here; the env's config check reports it."""
    out = []
    ok = isinstance(per_agent, Sequence) and not isinstance(per_agent, (str, Mapping)) \
        and len(per_agent) == n_agents
    for i in range(n_agents):
        own = per_agent[i] if ok and isinstance(per_agent[i], Mapping) else {}
        out.append({**common, **own})
    return out


def _xy(p) -> str:
    return f"({p[0]:.3g}, {p[1]:.3g})"


def deepest_overlap(world, data, depth: float = OVERLAP_DEPTH):
    """The deepest interpenetration deeper than ``depth`` (m) between geoms of different agents
    that collide (``contype`` or ``conaffinity`` set) in ``data``'s kinematics, as ``(depth, (i,
    geom), (j, geom))`` with agent ``i < j``; None if there is none. MuJoCo's own distance
    (``mj_geomDistance``) for the pairs whose bounding spheres overlap that deep: contacts alone
    would miss two held bodies (both welded to the world, MuJoCo makes no contact between
    them)."""
    m = world.model
    solid = (m.geom_contype | m.geom_conaffinity) != 0
    geoms = [np.flatnonzero(solid & (world.geom_agent == i)) for i in range(len(world.agents))]
    best = None
    for i, gi in enumerate(geoms):
        for j in range(i + 1, len(geoms)):
            gj = geoms[j]
            gap = (np.linalg.norm(data.geom_xpos[gi][:, None] - data.geom_xpos[gj][None], axis=2)
                   - m.geom_rbound[gi][:, None] - m.geom_rbound[gj][None])
            for p, q in zip(*np.nonzero(gap < -depth)):
                dist = mujoco.mj_geomDistance(m, data, int(gi[p]), int(gj[q]), 0.0, None)
                if -dist > depth and (best is None or -dist > best[0]):
                    best = (-dist, (i, int(gi[p])), (j, int(gj[q])))
    return best


def _who(name: str, config) -> str:
    age = "" if config.age_months is None else f", age_months={config.age_months:g}"
    return (f"{name} (body={config.body!r}{age}, posture={config.posture!r}, "
            f"scale={config.scale:g})")


def check_start_poses(world, data=None, when: str = "at the start") -> None:
    """A ConfigError naming both agents, the two body parts, how deep and where the agents
    stand when any part of one agent is more than :data:`OVERLAP_DEPTH` inside any part of
    another (:func:`deepest_overlap` in ``data``, e.g. right after a reset's ``mj_forward``,
    else in a scratch copy of the world's start state); naming the agent when it was told to
    face its own position. ``when`` says which state it was."""
    setups = world.agent_setups
    if data is None:
        for name, s in zip(world.names, setups):
            if s.config.facing is not None and np.allclose(s.facing, s.position):
                raise ConfigError(f"agent {name}: facing={_xy(s.facing)} is its own position; "
                                  "allowed: None or a point (x, y) other than where it stands")
    if len(setups) < 2:
        return
    d = world.scratch_contacts() if data is None else data
    found = deepest_overlap(world, d)
    if found is None:
        return
    depth, (i, gi), (j, gj) = found
    m, names = world.model, world.names
    part = [m.body(int(m.geom_bodyid[g])).name[len(names[x]) + 1:] for x, g in ((i, gi), (j, gj))]
    where = [_xy(d.xpos[world.agents[x].root_body]) for x in (i, j)]
    raise ConfigError(
        f"agents {_who(names[i], setups[i].config)} and {_who(names[j], setups[j].config)} "
        f"overlap: placed at {where[0]} and {where[1]} m, the {part[0]} of {names[i]} is "
        f"{100 * depth:.1f} cm inside the {part[1]} of {names[j]} {when} (allowed: at most "
        f"{100 * OVERLAP_DEPTH:g} cm, any two parts of different agents); place them farther "
        "apart (their position settings, or the task's distance option) or leave position=None "
        "to the task")


class Task:
    """Base task: N infants on the floor, reward 0, never terminates (truncated at max_steps).

    ``Task(n_agents, options)`` or ``Task(n_agents, **options)``: ``options`` is an instance of
    the task's :attr:`Options` dataclass or a dict; ``task.options`` is the checked instance.
    """

    name = "task"
    n_agents_range = (1, 8)
    default_n_agents = 2
    default_max_steps = 1000
    physics_overrides: Mapping[str, Any] = {}
    Options: ClassVar[type[TaskOptions]] = TaskOptions

    def __init__(self, n_agents: int, options: TaskOptions | Mapping[str, Any] | None = None,
                 /, **values):
        lo, hi = self.n_agents_range
        if isinstance(n_agents, bool) or not isinstance(n_agents, (int, np.integer)) \
                or not lo <= n_agents <= hi:
            raise ConfigError(f"{self.name}: n_agents={n_agents!r}; allowed: {lo} to {hi}")
        if options is not None and values:
            raise ConfigError(f"{self.name}: task options given both as {options!r} and as "
                              f"keywords {sorted(values)}; give them one way")
        self.n_agents = int(n_agents)
        self.options = self.Options.of(options if options is not None else values)
        self.configs: Sequence[AgentConfig] = ()  # every agent's config, set by the env

    # -- building ------------------------------------------------------------------------------
    def agent_name(self, i: int) -> str:
        """Agent i's name in the world being built (``infant_<j>`` or, for an adult,
        ``caregiver_<j>``), from :attr:`configs`, for messages before the world exists."""
        return agent_names([c.body for c in self.configs])[i]

    def agent_defaults(self, i: int, settings: Mapping[str, Any]) -> dict:
        """Default settings of agent i that this task wants; the user's settings override them.

        ``settings``: agent i's settings as the user gave them (for all agents, then its
        ``per_agent`` entry; unchecked), for defaults that depend on them (e.g. a skin that
        follows the chosen hands)."""
        return {}

    def setup(self, i: int, config: AgentConfig) -> AgentSetup:
        pos, facing = self.placement(i, self.configs)
        return AgentSetup(config, position=config.position or pos,
                          facing=config.facing or facing)

    # How far (m) an infant of scale 1 in each posture reaches forward from its hip along the
    # floor, and its half width with arms and legs; both grow with the agent's `scale`. The
    # circle is made large enough that no two infants start interpenetrating (their forward
    # parts converge toward the centre).
    POSTURE_REACH = {"standing": 0.22, "sitting": 0.45, "lying": 0.48}
    HALF_WIDTH = 0.2
    CLEARANCE = 0.14

    @staticmethod
    def body_size(config: AgentConfig) -> float:
        """The agent's size relative to the published 18-month infant: its ``scale`` times its
        body's standing height (of its age, or the adult's) over the infant's (1 for the
        published infant, exactly)."""
        c = config
        own = load_body(c.hands, age_months=c.age_months, body=c.body).standing_height
        return c.scale * (own / load_body(c.hands).standing_height)

    def placement(self, i: int, configs: Sequence[AgentConfig] = ()) -> tuple:
        """Agents on a circle around the origin, each facing the centre.

        The radius leaves room for the largest agent's reach and half width (both times its
        size, :meth:`body_size`: its ``scale``, age and body; a posture without a reach of its
        own, e.g. kneeling, takes the largest)."""
        if self.n_agents == 1:
            return (0.0, 0.0), (1.0, 0.0)
        far = max(self.POSTURE_REACH.values())
        reach = max((self.POSTURE_REACH.get(c.posture, far) * self.body_size(c)
                     for c in configs), default=self.POSTURE_REACH["standing"])
        half = max((self.HALF_WIDTH * self.body_size(c) for c in configs),
                   default=self.HALF_WIDTH)
        sin = np.sin(np.pi / self.n_agents)
        radius = max(0.3, reach + self.CLEARANCE / sin, half / sin)
        angle = np.pi + 2 * np.pi * i / self.n_agents
        pos = (radius * np.cos(angle), radius * np.sin(angle))
        return (float(pos[0]), float(pos[1])), (0.0, 0.0)

    def props(self) -> list[Prop]:
        return []

    #: the world this task's index tables were made for (set by the env with :meth:`bind`)
    bound_world = None

    def bind(self, env: EnvView) -> None:
        """Resolve names to this world's integer index tables (bodies, geoms, qpos and dof
        addresses, sensors, the shared sense systems a task reads). The env calls it once, after
        its world and senses are built and before the first reset, and again only when this
        task object is reset in another env (then :attr:`bound_world` is that env's world).
        The base binds nothing."""

    def task_spaces(self, env: EnvView, i: int) -> dict[str, spaces.Space]:
        """Extra observation keys of this task for agent i."""
        return {}

    # -- running -------------------------------------------------------------------------------
    def reset(self, env: EnvView, rng: np.random.Generator) -> None:
        """Randomise the initial state (the world has been reset to its initial pose)."""

    def before_physics(self, env: EnvView) -> None:
        """Called once per control step after the actions were applied."""

    def observe(self, env: EnvView, i: int) -> dict[str, np.ndarray]:
        return {}

    def rewards(self, env: EnvView) -> np.ndarray:
        return np.zeros(self.n_agents)

    def terminations(self, env: EnvView) -> tuple[np.ndarray, list[dict]]:
        """Per agent: terminated?, and task infos."""
        return np.zeros(self.n_agents, bool), [{} for _ in range(self.n_agents)]

    # -- replay --------------------------------------------------------------------------------
    def plots(self) -> list[Plot]:
        """The time series a replay shows for this task (:class:`Plot`); the base: the reward.
        A task names what tells its story (a distance, a success, a phase ...)."""
        return [Plot.reward()]
