"""``mimo-social bench``: real seconds per simulated second, split by component.

The configurations (:data:`CONFIGS`; the default set is every one but ``jacobian_*``):

* the MIMo paper's grid (its Sec. VI-B, Fig. 6): one infant with mitten hands and
  spring-damper actuation, two free objects (free play with ``props``), random actions, every
  sense, episodes of one simulated minute, a Rerun recording of the run; vision
  {64, 128, 256, 512}^2 at touch x1 (``v64``, ``v128``, ``default``, ``v512``) and touch density
  {x0.25, x0.5, x1, x2} at vision 256^2 (``t0.25``, ``t0.5``, ``default``, ``t2``);
  ``no_vision`` (touch x1, no eyes: the paper's "without vision");
* ``physics_only``, the floor: the same scene stepped by a bare ``mujoco.mj_step`` loop with the
  same actions written straight into ``data.ctrl`` as torques;
* every task env by its name with its defaults (``free_play``, ``high_five``, ``reach``), recorded;
* the other bodies, as ``default`` otherwise: ``five_fingers`` (``hands="five_fingers"``) and
  ``muscle`` (``actuation="muscle"``);
* scaling: ``agents_1``, ``agents_2``, ``agents_4``, ``agents_8`` infants in one world with every
  sense (vision 64^2, touch x1), as the grid otherwise (``agents_1`` is ``v64``: the two are the
  run's noise check);
* ``jacobian_dense_1`` ... ``jacobian_sparse_4``: the dense against the sparse constraint
  Jacobian (free play without props or recording; only with ``--only``).

Every configuration runs the same smooth random actions (low-pass filtered uniform noise per
motor, seeded, see :func:`mimo_social.core.random_actions.smooth_random_actions`, mapped onto each agent's action-space bounds),
generated in a block *before* the timed loop, so their cost is never counted. Resets between
episodes are not counted either (their time is taken out of the total and their sense readings
out of the components).

The total of a configuration is split with the env's own ``env.timing`` (actuation, physics,
touch, vision, proprioception, vestibular, task, accumulated inside ``env.step``), the time spent
in the recorder (``Recorder.log_step`` and the final ``close``: ``recording``), and ``other``:
everything else, i.e. the bookkeeping inside ``step`` (building the reward/info dicts,
``env.timing["other"]``) plus the Python overhead around it (the loop, the call, the timer calls
themselves). The components therefore sum to the total.

Every env is built first (``build_s``, in this process, after one throw-away build), then the
configurations advance in turns of ``CHUNK`` control steps until each has run its simulated
seconds: a drift of the machine's speed during the run (other processes, a shared virtual host)
then touches every configuration alike, and the chunk times (``rounds``) of two configurations
can be compared pair by pair (that is how :func:`jacobian_verdict` decides between the dense and
the sparse Jacobian). Before that, every configuration with touch is built in two fresh Python
processes whose skin cache (``MIMO_SOCIAL_CACHE``) is a new empty directory, then the same
directory again: ``build_cold_s`` and ``build_warm_s`` (see :func:`fresh_build`). A
configuration that cannot be built (e.g. a body or actuation model not available yet) is listed
under ``skipped`` with the reason instead of stopping the run.

Use :func:`run_benchmarks` from Python (tests), or the command::

    mimo-social bench --json bench.json --update-benchmarks-md
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from ..core.random_actions import random_action_block

__all__ = [
    "CONFIGS", "DEFAULT_CONFIGS", "COMPONENTS", "BenchConfig",
    "run_benchmarks", "fresh_build", "skin_cache_builds", "machine_info", "markdown_report",
    "plot_report", "target_checks", "mimo_comparison", "add_parser", "run",
]

COMPONENTS = ("physics", "actuation", "touch", "vision", "proprioception", "vestibular",
              "recording", "task", "other")
ENV_COMPONENTS = ("actuation", "physics", "proprioception", "vestibular", "touch", "vision",
                  "task")

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
    """One benchmarked configuration: an env factory module and its keyword arguments."""

    name: str
    module: str                      # module in mimo_social.envs, e.g. "free_play_v0"
    kwargs: Mapping[str, Any] = field(default_factory=dict)
    description: str = ""
    raw_physics: bool = False        # True: time a bare mj_step loop on the env's model
    record: bool = False             # True: record the run with mimo_social.recording.recorder.Recorder
    group: str = "other"             # grid, tasks, bodies, scaling, jacobian (plots and tables)
    default: bool = True             # in the default set (no --only)

    def make_env(self):
        import importlib

        mod = importlib.import_module(f"mimo_social.envs.{self.module}")
        return mod.parallel_env(**_deep_copy(self.kwargs))

    @property
    def has_touch(self) -> bool:
        return not self.raw_physics and self.kwargs.get("touch") not in (None, False)

    def key(self) -> str:
        """What makes two configurations the same run (everything but name and description)."""
        return json.dumps([self.module, _deep_copy(self.kwargs), self.raw_physics, self.record],
                          sort_keys=True)


def _deep_copy(x):
    if isinstance(x, Mapping):
        return {k: _deep_copy(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_deep_copy(v) for v in x]
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
    return BenchConfig(name, "free_play_v0", kwargs, description, raw, record and not raw,
                       group)


def _jacobian(name, n, jacobian):
    kwargs = {"n_agents": n, "proprioception": True, "vestibular": True, "expressions": True,
              "physics": {"jacobian": jacobian}}
    return BenchConfig(name, "free_play_v0", kwargs,
                       f"free play, {n} infant(s), no props, proprioception + vestibular, "
                       f"physics jacobian={jacobian!r}", group="jacobian", default=False)


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
    BenchConfig("basic_1", "free_play_v0",
                {"n_agents": 1, "proprioception": True, "vestibular": True, "expressions": True},
                "1 infant, free play, physics + actuation + proprioception + vestibular, not "
                "recorded (the foundation's target)", group="tasks"),
    BenchConfig("free_play", "free_play_v0", {}, "free play task, defaults (2 infants, "
                "proprioception + vestibular), recorded", record=True, group="tasks"),
    BenchConfig("high_five", "high_five_v0", {}, "high five task, defaults (2 infants), recorded",
                record=True, group="tasks"),
    BenchConfig("reach", "reach_v0", {}, "reach task, defaults (1 infant), recorded",
                record=True, group="tasks"),
    BenchConfig("standup", "standup_v0", {}, "stand-up task, defaults (1 infant, 5 ms control "
                "step), recorded", record=True, group="tasks"),
    BenchConfig("selfbody", "selfbody_v0", {}, "self-body touch task, defaults (1 infant, "
                "touch), recorded", record=True, group="tasks"),
    BenchConfig("catch", "catch_v0", {}, "catch task, defaults (1 infant, five fingers, "
                "muscles, touch), recorded", record=True, group="tasks"),
    BenchConfig("mirror", "mirror_v0", {}, "mirror task, defaults (2 infants, 2 x 64x64 eyes "
                "each), recorded", record=True, group="tasks"),
    BenchConfig("joint_attention", "joint_attention_v0", {}, "joint attention task, defaults "
                "(2 sitting infants, 4 toys, eyes), recorded", record=True, group="tasks"),
    BenchConfig("social_touch", "social_touch_v0", {}, "social touch task, defaults (2 sitting "
                "infants, touch), recorded", record=True, group="tasks"),
    BenchConfig("handover", "handover_v0", {}, "handover task, defaults (2 infants, five fingers, "
                "a ball in the giver's hand, touch), recorded", record=True, group="tasks"),
    _scene("five_fingers", "as default with five-fingered hands", group="bodies",
           hands="five_fingers"),
    _scene("muscle", "as default with the muscle model (controls in [0, 1], 2 per motor)",
           group="bodies", actuation="muscle"),
    _scene("agents_1", "1 infant, every sense (vision 64x64, touch x1), 2 objects, recorded "
           "(= v64)", vision=64, group="scaling"),
    _scene("agents_2", "2 infants in one world (as agents_1)", n=2, vision=64, group="scaling"),
    _scene("agents_4", "4 infants in one world (as agents_1)", n=4, vision=64, group="scaling"),
    _scene("agents_8", "8 infants in one world (as agents_1)", n=8, vision=64, group="scaling"),
    _jacobian("jacobian_dense_1", 1, "dense"),
    _jacobian("jacobian_sparse_1", 1, "sparse"),
    _jacobian("jacobian_dense_4", 4, "dense"),
    _jacobian("jacobian_sparse_4", 4, "sparse"),
)}
DEFAULT_CONFIGS = [name for name, c in CONFIGS.items() if c.default]


# -- timing ----------------------------------------------------------------------------------
def _zero_timing(env):
    for key in env.timing:
        env.timing[key] = 0.0


def _error(e: BaseException) -> str:
    text = f"{type(e).__name__}: {e}"
    return text if len(text) <= 400 else text[:397] + "..."


class _EnvRunner:
    """One configuration: its env, its action block, its recorder, and what its timed chunks
    accumulated.

    Configurations advance in turns of ``CHUNK`` steps (see :func:`run_benchmarks`), so a slow
    drift of the machine's speed (other processes, a shared host) touches every configuration
    alike. Resets are taken out of the time and the timing.
    """

    def __init__(self, cfg: BenchConfig, sim_seconds: float, seed: int,
                 record_dir: str | os.PathLike | None = None):
        self.cfg = cfg
        t = time.perf_counter()
        self.env = env = cfg.make_env()
        self.build_s = time.perf_counter() - t
        try:
            self.n_steps = max(1, int(round(sim_seconds / env.dt)))
            self.block = random_action_block(env, self.n_steps, seed)
            self.k = 0
            self.real = self.cpu = self.recording = 0.0
            self.episodes, self.unstable, self.reasons, self.ncon = 1, 0, [], []
            self.rounds, self.rounds_physics = [], []
            self.rec = None
            self.rec_path = None
            self.rec_error = None
            self.rec_setup_s = None
            self.rec_bytes = None
            self._warm_up(seed)
            if cfg.record and record_dir is not None:
                self._start_recorder(Path(record_dir))
        except BaseException:
            env.close()
            raise

    @property
    def done(self) -> bool:
        return self.k >= self.n_steps

    def _warm_up(self, seed):
        env, block = self.env, self.block
        env.reset(seed=seed)
        for k in range(min(WARMUP_STEPS, len(block))):
            if not env.agents:
                env.reset()
            env.step(block[k])
        env.reset(seed=seed)
        _zero_timing(env)

    def _start_recorder(self, record_dir: Path):
        try:
            from ..recording.recorder import Recorder

            path = record_dir / f"{self.cfg.name}.rrd"
            t = time.perf_counter()
            self.rec = Recorder(self.env, path)
            self.rec.log_reset()
            self.rec_setup_s = time.perf_counter() - t
            self.rec_path = path
        except Exception as e:  # noqa: BLE001 - the run goes on unrecorded, the reason noted
            self.rec = None
            self.rec_error = _error(e)

    def _recorder_failed(self, e: BaseException):
        self.rec_error = _error(e)
        rec, self.rec = self.rec, None
        try:
            rec.close()
        except Exception:  # noqa: BLE001
            pass

    def _physics_time(self) -> float:
        return self.env.timing["physics"]

    def run_chunk(self) -> int:
        """Run the next ``CHUNK`` steps (fewer at the end); return how many ran."""
        env, block, timing, step = self.env, self.block, self.env.timing, self.env.step
        rec = self.rec
        clock = time.perf_counter
        k = first = self.k
        end = min(self.n_steps, k + CHUNK)
        phys0 = self._physics_time()
        r0, c0 = clock(), time.process_time()
        while k < end:
            if not env.agents:
                r1, c1 = clock(), time.process_time()
                saved = dict(timing)
                env.reset()
                timing.update(saved)
                if rec is not None:
                    try:
                        rec.log_reset()
                    except Exception as e:  # noqa: BLE001
                        self._recorder_failed(e)
                        rec = None
                self.episodes += 1
                r0 += clock() - r1
                c0 += time.process_time() - c1
            action = block[k]
            out = step(action)
            k += 1
            if rec is not None:
                t = clock()
                try:
                    rec.log_step(action, out[1])
                except Exception as e:  # noqa: BLE001
                    self._recorder_failed(e)
                    rec = None
                self.recording += clock() - t
            if not env.agents:
                for info in out[4].values():
                    if "instability" in info:
                        self.unstable += 1
                        self.reasons.append(info["instability"])
                        break
        if k >= self.n_steps and rec is not None:  # the rest of the buffer and the footer
            t = clock()
            try:
                rec.close()
                self.rec_bytes = self.rec_path.stat().st_size
            except Exception as e:  # noqa: BLE001
                self.rec_error = _error(e)
            self.rec = None
            self.recording += clock() - t
        real = clock() - r0
        self.cpu += time.process_time() - c0
        self._finish_chunk(k, first, real, phys0)
        return k - first

    def _finish_chunk(self, k, first, real, phys0):
        self.k = k
        self.real += real
        sim = (k - first) * self.env.dt
        self.rounds.append(real / sim)
        self.rounds_physics.append((self._physics_time() - phys0) / sim)
        self.ncon.append(self.env.world.data.ncon)

    def components(self) -> tuple[dict, dict]:
        timing = self.env.timing
        inside = {key: float(timing[key]) for key in ENV_COMPONENTS}
        rest = max(0.0, self.real - sum(inside.values()) - self.recording)
        detail = {"in_step": float(timing["other"]),
                  "outside_step": max(0.0, rest - float(timing["other"]))}
        return {**inside, "recording": self.recording, "other": rest}, detail

    def _senses(self) -> dict:
        cfg = self.env.agent_configs[0]
        raw = self.cfg.raw_physics
        return {"vision": None if raw or not cfg.vision else [cfg.vision.width, cfg.vision.height],
                "touch": None if raw or not cfg.touch else float(cfg.touch.density),
                "hands": cfg.hands, "actuation": cfg.actuation}

    def _touch_points(self):
        return sum(int(s.n_points) for s in getattr(self.env, "shared", ())
                   if s.name == "touch") or None

    def _skin_cache(self):
        sources = [sk.from_cache or "built" for s in getattr(self.env, "shared", ())
                   if s.name == "touch" for sk in s.skins if sk is not None]
        return sorted(set(sources)) or None

    def result(self) -> dict:
        env = self.env
        sim = self.n_steps * env.dt
        comps, detail = self.components()
        n = 1 if self.cfg.raw_physics else len(env.possible_agents)
        total = self.real / sim
        entry = {
            "name": self.cfg.name,
            "description": self.cfg.description,
            "group": self.cfg.group,
            "n_agents": n,
            "real_s_per_sim_s": total,
            "per_agent_real_s_per_sim_s": total / n,
            "cpu_s_per_sim_s": self.cpu / sim,
            "build_s": self.build_s,
            "build_cold_s": None,
            "build_warm_s": None,
            "components": {k: comps[k] / sim for k in COMPONENTS},
            "other_detail": {k: v / sim for k, v in detail.items()},
            "senses": self._senses(),
            "skin_cache": self._skin_cache(),
            "touch_points": self._touch_points(),
            "recording": {"on": self.cfg.record and self.rec_error is None and
                          self.rec_setup_s is not None,
                          "error": self.rec_error, "setup_s": self.rec_setup_s,
                          "mb_per_sim_min": (self.rec_bytes / 1e6 / sim * 60.0
                                             if self.rec_bytes else None)},
            "sim_seconds": sim,
            "steps": self.n_steps,
            "episodes": self.episodes,
            "unstable_episodes": self.unstable,
            "instability": self.reasons[:3],
            "jacobian": env.physics.jacobian,
            "nv": int(env.world.model.nv),
            "mean_contacts": float(np.mean(self.ncon)) if self.ncon else 0.0,
            # real s per sim s of each chunk of CHUNK steps, in the order they ran
            "rounds": [round(x, 6) for x in self.rounds],
            "rounds_physics": [round(x, 6) for x in self.rounds_physics],
        }
        ref = mimo_reference(entry)
        entry["mimo_reference"] = ref
        entry["ahead_of_mimo"] = ref["value"] / total if ref else None
        return entry

    def close(self):
        if self.rec is not None:
            try:
                self.rec.close()
            except Exception:  # noqa: BLE001
                pass
            self.rec = None
        self.env.close()
        self.block = None


class _RawPhysicsRunner(_EnvRunner):
    """A bare ``mj_step`` loop on the env's model; torques precomputed from the same actions,
    episodes as long as the env's (the state reset to the initial pose in between)."""

    def __init__(self, cfg, sim_seconds, seed, record_dir=None):
        super().__init__(cfg, sim_seconds, seed, None)
        env = self.env
        m = env.world.model
        name = env.possible_agents[0]
        act = env.actuation[0]
        self.ctrl = np.zeros((self.n_steps, m.nu))
        for k, action in enumerate(self.block):
            u = action[name]["motors"] if isinstance(action[name], Mapping) else action[name]
            self.ctrl[k, act.actuator_ids] = act.torque(np.asarray(u, dtype=np.float64))
        self._physics = 0.0
        self._mj_step = __import__("mujoco").mj_step
        self._reset()
        self._steps(0, min(WARMUP_STEPS, self.n_steps))
        self._reset()

    def _warm_up(self, seed):
        self.env.reset(seed=seed)  # the pose the task randomises; the raw warm-up comes later

    def _reset(self):
        w = self.env.world
        w.reset()
        for a in self.env.actuation:
            a.reset(w.model, w.data)

    def _steps(self, k, end):
        m, d = self.env.world.model, self.env.world.data
        ctrl, skip, step = self.ctrl, self.env.frame_skip, self._mj_step
        while k < end:
            d.ctrl[:] = ctrl[k]
            for _ in range(skip):
                step(m, d)
            k += 1

    def _check(self):
        reason = self.env.world.instability()
        if reason:
            self.unstable += 1
            self.reasons.append(reason)

    def _physics_time(self) -> float:
        return self._physics

    def run_chunk(self) -> int:
        first = k = self.k
        end = min(self.n_steps, k + CHUNK)
        every = self.env.max_steps
        phys0 = self._physics
        real = 0.0
        while k < end:
            if k and k % every == 0:  # episode boundary: not timed
                self._check()
                self._reset()
                self.episodes += 1
            stop = min(end, (k // every + 1) * every)
            r0, c0 = time.perf_counter(), time.process_time()
            self._steps(k, stop)
            real += time.perf_counter() - r0
            self.cpu += time.process_time() - c0
            k = stop
        self._physics += real
        self._finish_chunk(k, first, real, phys0)
        if self.done:
            self._check()
        return k - first

    def components(self):
        comps = dict.fromkeys(COMPONENTS, 0.0)
        comps["physics"] = self.real
        return comps, {"in_step": 0.0, "outside_step": 0.0}


def mimo_reference(entry) -> dict | None:
    """The published MIMo's figure on this machine that a result is compared with: physics
    alone for the floor, the default configuration (2 x 256^2 eyes, touch) for anything with
    eyes, the configuration without vision otherwise. The comparison is of the whole total (all
    infants of a multi-infant world against one original MIMo)."""
    senses = entry.get("senses") or {}
    if entry.get("group") == "jacobian":
        return None
    if entry["name"] == "physics_only":
        return {"value": MIMO_REFERENCE["physics_only"], "label": "physics alone"}
    if senses.get("vision"):
        return {"value": MIMO_REFERENCE["default"], "label": "default (2 x 256² eyes, touch)"}
    return {"value": MIMO_REFERENCE["without_vision"], "label": "without vision"}


# -- machine ---------------------------------------------------------------------------------
def _proc_field(path: str, key: str) -> str | None:
    try:
        with open(path) as f:
            for line in f:
                if line.split(":", 1)[0].strip() == key:
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def _gl_renderer() -> str | None:
    """GL_RENDERER of the process's GL context, if the eyes have made one (none is made here)."""
    try:
        from ..render import eye_renderer

        if eye_renderer._GL is None or eye_renderer._GL_PID != os.getpid():
            return None
        eye_renderer.shared_gl_context()
        from OpenGL.GL import GL_RENDERER, GL_VERSION, glGetString

        return f"{glGetString(GL_RENDERER).decode()}; OpenGL {glGetString(GL_VERSION).decode()}"
    except Exception:  # noqa: BLE001 - informative only
        return None


def machine_info() -> dict:
    """CPU, cores, memory, versions, platform and the GL backend in force."""
    import mujoco

    mem = _proc_field("/proc/meminfo", "MemTotal")
    try:
        usable = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        usable = os.cpu_count()
    mhz = _proc_field("/proc/cpuinfo", "cpu MHz")
    return {
        "cpu": _proc_field("/proc/cpuinfo", "model name") or platform.processor() or "unknown",
        "cpu_mhz": float(mhz) if mhz else None,
        "cores": os.cpu_count(),
        "usable_cores": usable,
        "memory_gb": round(int(mem.split()[0]) / 2**20, 1) if mem else None,
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        "python": platform.python_version(),
        "platform": platform.platform(),
        "mujoco_gl": os.environ.get("MUJOCO_GL") or "unset",
        "gl_renderer": _gl_renderer(),
        "lp_num_threads": os.environ.get("LP_NUM_THREADS"),
    }


def _load() -> list[float] | None:
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


def cold_start(timeout: float = 300.0) -> dict:
    """Import and first 2-infant build in a fresh Python process (nothing cached)."""
    code = ("import time; t0 = time.perf_counter()\n"
            "from mimo_social.envs import free_play_v0\n"
            "t1 = time.perf_counter()\n"
            "env = free_play_v0.parallel_env(n_agents=2)\n"
            "t2 = time.perf_counter()\n"
            "print(t1 - t0, t2 - t1)\n")
    try:
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             timeout=timeout, check=True)
        imp, build = (float(x) for x in out.stdout.split()[-2:])
        return {"import_s": imp, "build_2_agents_s": build}
    except (subprocess.SubprocessError, ValueError, OSError) as e:
        return {"error": f"{type(e).__name__}: {e}"}


_FRESH_BUILD = """\
import importlib, json, sys, time
t0 = time.perf_counter()
from mimo_social.bench.suite import CONFIGS
cfg = CONFIGS[sys.argv[1]]
importlib.import_module("mimo_social.envs." + cfg.module)
t1 = time.perf_counter()
env = cfg.make_env()
t2 = time.perf_counter()
env.reset(seed=0)
t3 = time.perf_counter()
skin = sorted({sk.from_cache or "built" for s in [env.systems.get("touch")] if s is not None
               for sk in s.skins if sk is not None})
print("JSON" + json.dumps({"import_s": t1 - t0, "build_s": t2 - t1, "first_reset_s": t3 - t2,
                          "skin": skin}))
env.close()
"""


def fresh_build(name: str, cache_dir: str | os.PathLike, timeout: float = 600.0) -> dict:
    """Build configuration ``name`` in a fresh Python process whose skin cache
    (``MIMO_SOCIAL_CACHE``) is ``cache_dir``: ``{"import_s", "build_s", "first_reset_s",
    "skin"}`` (the skin's source per agent: "built", "disk", "memory"), or ``{"error"}``."""
    env = dict(os.environ, MIMO_SOCIAL_CACHE=str(cache_dir))
    try:
        out = subprocess.run([sys.executable, "-c", _FRESH_BUILD, name], capture_output=True,
                             text=True, timeout=timeout, env=env)
        lines = [ln for ln in out.stdout.splitlines() if ln.startswith("JSON")]
        if out.returncode or not lines:
            tail = (out.stderr or out.stdout).strip().splitlines()[-1:] or ["no output"]
            return {"error": f"exit {out.returncode}: {tail[0][:300]}"}
        return json.loads(lines[-1][4:])
    except (subprocess.SubprocessError, ValueError, OSError) as e:
        return {"error": _error(e)}


def skin_cache_builds(names: Sequence[str], progress=None) -> dict:
    """For each configuration with touch: :func:`fresh_build` with a new empty skin cache
    (``cold``) and again with the cache that filled (``warm``)."""
    out = {}
    for name in names:
        if not CONFIGS[name].has_touch:
            continue
        if progress is not None:
            progress(name)
        with tempfile.TemporaryDirectory(prefix="mimo_bench_cache_") as d:
            cold = fresh_build(name, d)
            warm = fresh_build(name, d) if "error" not in cold else {"error": "cold build failed"}
        out[name] = {"cold": cold, "warm": warm}
    return out


# -- the run ---------------------------------------------------------------------------------
def _check_names(names) -> list[str]:
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


def run_benchmarks(names: Sequence[str] | str | None = None,
                   sim_seconds: float = DEFAULT_SIM_SECONDS, seed: int = 0,
                   progress: bool = True, measure_cold_start: bool = True,
                   record: bool = True) -> dict:
    """Benchmark the named configurations (the default set when ``None``) for ``sim_seconds``
    each.

    Returns ``{"machine", "settings", "cold_start", "results", "skipped"}``; each result is
    ``{"name", "n_agents", "real_s_per_sim_s", "cpu_s_per_sim_s", "build_s", "components",
    ...}`` with the components in real s per simulated s (they sum to the total); ``skipped``
    lists ``{"name", "reason"}`` for configurations that could not be built or run.
    ``measure_cold_start``: also build in fresh processes (the 2-infant cold start, and every
    touch configuration with a cold and a warm skin cache). ``record``: record the
    configurations that are recorded (a Rerun file in a temporary directory, deleted after).
    """
    from tqdm import tqdm

    names = _check_names(names)
    if not sim_seconds > 0:
        raise ValueError(f"sim_seconds={sim_seconds}; must be positive")
    load_before = _load()
    skipped: list[dict] = []
    t_start = time.perf_counter()

    fresh = {}
    cold = None
    bar_format = "{l_bar}{bar}| {n:.1f}/{total:.1f} sim s [{elapsed}<{remaining}]"
    with tqdm(total=len(names) * sim_seconds, desc="bench", unit="sim s", disable=not progress,
              file=sys.stderr, dynamic_ncols=True, bar_format=bar_format) as bar:
        if measure_cold_start:
            bar.set_description("fresh-process build (2 infants)")
            cold = cold_start()
            fresh = skin_cache_builds(
                names, lambda n: bar.set_description(f"fresh-process builds {n} (cold, warm)"))
        # One throw-away build first, so lazy one-time work (imports, tables, face textures, the
        # skin) is not charged to whichever configuration happens to be built first.
        bar.set_description("first build")
        t = time.perf_counter()
        try:
            CONFIGS["agents_1"].make_env().close()
        except Exception as e:  # noqa: BLE001 - the configurations will say what fails
            print(f"mimo-social bench: the throw-away build failed: {_error(e)}", file=sys.stderr)
        first_build = time.perf_counter() - t

        runners = []
        loads = []
        with tempfile.TemporaryDirectory(prefix="mimo_bench_rec_") as rec_dir:
            for name in names:  # build every env first (timed), then run them in turns
                bar.set_description(f"build {name}")
                cfg = CONFIGS[name]
                cls = _RawPhysicsRunner if cfg.raw_physics else _EnvRunner
                try:
                    runners.append(cls(cfg, sim_seconds, seed, rec_dir if record else None))
                except Exception as e:  # noqa: BLE001 - noted, the other configurations run
                    skipped.append({"name": name, "stage": "build", "reason": _error(e)})
                    bar.update(sim_seconds)
                    print(f"mimo-social bench: skipping {name}: {_error(e)}", file=sys.stderr)
            while not all(r.done for r in runners):
                for r in list(runners):
                    if r.done:
                        continue
                    bar.set_description(r.cfg.name)
                    try:
                        n = r.run_chunk()
                    except Exception as e:  # noqa: BLE001
                        skipped.append({"name": r.cfg.name, "stage": f"run (step {r.k})",
                                        "reason": _error(e)})
                        bar.update(sim_seconds * (1 - r.k / r.n_steps))
                        runners.remove(r)
                        r.close()
                        continue
                    bar.update(n * sim_seconds / r.n_steps)
                loads.append(_load())
            results = [r.result() for r in runners]
            for r in runners:
                r.close()
        del runners
    for entry in results:
        f = fresh.get(entry["name"])
        if f:
            entry["fresh_process"] = f
            entry["build_cold_s"] = f["cold"].get("build_s")
            entry["build_warm_s"] = f["warm"].get("build_s")
    order = {n: i for i, n in enumerate(names)}
    results.sort(key=lambda e: order[e["name"]])
    one_min = [x[0] for x in loads if x]
    report = {
        "machine": machine_info(),
        "settings": {
            "sim_seconds": sim_seconds, "seed": seed, "warmup_steps": WARMUP_STEPS,
            "chunk_steps": CHUNK, "episode_steps_grid": EPISODE_STEPS, "recording": record,
            "first_build_s": first_build, "load_average_before": load_before,
            "load_average_after": _load(),
            "load_1min_during": ({"mean": round(float(np.mean(one_min)), 2),
                                  "max": round(float(np.max(one_min)), 2)} if one_min else None),
            "wall_s": time.perf_counter() - t_start,
            "date_utc": time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime()),
        },
        "cold_start": cold,
        "results": results,
        "skipped": skipped,
    }
    return report


