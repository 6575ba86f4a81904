"""What the benchmark runs: the configurations, the components a run is split into, the run's
constants, the package's speed targets and the original MIMo's figures they are compared with.

The configurations (:data:`CONFIGS`; the default set is every one but ``jacobian_*``):

* the MIMo paper's grid (its Sec. VI-B, Fig. 6): one infant with mitten hands and
  spring-damper actuation, two free objects (free play with ``props``), random actions, every
  sense, episodes of one simulated minute, a Rerun recording of the run; vision
  {64, 128, 256, 512}^2 at touch x1 (``v64``, ``v128``, ``default``, ``v512``) and touch density
  {x0.25, x0.5, x1, x2} at vision 256^2 (``t0.25``, ``t0.5``, ``default``, ``t2``);
  ``no_vision`` (touch x1, no eyes: the paper's "without vision");
* ``physics_only``, the floor: the same scene stepped by a bare ``mujoco.mj_step`` loop with the
  same actions written straight into ``data.ctrl`` as torques;
* ``basic_1``: one infant, physics + proprioception + vestibular, not recorded;
* every env of the catalogue (:data:`mimo_social.envs.catalog.CATALOG`) by its task name with
  its defaults, recorded: a new catalogue line is benchmarked with no change here;
* the other bodies, as ``default`` otherwise: ``five_fingers`` (``hands="five_fingers"``) and
  ``muscle`` (``actuation="muscle"``);
* scaling: ``agents_1``, ``agents_2``, ``agents_4``, ``agents_8`` infants in one world with every
  sense (vision 64^2, touch x1), as the grid otherwise (``agents_1`` is ``v64``: the two are the
  run's noise check);
* ``playroom_2``: ``agents_2`` in the play room (``scene="playroom"``, docs/playroom.md);
* ``jacobian_dense_1`` ... ``jacobian_sparse_4``: the dense against the sparse constraint
  Jacobian (free play without props or recording; only with ``--only``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Mapping

from ..core.env import TIMING_KEYS
from ..envs.catalog import CATALOG, entry
from ..senses import SENSES

__all__ = [
    "COMPONENTS", "ENV_COMPONENTS", "CHUNK", "WARMUP_STEPS", "EPISODE_STEPS",
    "DEFAULT_SIM_SECONDS", "MIMO_REFERENCE", "TARGETS", "BenchConfig", "CONFIGS",
    "DEFAULT_CONFIGS", "check_names", "mimo_reference",
]

#: What a configuration's total is split into (they sum to the total): physics, actuation, each
#: sense of the registry (:data:`mimo_social.senses.SENSES`, in its order), recording, task and
#: the rest.
COMPONENTS = ("physics", "actuation", *SENSES, "recording", "task", "other")
#: The components the env times itself (``env.timing``, :data:`mimo_social.core.env.TIMING_KEYS`)
#: but its own remainder (``other``: this benchmark's ``other`` is all that is not timed).
ENV_COMPONENTS = tuple(key for key in TIMING_KEYS if key != "other")

#: Steps per timed chunk; the progress bar is updated between chunks, outside the timer.
CHUNK = 100
#: Control steps run (and thrown away) before the timed loop of every configuration.
WARMUP_STEPS = 20
#: Episode length of the grid and scaling configurations: one simulated minute at 100 Hz.
EPISODE_STEPS = 6000
#: Simulated seconds per configuration by default: one episode (the paper ran one hour).
DEFAULT_SIM_SECONDS = 60.0

#: The original MIMo, measured on this machine (real s per simulated s; build times in s).
MIMO_REFERENCE = {
    "default": 12.0,             # one infant, 2 x 256^2 eyes, touch x1, two objects
    "without_vision": 0.30,      # the same without the eyes
    "physics_only": 0.08,
    "build_with_touch_s": 120.0,
    "build_without_touch_s": 6.0,
}

#: Targets of this package (see BENCHMARKS.md).
TARGETS = {
    "default_max": 0.5,            # 2 x 256^2 eyes, touch x1: under 0.5 real s per simulated s
    "agents_1_max": 0.04,          # one infant, physics + proprioception + vestibular
    "build_2_agents_max_s": 2.0,   # building a 2-infant env
    "scaling_per_infant_max": 1.25,  # N infants cost at most 1.25 N times one ("close to linear")
}


@dataclass(frozen=True)
class BenchConfig:
    """One benchmarked configuration: a catalogue env (its task name) and its keyword
    arguments."""

    name: str
    task: str                        # a task name of the catalogue, e.g. "free_play"
    kwargs: Mapping[str, Any] = field(default_factory=dict)
    description: str = ""
    raw_physics: bool = False        # True: time a bare mj_step loop on the env's model
    record: bool = False             # True: record the run with the Rerun recorder
    group: str = "other"             # grid, tasks, bodies, scaling, jacobian (plots and tables)
    default: bool = True             # in the default set (no --only)

    def make_env(self):
        # text infos: the runner reports an instability's reason
        return entry(self.task).parallel_env(**{"info_text": True, **deep_copy(self.kwargs)})

    @property
    def has_touch(self) -> bool:
        return not self.raw_physics and self.kwargs.get("touch") not in (None, False)

    def key(self) -> str:
        """What makes two configurations the same run (everything but name and description)."""
        return json.dumps([self.task, deep_copy(self.kwargs), self.raw_physics, self.record],
                          sort_keys=True)


def deep_copy(x):
    """Nested mappings and sequences as fresh dicts and lists (plain JSON)."""
    if isinstance(x, Mapping):
        return {k: deep_copy(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [deep_copy(v) for v in x]
    return x


def _scene(name, description, *, n=1, vision=256, touch=1.0, group="grid", raw=False,
           record=True, **extra):
    """The paper's scene: ``n`` infants, two free objects, every sense, 1-minute episodes."""
    kwargs = {"n_agents": n, "task_options": {"props": True}, "max_steps": EPISODE_STEPS,
              "proprioception": True, "vestibular": True, "expressions": True, **extra}
    if vision:
        kwargs["vision"] = {"width": vision, "height": vision}
    if touch:
        kwargs["touch"] = {"density": touch}
    return BenchConfig(name, "free_play", kwargs, description, raw, record and not raw, group)


def _jacobian(name, n, jacobian):
    kwargs = {"n_agents": n, "proprioception": True, "vestibular": True, "expressions": True,
              "physics": {"jacobian": jacobian}}
    return BenchConfig(name, "free_play", kwargs,
                       f"free play, {n} infant(s), no props, proprioception + vestibular, "
                       f"physics jacobian={jacobian!r}", group="jacobian", default=False)


def _task(e) -> BenchConfig:
    """A catalogue env with its defaults, recorded."""
    return BenchConfig(e.name, e.name, {}, f"{e.summary} ({e.module_name} defaults), recorded",
                       record=True, group="tasks")


_GRID = "1 infant, mitten hands, spring-damper, 2 objects, recorded"
CONFIGS: dict[str, BenchConfig] = {c.name: c for c in (
    _scene("v64", f"{_GRID}; vision 64x64, touch x1", vision=64),
    _scene("v128", f"{_GRID}; vision 128x128, touch x1", vision=128),
    _scene("default", f"{_GRID}; vision 256x256, touch x1 (the paper's default)"),
    _scene("v512", f"{_GRID}; vision 512x512, touch x1", vision=512),
    _scene("t0.25", f"{_GRID}; vision 256x256, touch x0.25", touch=0.25),
    _scene("t0.5", f"{_GRID}; vision 256x256, touch x0.5", touch=0.5),
    _scene("t2", f"{_GRID}; vision 256x256, touch x2", touch=2.0),
    _scene("no_vision", f"{_GRID}; no vision, touch x1", vision=None),
    _scene("physics_only", "the grid's scene (1 infant, 2 objects), bare mujoco.mj_step loop "
           "(the floor)", vision=None, touch=None, raw=True),
    BenchConfig("basic_1", "free_play",
                {"n_agents": 1, "proprioception": True, "vestibular": True, "expressions": True},
                "1 infant, free play, physics + actuation + proprioception + vestibular, not "
                "recorded (the foundation's target)", group="tasks"),
    *(_task(e) for e in CATALOG),
    _scene("five_fingers", "as default with five-fingered hands", group="bodies",
           hands="five_fingers"),
    _scene("muscle", "as default with the muscle model (controls in [0, 1], 2 per motor)",
           group="bodies", actuation="muscle"),
    _scene("agents_1", "1 infant, every sense (vision 64x64, touch x1), 2 objects, recorded "
           "(= v64)", vision=64, group="scaling"),
    _scene("agents_2", "2 infants in one world (as agents_1)", n=2, vision=64, group="scaling"),
    _scene("agents_4", "4 infants in one world (as agents_1)", n=4, vision=64, group="scaling"),
    _scene("agents_8", "8 infants in one world (as agents_1)", n=8, vision=64, group="scaling"),
    _scene("playroom_2", "2 infants in the play room (scene='playroom': furniture, 9 toys; as "
           "agents_2 otherwise)", n=2, vision=64, group="scenes", scene="playroom"),
    _jacobian("jacobian_dense_1", 1, "dense"),
    _jacobian("jacobian_sparse_1", 1, "sparse"),
    _jacobian("jacobian_dense_4", 4, "dense"),
    _jacobian("jacobian_sparse_4", 4, "sparse"),
)}
DEFAULT_CONFIGS = [name for name, c in CONFIGS.items() if c.default]


def check_names(names) -> list[str]:
    """The configurations to run: ``None`` the default set, ``"all"`` every one, else the
    named ones (a comma-separated string or a sequence), each once; a ValueError naming every
    allowed one for an unknown name."""
    if names is None:
        return list(DEFAULT_CONFIGS)
    if isinstance(names, str):
        names = names.split(",")
    names = [n.strip() for n in names if n.strip()]
    if names == ["all"]:
        return list(CONFIGS)
    unknown = [n for n in names if n not in CONFIGS]
    if unknown or not names:
        raise ValueError(f"unknown benchmark configuration(s) {unknown or names}; "
                         f"allowed: {', '.join(sorted(CONFIGS))} (or 'all')")
    return list(dict.fromkeys(names))


def mimo_reference(result) -> dict | None:
    """The published MIMo's figure on this machine that a result is compared with: physics
    alone for the floor, the default configuration (2 x 256^2 eyes, touch) for anything with
    eyes, the configuration without vision otherwise. The comparison is of the whole total (all
    infants of a multi-infant world against one original MIMo)."""
    senses = result.get("senses") or {}
    if result.get("group") == "jacobian":
        return None
    if result["name"] == "physics_only":
        return {"value": MIMO_REFERENCE["physics_only"], "label": "physics alone"}
    if senses.get("vision"):
        return {"value": MIMO_REFERENCE["default"], "label": "default (2 x 256² eyes, touch)"}
    return {"value": MIMO_REFERENCE["without_vision"], "label": "without vision"}