# -- reading a report ------------------------------------------------------------------------
def _by_name(report) -> dict:
    return {r["name"]: r for r in report["results"]}


def jacobian_verdict(report, tie: float = 0.03) -> list[dict]:
    """Dense against sparse per agent count (only those measured): which is faster, stable?

    The physics time of the two runs is compared chunk by chunk (they ran in turns, next to
    each other in time): ``dense_faster_by`` is the median over chunks of
    ``1 - dense / sparse``; within ``tie`` of 0 there is no clear winner.
    """
    res = _by_name(report)
    out = []
    for n in (1, 2, 4, 8):
        dense, sparse = res.get(f"jacobian_dense_{n}"), res.get(f"jacobian_sparse_{n}")
        if not dense or not sparse:
            continue
        d_phy, s_phy = dense["components"]["physics"], sparse["components"]["physics"]
        pairs = [(d, s) for d, s in zip(dense.get("rounds_physics", []),
                                        sparse.get("rounds_physics", [])) if d > 0 and s > 0]
        if pairs:
            rel = float(np.median([1.0 - d / s for d, s in pairs]))
            dense_wins = sum(d < s for d, s in pairs) / len(pairs)
        else:
            rel, dense_wins = 1.0 - d_phy / s_phy, float(d_phy < s_phy)
        winner = "tie" if abs(rel) < tie else ("dense" if rel > 0 else "sparse")
        out.append({"n_agents": n, "dense_total": dense["real_s_per_sim_s"],
                    "sparse_total": sparse["real_s_per_sim_s"],
                    "dense_physics": d_phy, "sparse_physics": s_phy,
                    "dense_faster_by": rel, "dense_faster_in": dense_wins,
                    "chunks": len(pairs), "winner": winner,
                    "dense_unstable": dense["unstable_episodes"],
                    "sparse_unstable": sparse["unstable_episodes"],
                    "dense_episodes": dense["episodes"], "sparse_episodes": sparse["episodes"]})
    return out


def _scaling(report) -> list[dict]:
    """Per agent count of ``agents_N``: total, per infant, and per infant relative to one."""
    res = _by_name(report)
    rows = [res[f"agents_{n}"] for n in (1, 2, 4, 8) if f"agents_{n}" in res]
    one = res.get("agents_1")
    out = []
    for r in rows:
        n = r["n_agents"]
        per = r["real_s_per_sim_s"] / n
        blind = (r["real_s_per_sim_s"] - r["components"]["vision"]) / n
        one_blind = (one["real_s_per_sim_s"] - one["components"]["vision"]) if one else None
        out.append({"name": r["name"], "n_agents": n, "total": r["real_s_per_sim_s"],
                    "per_agent": per,
                    "relative": per / one["real_s_per_sim_s"] if one else None,
                    "relative_without_vision": blind / one_blind if one_blind else None,
                    "per_agent_components": {k: r["components"].get(k, 0.0) / n
                                             for k in COMPONENTS}})
    return out


def mimo_comparison(report) -> list[dict]:
    """Per result: the published MIMo figure it is compared with and whether it is ahead."""
    out = []
    for r in report["results"]:
        ref = r.get("mimo_reference", mimo_reference(r))
        if not ref:
            continue
        total = r["real_s_per_sim_s"]
        out.append({"name": r["name"], "total": total, "reference": ref["value"],
                    "label": ref["label"], "factor": ref["value"] / total,
                    "ahead": total < ref["value"]})
    return out


def target_checks(report) -> list[dict]:
    """The package's speed targets, each with the measured value and whether it is met."""
    res = _by_name(report)
    out = []
    if "default" in res:
        r = res["default"]
        total = r["real_s_per_sim_s"]
        env_only = total - r["components"]["recording"]
        out.append({"target": "default configuration (2 x 256² eyes, touch x1, recorded) "
                              f"< {TARGETS['default_max']} real s / sim s",
                    "measured": f"{total:.3f} ({1 / total:.1f}x real time); "
                                f"{env_only:.3f} without the recording",
                    "met": total < TARGETS["default_max"],
                    "met_without_recording": env_only < TARGETS["default_max"]})
    comp = mimo_comparison(report)
    if comp:
        behind = [c for c in comp if not c["ahead"]]
        worst = min(comp, key=lambda c: c["factor"])
        out.append({"target": "every configuration ahead of the original MIMo on this machine",
                    "measured": (f"{len(comp) - len(behind)} of {len(comp)} ahead; least: "
                                 f"`{worst['name']}` {worst['factor']:.1f}x faster than MIMo "
                                 f"{worst['label']} ({worst['reference']:g})"
                                 + (("; behind: " + ", ".join(f"`{c['name']}`" for c in behind))
                                    if behind else "")),
                    "met": not behind})
    colds = [(r["name"], r["build_cold_s"] + (r["fresh_process"]["cold"].get("first_reset_s")
                                              or 0.0))
             for r in report["results"] if r.get("build_cold_s") is not None]
    if colds:
        name, worst = max(colds, key=lambda x: x[1])
        out.append({"target": "building with touch (fresh process, empty skin cache, build + "
                              f"first reset) faster than the original MIMo's "
                              f"~{MIMO_REFERENCE['build_with_touch_s']:.0f} s",
                    "measured": f"at most {worst:.2f} s (`{name}`)",
                    "met": worst < MIMO_REFERENCE["build_with_touch_s"]})
    if "basic_1" in res:  # the whole step of an infant with exactly these senses
        total = res["basic_1"]["real_s_per_sim_s"]
        out.append({"target": "one infant (physics + proprioception + vestibular) "
                              f"<= {TARGETS['agents_1_max']} real s / sim s",
                    "measured": f"{total:.4f} (the whole step of `basic_1`)",
                    "met": total <= TARGETS["agents_1_max"]})
    elif "agents_1" in res:
        r = res["agents_1"]
        c = r["components"]
        pps = c["physics"] + c["proprioception"] + c["vestibular"]
        out.append({"target": "one infant (physics + proprioception + vestibular) "
                              f"<= {TARGETS['agents_1_max']} real s / sim s",
                    "measured": f"{pps:.4f} (those three components of `agents_1`, which also "
                                "renders and feels: add `basic_1` for the exact figure)",
                    "met": pps <= TARGETS["agents_1_max"]})
    builds = []
    cold = report.get("cold_start") or {}
    if "build_2_agents_s" in cold:
        builds.append(("fresh process", cold["build_2_agents_s"]))
    if "agents_2" in res:
        builds.append(("`agents_2` in the benchmark process", res["agents_2"]["build_s"]))
    if builds:
        worst = max(b for _, b in builds)
        out.append({"target": f"building a 2-infant env < {TARGETS['build_2_agents_max_s']} s",
                    "measured": "; ".join(f"{b:.3f} s {where}" for where, b in builds),
                    "met": worst < TARGETS["build_2_agents_max_s"]})
    scaling = [s for s in _scaling(report) if s["n_agents"] > 1 and s["relative"] is not None]
    if scaling:
        lim = TARGETS["scaling_per_infant_max"]
        out.append({"target": f"scaling close to linear: N infants <= {lim} x N x one infant",
                    "measured": "; ".join(f"{s['n_agents']} infants {s['relative']:.2f}x one "
                                          "per infant" for s in scaling)
                                + " (all but vision: " + "; ".join(
                                    f"{s['relative_without_vision']:.2f}x" for s in scaling)
                                + ")",
                    "met": all(s["relative"] <= lim for s in scaling)})
    return out


def noise_pairs(report) -> list[tuple[str, str]]:
    """Pairs of measured configurations that are the same run (same env, same actions)."""
    keys: dict[str, list[str]] = {}
    for r in report["results"]:
        cfg = CONFIGS.get(r["name"])
        if cfg is not None:
            keys.setdefault(cfg.key(), []).append(r["name"])
    return [(names[0], other) for names in keys.values() if len(names) > 1
            for other in names[1:]]


def noise_note(report) -> str:
    """A sentence on the run's noise, from configurations that are the same run."""
    res = _by_name(report)
    parts = []
    for a, b in noise_pairs(report):
        x, y = res[a]["real_s_per_sim_s"], res[b]["real_s_per_sim_s"]
        parts.append(f"`{a}` and `{b}` (totals {x:.4f} and {y:.4f}: "
                     f"{abs(x - y) / min(x, y) * 100:.0f} % apart)")
    if not parts:
        return ""
    return ("Noise check: " + "; ".join(parts) + " are the same configuration (same env, same "
            "actions, same trajectory), measured side by side; their difference is the "
            "measurement noise of this run, and differences of that size between other rows "
            "mean nothing.")


def load_note(report) -> str:
    """Whether other work shared the machine during the run (load averages)."""
    st, mach = report["settings"], report["machine"]
    before, during = st.get("load_average_before"), st.get("load_1min_during")
    cores = mach.get("usable_cores") or mach.get("cores") or 1
    if not before:
        return ""
    text = (f"Load average (1, 5, 15 min) before the run: {before}; 1-min load during the "
            + (f"run: mean {during['mean']}, max {during['max']}" if during else "run: unknown")
            + f" (the benchmark itself adds about 1, more while Mesa renders; {cores} cores).")
    busy_before = before[0] >= 0.5 * cores or (len(before) > 1 and before[1] >= 0.5 * cores)
    busy_during = during is not None and during["mean"] >= cores + 0.5
    if busy_before or busy_during:
        text = ("**The machine was shared with other jobs during this run** (the load was high), "
                "so every figure is somewhat pessimistic; the configurations ran in "
                f"interleaved turns of {CHUNK} steps, so they were slowed alike. " + text)
    return text


# -- Markdown --------------------------------------------------------------------------------
def _f(x: float) -> str:
    return f"{x:.4f}"


def _ahead(r) -> str:
    ref = r.get("mimo_reference")
    if not ref:
        return "-"
    k = ref["value"] / r["real_s_per_sim_s"]
    word = "ahead" if k > 1 else "**behind**"
    return f"{ref['value']:g} ({ref['label']}): {word}, {k:.1f}x"


def markdown_table(report) -> str:
    head = ("| configuration | agents | real s / sim s | × real time | "
            + " | ".join(COMPONENTS)
            + " | CPU s / sim s | build s | episodes (unstable) | original MIMo here |")
    lines = [head, "|" + "---|" * (len(COMPONENTS) + 8)]
    for r in report["results"]:
        c = r["components"]
        lines.append(
            f"| `{r['name']}` | {r['n_agents']} | **{_f(r['real_s_per_sim_s'])}** "
            f"| {1.0 / r['real_s_per_sim_s']:.1f} "
            + "".join(f"| {_f(c.get(k, 0.0))} " for k in COMPONENTS)
            + f"| {_f(r['cpu_s_per_sim_s'])} | {r['build_s']:.3f} "
            f"| {r['episodes']} ({r['unstable_episodes']}) | {_ahead(r)} |")
    return "\n".join(lines)


def _descriptions(report) -> str:
    return "\n".join(f"- `{r['name']}`: {r.get('description', '')}" for r in report["results"])


def scaling_table(report) -> str:
    rows = _scaling(report)
    if not rows:
        return ""
    parts = ("physics", "touch", "vision", "recording")
    lines = ["| infants | real s / sim s | per infant | per infant, relative to 1 infant | "
             "all but vision, per infant, relative to 1 infant | "
             + " | ".join(f"{p} per infant" for p in parts) + " | build s |",
             "|" + "---|" * (6 + len(parts))]
    res = _by_name(report)
    for s in rows:
        rel = f"{s['relative']:.2f}" if s["relative"] is not None else "-"
        blind = (f"{s['relative_without_vision']:.2f}"
                 if s["relative_without_vision"] is not None else "-")
        lines.append(f"| {s['n_agents']} | {_f(s['total'])} | {_f(s['per_agent'])} | {rel} | "
                     f"{blind} | "
                     + " | ".join(_f(s["per_agent_components"][p]) for p in parts)
                     + f" | {res[s['name']]['build_s']:.3f} |")
    return "\n".join(lines)


def build_table(report) -> str:
    rows = [r for r in report["results"] if r.get("fresh_process")]
    if not rows:
        return ""
    lines = ["| configuration | in this process (skin cached) | fresh process, empty skin "
             "cache: import / build / first reset | fresh process, warm skin cache: import / "
             "build / first reset |", "|---|---|---|---|"]

    def cell(f):
        if "error" in f:
            return f"failed: {f['error']}"
        return (f"{f['import_s']:.2f} / **{f['build_s']:.2f}** / {f['first_reset_s']:.2f} s "
                f"(skin: {', '.join(f.get('skin') or []) or '-'})")

    for r in rows:
        f = r["fresh_process"]
        lines.append(f"| `{r['name']}` | {r['build_s']:.3f} s | {cell(f['cold'])} | "
                     f"{cell(f['warm'])} |")
    return "\n".join(lines)


def where_time_goes(report) -> str:
    """Data-driven remarks: what dominates, what grows, where the recording and tasks cost."""
    res = _by_name(report)
    parts = []
    for name in ("default", "agents_1"):
        if name in res:
            r = res[name]
            tot = r["real_s_per_sim_s"]
            shares = sorted(r["components"].items(), key=lambda kv: -kv[1])
            parts.append(f"in `{name}` ({tot:.3f} real s / sim s) the time goes to "
                         + ", ".join(f"{k} {v / tot * 100:.0f} % ({v:.3f})"
                                     for k, v in shares if v / tot >= 0.01))
            break
    recs = [(r["name"], r["components"]["recording"], r["real_s_per_sim_s"])
            for r in report["results"] if r["components"].get("recording", 0) > 0]
    if recs:
        hi = max(recs, key=lambda x: x[1] / x[2])
        lo = min(recs, key=lambda x: x[1] / x[2])
        text = (f"recording (the Rerun recorder with its defaults) costs from "
                f"{lo[1] / lo[2] * 100:.0f} % (`{lo[0]}`) to {hi[1] / hi[2] * 100:.0f} % "
                f"(`{hi[0]}`, {hi[1]:.3f} real s / sim s) of a run")
        sizes = [(r["name"], r["recording"]["mb_per_sim_min"]) for r in report["results"]
                 if (r.get("recording") or {}).get("mb_per_sim_min")]
        if sizes:
            big = max(sizes, key=lambda x: x[1])
            small = min(sizes, key=lambda x: x[1])
            text += (f"; its files take {small[1]:.0f} (`{small[0]}`) to {big[1]:.0f} MB "
                     f"(`{big[0]}`) per simulated minute")
        parts.append(text)
    sweep = [res[n] for n in ("v64", "v128", "default", "v512") if n in res]
    if len(sweep) > 1:
        a, b = sweep[0], sweep[-1]
        px = (b["senses"]["vision"][0] * b["senses"]["vision"][1]
              / (a["senses"]["vision"][0] * a["senses"]["vision"][1]))
        parts.append("vision costs " + " / ".join(f"{r['components']['vision']:.3f}"
                                                  for r in sweep)
                     + " at " + " / ".join(f"{r['senses']['vision'][0]}²" for r in sweep)
                     + f": {px:.0f}x the pixels cost "
                     f"{b['components']['vision'] / a['components']['vision']:.1f}x the time "
                     "(a fixed cost per frame dominates the small images)")
    sweep = [res[n] for n in ("t0.25", "t0.5", "default", "t2") if n in res]
    if len(sweep) > 1 and all(r.get("touch_points") for r in sweep):
        a, b = sweep[0], sweep[-1]
        parts.append("touch costs " + " / ".join(f"{r['components']['touch']:.3f}"
                                                 for r in sweep)
                     + " at x" + " / x".join(f"{r['senses']['touch']:g}" for r in sweep)
                     + " (" + " / ".join(str(r["touch_points"]) for r in sweep)
                     + f" skin points): {b['touch_points'] / a['touch_points']:.1f}x the points "
                     f"cost {b['components']['touch'] / a['components']['touch']:.2f}x the "
                     "time (the work is per contact, not per skin point)")
    if "default" in res and "five_fingers" in res:
        d, f = res["default"]["components"], res["five_fingers"]["components"]
        ratio = res["five_fingers"]["real_s_per_sim_s"] / res["default"]["real_s_per_sim_s"]
        parts.append(f"five-fingered hands cost {ratio:.1f}x "
                     f"the mitten default (physics {f['physics'] / d['physics']:.1f}x, vision "
                     f"{f['vision'] / max(d['vision'], 1e-12):.1f}x, touch "
                     f"{f['touch'] / max(d['touch'], 1e-12):.1f}x)")
    if "default" in res and "muscle" in res:
        d, m = res["default"]["components"], res["muscle"]["components"]
        ratio = res["muscle"]["real_s_per_sim_s"] / res["default"]["real_s_per_sim_s"]
        parts.append(f"muscles cost {ratio:.2f}x "
                     f"the spring-damper default: {m['physics'] / d['physics']:.2f}x its "
                     "physics (the muscle dynamics run before every physics sub-step, so "
                     "their time counts as `physics`) and "
                     f"{m['actuation'] / max(d['actuation'], 1e-12):.2f}x its actuation")
    sc = _scaling(report)
    if len(sc) > 1 and sc[0]["n_agents"] == 1:
        a, b = sc[0], sc[-1]
        grow = {k: b["per_agent_components"][k] / a["per_agent_components"][k]
                for k in COMPONENTS if a["per_agent_components"][k] > 1e-5}
        worst = max(grow, key=lambda k: b["per_agent_components"][k]
                    - a["per_agent_components"][k])
        parts.append(f"from 1 to {b['n_agents']} infants the cost per infant grows "
                     f"{b['per_agent'] / a['per_agent']:.2f}x; most of the growth is {worst} "
                     f"({grow[worst]:.2f}x per infant: "
                     + ("each eye sees the other infants, so the rendering work per infant "
                        "grows with their number" if worst == "vision" else
                        "more bodies in one world") + ")"
                     + "; per component: " + ", ".join(f"{k} {v:.2f}x" for k, v in grow.items()))
    slow = [r for r in report["results"]
            if r["components"]["task"] > r["components"]["physics"] > 0]
    for r in slow:
        parts.append(f"in `{r['name']}` the task's own per-step work (`task`) takes "
                     f"{r['components']['task']:.4f} real s / sim s, "
                     f"{r['components']['task'] / r['components']['physics']:.1f}x the physics")
    if not parts:
        return ""
    return "\n".join(f"- {p[0].upper() + p[1:]}." for p in parts)


def _mimo_paragraph(report) -> str:
    comp = mimo_comparison(report)
    if not comp:
        return ""
    ref = MIMO_REFERENCE
    lines = [f"The original MIMo, measured on this machine: default configuration (one infant, "
             f"2 x 256² eyes, touch x1, two objects) ~{ref['default']:g} real s per simulated s, "
             f"without vision {ref['without_vision']:g}, physics alone {ref['physics_only']:g}; "
             f"~{ref['build_with_touch_s']:.0f} s to build with touch "
             f"(~{ref['build_without_touch_s']:.0f} s without). Each configuration is compared "
             "with the closest of these figures (anything with eyes with the default, whatever "
             "its image size; multi-infant worlds as a whole with one original infant):", ""]
    for c in comp:
        lines.append(f"- `{c['name']}`: {c['total']:.4f} against {c['reference']:g} "
                     f"({c['label']}): " + (f"ahead, {c['factor']:.1f}x faster" if c["ahead"]
                                            else f"**behind**, {1 / c['factor']:.1f}x slower"))
    colds = [(r["name"], r["build_cold_s"]) for r in report["results"]
             if r.get("build_cold_s") is not None]
    if colds:
        lo, hi = min(colds, key=lambda x: x[1]), max(colds, key=lambda x: x[1])
        lines.append(f"- building with touch in a fresh process with an empty skin cache takes "
                     f"{lo[1]:.2f} s (`{lo[0]}`) to {hi[1]:.2f} s (`{hi[0]}`), against "
                     f"~{ref['build_with_touch_s']:.0f} s for the original MIMo")
    return "\n".join(lines)


def _plot_links(plot) -> list[str]:
    if not plot:
        return []
    return [plot] if isinstance(plot, (str, os.PathLike)) else list(plot)


def markdown_report(report, command: str | None = None, plot=None) -> str:
    """The whole BENCHMARKS.md text: machine, command, tables, plots, targets, MIMo, Jacobian.
    ``plot``: the path (or list of paths) of the charts, relative to the Markdown file."""
    mach = report["machine"]
    st = report["settings"]
    out = ["# Benchmarks", "",
           "Real (wall-clock) seconds per simulated second, split by component, for each "
           "configuration; smaller is faster, and `× real time` is its inverse. The grid is the "
           "MIMo paper's (its Sec. VI-B, Fig. 6): one infant with mitten hands and spring-damper "
           "actuation, two free objects, random actions, every sense, vision at "
           "{64, 128, 256, 512}² with touch x1 and touch at x{0.25, 0.5, 1, 2} the published "
           "point density with vision at 256², episodes of one simulated minute; every run is "
           "recorded to a Rerun file (`mimo_social.recording.recorder.Recorder` with its defaults). "
           "Every configuration runs the same smooth random actions (low-pass filtered "
           "uniform noise per motor, seeded, mapped onto each action space's bounds), generated "
           "before the timed loop. The components come from `env.timing` (inside `env.step`) "
           "and the recorder's calls; `other` is the Python overhead around them (dict building "
           "in `step`, the call, the loop), so they sum to the total. `physics_only` is the "
           "floor: the grid's scene stepped by a bare `mujoco.mj_step` loop. All envs are built "
           "first (`build s`, in this process, skin from the cache), then the configurations "
           f"run in turns of {CHUNK} control steps, so a change in the machine's speed during "
           "the run touches them alike; resets between episodes are not counted. The count in "
           "brackets is of episodes that ended unstable. `CPU s / sim s` is the process's CPU "
           "time, Mesa's rasterizer threads included (so it can exceed the real time with "
           "vision); clearly below the real time, it means the benchmark waited for a CPU.", "",
           "## Machine", "",
           f"- CPU: {mach['cpu']} ({mach['cores']} cores"
           + (f", {mach['usable_cores']} usable"
              if mach.get("usable_cores") != mach["cores"] else "")
           + (f", {mach['cpu_mhz']:.0f} MHz" if mach.get("cpu_mhz") else "")
           + (f"), {mach['memory_gb']} GB RAM" if mach.get("memory_gb") else ")"),
           f"- MuJoCo {mach['mujoco']}, NumPy {mach['numpy']}, Python {mach['python']}, "
           f"{mach['platform']}",
           f"- OpenGL: MUJOCO_GL={mach['mujoco_gl']}"
           + (f", {mach['gl_renderer']}" if mach.get("gl_renderer") else "")
           + (f", LP_NUM_THREADS={mach['lp_num_threads']}" if mach.get("lp_num_threads") else
              " (no GPU: Mesa software rendering)"),
           f"- measured {st['date_utc']} UTC, {st['sim_seconds']:g} simulated s per "
           f"configuration, seed {st['seed']}"
           + (f", {st['wall_s'] / 60:.1f} min in all" if st.get("wall_s") else ""), ""]
    load = load_note(report)
    if load:
        out += [load, ""]
    if command:
        out += ["Produced by:", "", "```", command, "```", ""]
    out += ["## Results", "", markdown_table(report), ""]
    noise = noise_note(report)
    if noise:
        out += [noise, ""]
    skipped = report.get("skipped") or []
    if skipped:
        out += ["Skipped (could not be built or run):", ""]
        out += [f"- `{s['name']}` ({s.get('stage', 'build')}): {s['reason']}" for s in skipped]
        out.append("")
    recfail = [r for r in report["results"] if (r.get("recording") or {}).get("error")]
    if recfail:
        out += ["Recorder failures (those runs went on unrecorded from that point):", ""]
        out += [f"- `{r['name']}`: {r['recording']['error']}" for r in recfail]
        out.append("")
    out += ["Configurations:", "", _descriptions(report), ""]
    links = _plot_links(plot)
    captions = ["The paper's grid (like its Fig. 6): real s per simulated s, stacked by component",
                "Tasks, bodies and infants in one world (like the paper's Fig. 7), stacked by "
                "component"]
    for i, p in enumerate(links):
        cap = captions[i] if len(links) > 1 and i < len(captions) else \
            "Real seconds per simulated second, stacked by component"
        out += [f"![{cap}]({p})", ""]
    sc = scaling_table(report)
    if sc:
        out += ["## Infants in one world", "", "Every sense (vision 64², touch x1), two objects, "
                "recorded; the total for the whole world and per infant.", "", sc, ""]
    bt = build_table(report)
    if bt:
        out += ["## Build time", "",
                "Every configuration with touch, built in a fresh Python process (after its "
                "imports), first with `MIMO_SOCIAL_CACHE` pointing at a new empty directory "
                "(the skin is computed), then again with the cache that run filled (the skin is "
                "read from disk); the first reset makes the GL context of the eyes.", "", bt, ""]
    checks = target_checks(report)
    if checks:
        out += ["## Targets", "", "| target | measured | met |", "|---|---|---|"]
        for c in checks:
            out.append(f"| {c['target']} | {c['measured']} | {'yes' if c['met'] else '**no**'} |")
        out.append("")
    where = where_time_goes(report)
    if where:
        out += ["## Where the time goes", "", where, ""]
    para = _mimo_paragraph(report)
    if para:
        out += ["## Compared with the original MIMo", "", para, ""]
    verdicts = jacobian_verdict(report)
    if verdicts:
        out += ["## Jacobian: dense or sparse", ""]
        for v in verdicts:
            stab = (f"dense {v['dense_unstable']}/{v['dense_episodes']} and sparse "
                    f"{v['sparse_unstable']}/{v['sparse_episodes']} episodes unstable")
            if v["winner"] == "tie":
                verdict = "no clear winner (the median chunk differs by less than 3 %)"
            else:
                wins = v["dense_faster_in"] if v["winner"] == "dense" else 1 - v["dense_faster_in"]
                verdict = (f"**{v['winner']} is faster**: its physics takes "
                           f"{abs(v['dense_faster_by']) * 100:.0f} % less time in the median "
                           f"chunk, and less in {wins * 100:.0f} % of the {v['chunks']} chunks")
            out.append(f"- {v['n_agents']} infant{'s' if v['n_agents'] > 1 else ''}: physics "
                       f"{_f(v['dense_physics'])} (dense) vs {_f(v['sparse_physics'])} (sparse) "
                       f"real s / sim s, totals {_f(v['dense_total'])} vs {_f(v['sparse_total'])}: "
                       f"{verdict}; {stab}.")
        out.append("")
    return "\n".join(out)


# -- plots -----------------------------------------------------------------------------------
COLOURS = {"physics": "#4C72B0", "actuation": "#DD8452", "touch": "#DA8BC3",
           "vision": "#64B5CD", "proprioception": "#55A868", "vestibular": "#C44E52",
           "recording": "#8C8C8C", "task": "#8172B3", "other": "#937860"}

#: (figure, panel title, [(configuration, bar label)]): the paper's Fig. 6 and Fig. 7.
PANELS = (
    ("grid", "vision (touch x1)", (("v64", "64²"), ("v128", "128²"), ("default", "256²"),
                                   ("v512", "512²"))),
    ("grid", "touch density (vision 256²)", (("t0.25", "x0.25"), ("t0.5", "x0.5"),
                                             ("default", "x1"), ("t2", "x2"))),
    ("grid", "without", (("no_vision", "no vision"), ("physics_only", "physics\nonly"))),
    ("tasks", "tasks (defaults)", (("free_play", "free_play"), ("high_five", "high_five"),
                                   ("reach", "reach"))),
    ("tasks", "bodies (vision 256², touch x1)", (("default", "mitten,\nspring-d."),
                                                  ("five_fingers", "five\nfingers"),
                                                  ("muscle", "muscle"))),
    ("tasks", "infants in one world (vision 64², touch x1)",
     (("agents_1", "1"), ("agents_2", "2"), ("agents_4", "4"), ("agents_8", "8"))),
)


def _panels(report) -> dict[str, list]:
    """Panels of each figure with the measured bars; unplaced results go to an extra panel."""
    res = _by_name(report)
    figs: dict[str, list] = {"grid": [], "tasks": []}
    placed = set()
    for fig, title, bars in PANELS:
        present = [(res[n], label) for n, label in bars if n in res]
        # a panel whose only bar is shown elsewhere (default) says nothing new
        if present and not all(r["name"] == "default" for r, _ in present):
            figs[fig].append((title, present))
            placed.update(r["name"] for r, _ in present)
    rest = [(r, r["name"]) for r in report["results"] if r["name"] not in placed]
    if rest:
        figs["tasks"].append(("other", rest))
    return figs


def _draw_panel(ax, title, bars, scaling=False):
    x = np.arange(len(bars))
    bottom = np.zeros(len(bars))
    for comp in COMPONENTS:
        h = np.array([r["components"].get(comp, 0.0) for r, _ in bars])
        ax.bar(x, h, 0.65, bottom=bottom, label=comp, color=COLOURS[comp])
        bottom += h
    for xi, (r, _) in zip(x, bars):
        label = f"{r['real_s_per_sim_s']:.3f}"
        if scaling and r["n_agents"] > 1:
            label += f"\n{r['real_s_per_sim_s'] / r['n_agents']:.3f}/inf."
        ax.text(xi, r["real_s_per_sim_s"], label, ha="center", va="bottom", fontsize=7)
    if scaling:
        one = next((r for r, _ in bars if r["name"] == "agents_1"), None)
        if one is not None:
            lin = [one["real_s_per_sim_s"] * r["n_agents"] for r, _ in bars]
            ax.plot(x, lin, "k--", marker="_", markersize=14, linewidth=0.8,
                    label="linear (N x 1 infant)")
    ax.set_xticks(x)
    ax.set_xticklabels([label for _, label in bars], fontsize=8)
    ax.set_title(title, fontsize=9)
    return float(bottom.max()) if len(bottom) else 0.0


def _figure(report, panels, title, path, aim=True, share=True):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    widths = [max(2, len(bars)) for _, bars in panels]
    fig = Figure(figsize=(max(6.0, 1.0 * sum(widths) + 1.5) + 1.8, 5.2), dpi=120)
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(panels), sharey=False, squeeze=False,
                        gridspec_kw={"width_ratios": widths})[0]
    tops = [_draw_panel(ax, ptitle, bars, scaling=ptitle.startswith("infants"))
            for ax, (ptitle, bars) in zip(axes, panels)]
    for i, ax in enumerate(axes):
        top = max(tops) if share else tops[i]
        ax.set_ylim(0, max(top * 1.2, TARGETS["default_max"] * 1.15 if aim else 0.0,
                           MIMO_REFERENCE["without_vision"] * 1.15))
        if aim:
            ax.axhline(TARGETS["default_max"], color="#B22222", linestyle="--", linewidth=0.9,
                       label=f"aim for default: {TARGETS['default_max']}")
        ax.axhline(MIMO_REFERENCE["without_vision"], color="0.25", linestyle=":", linewidth=1,
                   label=f"original MIMo,\nwithout vision: {MIMO_REFERENCE['without_vision']}")
        ax.axhline(MIMO_REFERENCE["physics_only"], color="0.55", linestyle=":", linewidth=1,
                   label=f"original MIMo,\nphysics only: {MIMO_REFERENCE['physics_only']}")
        if i and share:
            ax.tick_params(labelleft=False)
        ax.grid(axis="y", linewidth=0.3, alpha=0.6)
    axes[0].set_ylabel("real s per simulated s")
    found = {}
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            found.setdefault(lab, h)
    # components top of the stack first, then the reference lines
    labels = [c for c in reversed(COMPONENTS) if c in found]
    labels += [lab for lab in found if lab not in COMPONENTS]
    fig.legend([found[lab] for lab in labels], labels, loc="center right", fontsize=7,
               frameon=False)
    m = report["machine"]
    fig.suptitle(f"{title}\n{m['cpu']}, {m.get('usable_cores') or m['cores']} cores, MuJoCo "
                 f"{m['mujoco']}, MUJOCO_GL={m['mujoco_gl']} (software rendering)\n"
                 f"original MIMo, default configuration, here: ~{MIMO_REFERENCE['default']:g} "
                 "real s / sim s (off the scale)", fontsize=9)
    fig.tight_layout(rect=(0, 0, 1 - 1.6 / fig.get_figwidth(), 1))
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)


def plot_report(report, path: str | os.PathLike) -> list[Path]:
    """Stacked bar charts of the components: the paper's grid (Fig. 6) at ``path``, tasks,
    bodies and scaling (Fig. 7) at ``<stem>_tasks_scaling.png`` beside it (whichever has bars
    comes first at ``path`` when only one has). Returns the paths written."""
    path = Path(path)
    figs = _panels(report)
    jobs = [("grid", "The paper's grid: one infant, two objects, every sense, recorded"),
            ("tasks", "Tasks, bodies, infants in one world")]
    jobs = [(k, t) for k, t in jobs if figs[k]]
    written = []
    for i, (key, title) in enumerate(jobs):
        out = path if i == 0 else path.with_name(f"{path.stem}_tasks_scaling{path.suffix}")
        _figure(report, figs[key], title, out, aim=key == "grid", share=key == "grid")
        written.append(out)
    return written


# -- CLI -------------------------------------------------------------------------------------
def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "bench", help="measure real seconds per simulated second, by component",
        description="Measure real seconds per simulated second (and env build time) for each "
                    "configuration, split by component. Default set: "
                    + ", ".join(DEFAULT_CONFIGS) + "; also: "
                    + ", ".join(n for n in CONFIGS if n not in DEFAULT_CONFIGS) + ".")
    parser.add_argument("--json", default="bench.json", metavar="FILE",
                        help="where to write the results (default: bench.json)")
    parser.add_argument("--sim-seconds", type=float, default=DEFAULT_SIM_SECONDS, metavar="S",
                        help=f"simulated seconds per configuration (default: "
                             f"{DEFAULT_SIM_SECONDS:g}, one episode of the grid)")
    parser.add_argument("--only", default=None, metavar="NAME,...",
                        help="comma-separated configurations to run (default: the default set; "
                             "'all': every configuration)")
    parser.add_argument("--markdown", default=None, metavar="FILE",
                        help="write a Markdown report there (default: none)")
    parser.add_argument("--update-benchmarks-md", action="store_true",
                        help="write BENCHMARKS.md (and docs/benchmarks.png unless --plot is given)")
    parser.add_argument("--plot", default=None, metavar="FILE.png",
                        help="write stacked bar charts of the components there (and a second "
                             "one, tasks and scaling, beside it as <stem>_tasks_scaling.png)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random actions")
    parser.add_argument("--no-recording", action="store_true",
                        help="do not record the runs (the recording component is then 0)")
    parser.add_argument("--from-json", default=None, metavar="FILE",
                        help="measure nothing: re-render --markdown/--plot from an earlier --json "
                             "output (its recorded command is kept)")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    parser.add_argument("--no-cold-start", action="store_true",
                        help="skip the fresh-process build measurements")
    parser.set_defaults(func=run)
    return parser


def _command(args, markdown, plot) -> str:
    parts = ["mimo-social bench", f"--json {args.json}", f"--sim-seconds {args.sim_seconds:g}"]
    if args.only:
        parts.append(f"--only {args.only}")
    if args.seed:
        parts.append(f"--seed {args.seed}")
    if getattr(args, "no_recording", False):
        parts.append("--no-recording")
    if args.no_cold_start:
        parts.append("--no-cold-start")
    if markdown:
        parts.append(f"--markdown {markdown}")
    if plot:
        parts.append(f"--plot {plot}")
    return " ".join(parts)


def run(args) -> int:
    try:
        names = _check_names(args.only)
    except ValueError as e:
        print(f"mimo-social bench: {e}", file=sys.stderr)
        return 2
    markdown, plot = args.markdown, args.plot
    if args.update_benchmarks_md:
        markdown = markdown or "BENCHMARKS.md"
        plot = plot or "docs/benchmarks.png"
    if args.from_json:
        report = json.loads(Path(args.from_json).read_text())
    else:
        report = run_benchmarks(names, args.sim_seconds, seed=args.seed,
                                progress=not args.no_progress,
                                measure_cold_start=not args.no_cold_start,
                                record=not getattr(args, "no_recording", False))
        report["settings"]["command"] = _command(args, markdown, plot)
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    plots = plot_report(report, plot) if plot else []
    if markdown:
        md = Path(markdown)
        rel = [os.path.relpath(Path(p).resolve(), md.resolve().parent) for p in plots]
        md.parent.mkdir(parents=True, exist_ok=True)
        md.write_text(markdown_report(report, report["settings"].get("command"), rel) + "\n")
    print(markdown_table(report))
    for s in report.get("skipped") or []:
        print(f"skipped: {s['name']}: {s['reason']}")
    for c in target_checks(report):
        print(f"target: {c['target']}: {c['measured']} -> {'met' if c['met'] else 'NOT met'}")
    for v in jacobian_verdict(report):
        print(f"jacobian, {v['n_agents']} agent(s): {v['winner']} "
              f"(dense faster by {v['dense_faster_by'] * 100:+.1f} % of physics in the median "
              f"chunk, in {v['dense_faster_in'] * 100:.0f} % of chunks; unstable "
              f"episodes dense {v['dense_unstable']}, sparse {v['sparse_unstable']})")
    written = [str(p) for p in (None if args.from_json else args.json, markdown, *plots) if p]
    print("wrote " + ", ".join(written))
    return 0
