"""``mimo-social bench``: real seconds per simulated second, split by component.

Every configuration runs the same smooth random actions (low-pass filtered uniform noise per
motor, seeded, see :func:`smooth_random_actions`), generated in a block *before* the timed loop,
so their cost is never counted. Resets between episodes are not counted either (their time is
taken out of the total and their sense readings out of the components).

The total of a configuration is split with the env's own ``env.timing`` (actuation, physics,
proprioception, vestibular, task, accumulated inside ``env.step``); ``other`` is everything
else: the bookkeeping inside ``step`` (building the reward/info dicts, ``env.timing["other"]``)
plus the Python overhead around it (the loop, the call, the timer calls themselves). The
components therefore sum to the total.

``physics_only`` is the floor: the 1-infant free-play model stepped by a bare ``mujoco.mj_step``
loop with the same actions written straight into ``data.ctrl`` as torques.

Every env is built first (``build_s``), then the configurations advance in turns of ``CHUNK``
control steps until each has run its simulated seconds: a drift of the machine's speed during
the run (other processes, a shared virtual host) then touches every configuration alike, and
the chunk times (``rounds``) of two configurations can be compared pair by pair (that is how
:func:`jacobian_verdict` decides between the dense and the sparse Jacobian).

Use :func:`run_benchmarks` from Python (tests), or the command::

    mimo-social bench --json bench.json --sim-seconds 20 --markdown BENCHMARKS.md \\
        --plot docs/benchmarks.png
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

__all__ = [
    "CONFIGS", "COMPONENTS", "BenchConfig", "smooth_random_actions", "run_benchmarks",
    "machine_info", "markdown_report", "plot_report", "add_parser", "run",
]

COMPONENTS = ("physics", "actuation", "proprioception", "vestibular", "task", "other")
ENV_COMPONENTS = ("actuation", "physics", "proprioception", "vestibular", "task")

#: Steps per timed chunk; the progress bar is updated between chunks, outside the timer.
CHUNK = 100
#: Control steps run (and thrown away) before the timed loop of every configuration.
WARMUP_STEPS = 20

#: The original MIMo, measured on this machine (real s per simulated s; build times in s).
MIMO_REFERENCE = {
    "physics_only": 0.08,
    "without_vision": 0.30,
    "build_with_touch_s": 120.0,
    "build_without_touch_s": 6.0,
}

#: Targets of this package (see BENCHMARKS.md).
TARGETS = {
    "agents_1_max": 0.04,        # one infant, physics + proprioception + vestibular
    "build_2_agents_max_s": 2.0,  # building a 2-infant env
    "agents_4_over_1_max": 4.5,   # 4 infants cost at most 4.5x one
}

_SENSES_ON = {"proprioception": True, "vestibular": True, "expressions": True}


@dataclass(frozen=True)
class BenchConfig:
    """One benchmarked configuration: an env factory module and its keyword arguments."""

    name: str
    module: str                      # module in mimo_social.envs, e.g. "free_play_v0"
    kwargs: Mapping[str, Any] = field(default_factory=dict)
    description: str = ""
    raw_physics: bool = False        # True: time a bare mj_step loop on the env's model

    def make_env(self):
        import importlib

        mod = importlib.import_module(f"mimo_social.envs.{self.module}")
        return mod.parallel_env(**dict(self.kwargs))


def _free_play(name, n, description, jacobian=None, raw=False):
    kwargs = {"n_agents": n, **_SENSES_ON}
    if jacobian is not None:
        kwargs["physics"] = {"jacobian": jacobian}
    return BenchConfig(name, "free_play_v0", kwargs, description, raw)


CONFIGS: dict[str, BenchConfig] = {c.name: c for c in (
    _free_play("agents_1", 1, "free play, 1 infant: physics, actuation, proprioception, "
               "vestibular, expressions"),
    _free_play("agents_2", 2, "free play, 2 infants (as agents_1)"),
    _free_play("agents_4", 4, "free play, 4 infants (as agents_1)"),
    _free_play("physics_only", 1, "1-infant free-play model, bare mujoco.mj_step loop (floor)",
               raw=True),
    BenchConfig("high_five", "high_five_v0", {}, "high five task, 2 infants (defaults)"),
    BenchConfig("reach", "reach_v0", {}, "reach task, 1 infant (defaults)"),
    _free_play("jacobian_dense_1", 1, "agents_1 with physics jacobian='dense'", "dense"),
    _free_play("jacobian_sparse_1", 1, "agents_1 with physics jacobian='sparse'", "sparse"),
    _free_play("jacobian_dense_4", 4, "agents_4 with physics jacobian='dense'", "dense"),
    _free_play("jacobian_sparse_4", 4, "agents_4 with physics jacobian='sparse'", "sparse"),
)}


# -- actions ---------------------------------------------------------------------------------
def smooth_random_actions(n_steps: int, n_motors: int, seed, dt: float = 0.01,
                          tau: float = 0.1, n_expressions: int = 7,
                          expression_period: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Low-pass filtered uniform noise per motor and a slowly switching expression id.

    Uniform noise ``w ~ U(-1, 1)`` through two cascaded first-order low-pass filters
    ``x[k+1] = a x[k] + (1 - a) in[k]``, ``a = exp(-dt / tau)`` (so the motors move smoothly,
    like a slow policy, not like white noise), rescaled to the spread of ``U(-1, 1)`` and clipped
    to [-1, 1]. The filters run ``10 tau`` first so the block starts in their steady state. The
    expression changes on average every ``expression_period`` seconds. Returns ``(motors
    (n_steps, n_motors) float32, expressions (n_steps,) int64)``; the same ``seed`` gives the
    same actions.
    """
    rng = np.random.default_rng(seed)
    a = float(np.exp(-dt / tau))
    # steady-state std of the cascade's output, relative to its input's
    gain = np.sqrt((1.0 + a) ** 3 / ((1.0 - a) * (1.0 + a * a)))
    burn = int(np.ceil(10 * tau / dt))
    noise = rng.uniform(-1.0, 1.0, (burn + n_steps, n_motors))
    x1 = np.zeros(n_motors)
    x2 = np.zeros(n_motors)
    motors = np.empty((n_steps, n_motors))
    for k in range(burn + n_steps):
        x1 = a * x1 + (1.0 - a) * noise[k]
        x2 = a * x2 + (1.0 - a) * x1
        if k >= burn:
            motors[k - burn] = x2
    motors = np.clip(motors * gain, -1.0, 1.0).astype(np.float32)
    switch = rng.random(n_steps) < dt / expression_period
    switch[0] = True
    draws = rng.integers(0, n_expressions, n_steps)
    expressions = draws[np.maximum.accumulate(np.where(switch, np.arange(n_steps), 0))]
    return motors, expressions.astype(np.int64)


def _agent_seeds(seed: int, n_agents: int):
    return np.random.SeedSequence(seed).spawn(n_agents)


def _action_block(env, n_steps: int, seed: int) -> list[dict]:
    """Every action dict of the run, built before timing (agent i always gets stream i)."""
    from gymnasium import spaces

    per_agent = []
    for name, s in zip(env.possible_agents, _agent_seeds(seed, len(env.possible_agents))):
        space = env.action_space(name)
        with_expr = isinstance(space, spaces.Dict)
        box = space["motors"] if with_expr else space
        n_expr = space["expression"].n if with_expr else 7
        motors, expr = smooth_random_actions(n_steps, box.shape[0], s, env.dt,
                                             n_expressions=n_expr)
        per_agent.append((name, with_expr, motors, expr))
    block = []
    for k in range(n_steps):
        block.append({name: ({"motors": motors[k], "expression": int(expr[k])} if with_expr
                             else motors[k])
                      for name, with_expr, motors, expr in per_agent})
    return block


# -- timing ----------------------------------------------------------------------------------
def _zero_timing(env):
    for key in env.timing:
        env.timing[key] = 0.0


class _EnvRunner:
    """One configuration: its env, its action block, and what its timed chunks accumulated.

    Configurations advance in turns of ``CHUNK`` steps (see :func:`run_benchmarks`), so a slow
    drift of the machine's speed (other processes, a shared host) touches every configuration
    alike. Resets are taken out of the time and the timing.
    """

    def __init__(self, cfg: BenchConfig, sim_seconds: float, seed: int):
        self.cfg = cfg
        t = time.perf_counter()
        self.env = env = cfg.make_env()
        self.build_s = time.perf_counter() - t
        self.n_steps = max(1, int(round(sim_seconds / env.dt)))
        self.block = _action_block(env, self.n_steps, seed)
        self.k = 0
        self.real = self.cpu = 0.0
        self.episodes, self.unstable, self.reasons, self.ncon = 1, 0, [], []
        self.rounds, self.rounds_physics = [], []
        self._warm_up(seed)

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

    def _physics_time(self) -> float:
        return self.env.timing["physics"]

    def run_chunk(self) -> int:
        """Run the next ``CHUNK`` steps (fewer at the end); return how many ran."""
        env, block, timing, step = self.env, self.block, self.env.timing, self.env.step
        k = first = self.k
        end = min(self.n_steps, k + CHUNK)
        phys0 = self._physics_time()
        r0, c0 = time.perf_counter(), time.process_time()
        while k < end:
            if not env.agents:
                r1, c1 = time.perf_counter(), time.process_time()
                saved = dict(timing)
                env.reset()
                timing.update(saved)
                self.episodes += 1
                r0 += time.perf_counter() - r1
                c0 += time.process_time() - c1
            infos = step(block[k])[4]
            k += 1
            if not env.agents:
                for info in infos.values():
                    if "instability" in info:
                        self.unstable += 1
                        self.reasons.append(info["instability"])
                        break
        real = time.perf_counter() - r0
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
        rest = max(0.0, self.real - sum(inside.values()))
        detail = {"in_step": float(timing["other"]),
                  "outside_step": max(0.0, rest - float(timing["other"]))}
        return {**inside, "other": rest}, detail

    def result(self) -> dict:
        env = self.env
        sim = self.n_steps * env.dt
        comps, detail = self.components()
        return {
            "name": self.cfg.name,
            "description": self.cfg.description,
            "n_agents": 1 if self.cfg.raw_physics else len(env.possible_agents),
            "real_s_per_sim_s": self.real / sim,
            "cpu_s_per_sim_s": self.cpu / sim,
            "build_s": self.build_s,
            "components": {k: comps[k] / sim for k in COMPONENTS},
            "other_detail": {k: v / sim for k, v in detail.items()},
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

    def close(self):
        self.env.close()
        self.block = None


class _RawPhysicsRunner(_EnvRunner):
    """A bare ``mj_step`` loop on the env's model; torques precomputed from the same actions,
    episodes as long as the env's (the state reset to the initial pose in between)."""

    def __init__(self, cfg, sim_seconds, seed):
        super().__init__(cfg, sim_seconds, seed)
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


# -- the run ---------------------------------------------------------------------------------
def _check_names(names) -> list[str]:
    if names is None:
        return list(CONFIGS)
    if isinstance(names, str):
        names = [n for n in names.split(",")]
    names = [n.strip() for n in names if n.strip()]
    unknown = [n for n in names if n not in CONFIGS]
    if unknown or not names:
        raise ValueError(f"unknown benchmark configuration(s) {unknown or names}; "
                         f"allowed: {', '.join(CONFIGS)}")
    return list(dict.fromkeys(names))


def run_benchmarks(names: Sequence[str] | str | None = None, sim_seconds: float = 20.0,
                   seed: int = 0, progress: bool = True, measure_cold_start: bool = True) -> dict:
    """Benchmark the named configurations (all when ``None``) for ``sim_seconds`` each.

    Returns ``{"machine", "settings", "cold_start", "results"}``; each result is
    ``{"name", "n_agents", "real_s_per_sim_s", "cpu_s_per_sim_s", "build_s", "components",
    ...}`` with the components in real s per simulated s (they sum to the total).
    """
    from tqdm import tqdm

    names = _check_names(names)
    if not sim_seconds > 0:
        raise ValueError(f"sim_seconds={sim_seconds}; must be positive")
    load_before = _load()
    # One throw-away build first, so lazy one-time work (tables, face textures) is not
    # charged to whichever configuration happens to run first.
    t = time.perf_counter()
    CONFIGS["agents_1"].make_env().close()
    first_build = time.perf_counter() - t

    runners = []
    with tqdm(total=len(names) * sim_seconds, desc="bench", unit="sim s", disable=not progress,
              file=sys.stderr, dynamic_ncols=True,
              bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} sim s [{elapsed}<{remaining}]") as bar:
        for name in names:  # build every env first (timed), then run them in turns
            bar.set_description(f"build {name}")
            cfg = CONFIGS[name]
            runners.append((_RawPhysicsRunner if cfg.raw_physics else _EnvRunner)(
                cfg, sim_seconds, seed))
        while not all(r.done for r in runners):
            for r in runners:
                if r.done:
                    continue
                bar.set_description(r.cfg.name)
                n = r.run_chunk()
                bar.update(n * sim_seconds / r.n_steps)
    results = [r.result() for r in runners]
    for r in runners:
        r.close()
    del runners
    report = {
        "machine": machine_info(),
        "settings": {
            "sim_seconds": sim_seconds, "seed": seed, "warmup_steps": WARMUP_STEPS,
            "first_build_s": first_build, "load_average_before": load_before,
            "load_average_after": _load(),
            "date_utc": time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime()),
        },
        "cold_start": cold_start() if measure_cold_start else None,
        "results": results,
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


def target_checks(report) -> list[dict]:
    """The package's speed targets, each with the measured value and whether it is met."""
    res = _by_name(report)
    out = []
    if "agents_1" in res:
        r = res["agents_1"]
        c = r["components"]
        pps = c["physics"] + c["proprioception"] + c["vestibular"]
        out.append({"target": "one infant (physics + proprioception + vestibular) "
                              f"<= {TARGETS['agents_1_max']} real s / sim s",
                    "measured": f"{pps:.4f} (those three components); {r['real_s_per_sim_s']:.4f} "
                                "for the whole step (with actuation, expressions, overhead)",
                    "met": pps <= TARGETS["agents_1_max"],
                    "met_whole_step": r["real_s_per_sim_s"] <= TARGETS["agents_1_max"]})
    builds = []
    cold = report.get("cold_start") or {}
    if "build_2_agents_s" in cold:
        builds.append(("fresh process", cold["build_2_agents_s"]))
    if "agents_2" in res:
        builds.append(("in the benchmark process", res["agents_2"]["build_s"]))
    if builds:
        worst = max(b for _, b in builds)
        out.append({"target": f"building a 2-infant env < {TARGETS['build_2_agents_max_s']} s",
                    "measured": "; ".join(f"{b:.3f} s {where}" for where, b in builds),
                    "met": worst < TARGETS["build_2_agents_max_s"]})
    if "agents_1" in res and "agents_4" in res:
        ratio = res["agents_4"]["real_s_per_sim_s"] / res["agents_1"]["real_s_per_sim_s"]
        out.append({"target": f"4 infants <= {TARGETS['agents_4_over_1_max']}x one",
                    "measured": f"{ratio:.2f}x",
                    "met": ratio <= TARGETS["agents_4_over_1_max"]})
    return out


# -- Markdown --------------------------------------------------------------------------------
def _f(x: float) -> str:
    return f"{x:.4f}"


def markdown_table(report) -> str:
    head = ("| configuration | agents | real s / sim s | × real time | physics | actuation "
            "| proprioception | vestibular | task | other | CPU s / sim s | build s "
            "| episodes (unstable) |")
    lines = [head, "|" + "---|" * 13]
    for r in report["results"]:
        c = r["components"]
        lines.append(
            f"| `{r['name']}` | {r['n_agents']} | **{_f(r['real_s_per_sim_s'])}** "
            f"| {1.0 / r['real_s_per_sim_s']:.1f} "
            + "".join(f"| {_f(c[k])} " for k in COMPONENTS)
            + f"| {_f(r['cpu_s_per_sim_s'])} | {r['build_s']:.3f} "
            f"| {r['episodes']} ({r['unstable_episodes']}) |")
    return "\n".join(lines)


def _mimo_paragraph(report) -> str:
    res = _by_name(report)
    ref = MIMO_REFERENCE
    parts = []
    if "physics_only" in res:
        p = res["physics_only"]["real_s_per_sim_s"]
        parts.append(f"physics alone takes {p:.4f} real s per simulated s here against "
                     f"{ref['physics_only']} for the original MIMo ({ref['physics_only'] / p:.1f}x "
                     "faster)")
    if "agents_1" in res:
        a = res["agents_1"]["real_s_per_sim_s"]
        parts.append(f"one infant with actuation, proprioception, vestibular sense and expressions "
                     f"takes {a:.4f} against {ref['without_vision']} for the original MIMo without "
                     f"vision ({ref['without_vision'] / a:.1f}x faster; the original's figure "
                     "covers every sense but vision, and this version has no touch skin yet, so "
                     "this comparison flatters it)")
    if "agents_4" in res:
        a4 = res["agents_4"]["real_s_per_sim_s"]
        parts.append(f"four infants in one world take {a4:.4f}, "
                     + ("still less than" if a4 < ref["without_vision"] else "more than")
                     + " one original MIMo without vision")
    builds = [r["build_s"] for r in report["results"]]
    cold = report.get("cold_start") or {}
    if builds:
        b = f"building an env takes {min(builds):.2f} to {max(builds):.2f} s"
        if "build_2_agents_s" in cold:
            b += (f" ({cold['build_2_agents_s']:.2f} s for 2 infants in a fresh process, after "
                  f"{cold['import_s']:.2f} s of imports)")
        b += (f", against ~{ref['build_with_touch_s']:.0f} s for the original MIMo with touch "
              f"and ~{ref['build_without_touch_s']:.0f} s without")
        parts.append(b)
    if not parts:
        return ""
    return ("Compared with the original MIMo measured on this machine: "
            + "; ".join(parts) + ".")


def where_time_goes(report) -> str:
    """Data-driven remarks: the share of Python work beside the physics, tasks slower than it."""
    res = _by_name(report)
    parts = []
    for name in ("agents_1", "agents_4"):
        if name in res:
            r = res[name]
            c = r["components"]
            pct = {k: v / r["real_s_per_sim_s"] * 100 for k, v in c.items()}
            parts.append(f"in `{name}`, {100 - pct['physics']:.0f} % of the time is Python work "
                         f"beside the physics (actuation {pct['actuation']:.0f} %, "
                         f"proprioception {pct['proprioception']:.0f} %, "
                         f"other {pct['other']:.0f} %)")
    slow = [r for r in report["results"] if r["components"]["task"] > r["components"]["physics"]]
    for r in slow:
        parts.append(f"in `{r['name']}` the task's own per-step work (`task`) takes "
                     f"{r['components']['task']:.4f} real s / sim s, "
                     f"{r['components']['task'] / r['components']['physics']:.1f}x the physics")
    if not parts:
        return ""
    text = "; ".join(parts) + "."
    return text[0].upper() + text[1:]


def noise_note(report) -> str:
    """A sentence on the run's noise: agents_1 and jacobian_sparse_1 are the same configuration
    when sparse is the default."""
    res = _by_name(report)
    a, b = res.get("agents_1"), res.get("jacobian_sparse_1")
    if not a or not b or a.get("jacobian") != "sparse":
        return ""
    x, y = a["real_s_per_sim_s"], b["real_s_per_sim_s"]
    return (f"`agents_1` and `jacobian_sparse_1` are the same configuration (same actions, same "
            f"trajectory): their totals differ by {abs(x - y) / min(x, y) * 100:.0f} %, which "
            "is the measurement noise of this run; differences of that size between other rows "
            "mean nothing.")


def markdown_report(report, command: str | None = None, plot: str | None = None) -> str:
    """The whole BENCHMARKS.md text: machine, command, table, plot, targets, Jacobian, MIMo."""
    mach = report["machine"]
    st = report["settings"]
    out = ["# Benchmarks", "",
           "Real (wall-clock) seconds per simulated second, split by component, for each "
           "configuration; smaller is faster, and `× real time` is its inverse. Every "
           "configuration runs the same smooth random actions (low-pass filtered uniform noise "
           "per motor, seeded), generated before the timed loop. `other` is the Python overhead "
           "outside the env's timed sections (dict building in `step`, the call, the loop). "
           "`physics_only` is the floor: the 1-infant model stepped by a bare `mujoco.mj_step` "
           "loop. All envs are built first (`build s`), then the configurations run in turns "
           f"of {CHUNK} control steps, so a change in the machine's speed during the run "
           "touches them alike; resets between episodes are not counted. Episodes end at "
           "the task's time limit (free play: 10 simulated s) or its goal; the count in "
           "brackets ended unstable (`infos[agent][\"instability\"]`). `CPU s / sim s` is the "
           "process's CPU time: clearly below the real time, it means the benchmark waited for "
           "a CPU (other load on the machine).", "",
           "## Machine", "",
           f"- CPU: {mach['cpu']} ({mach['cores']} cores"
           + (f", {mach['usable_cores']} usable"
              if mach.get("usable_cores") != mach["cores"] else "")
           + (f", {mach['cpu_mhz']:.0f} MHz" if mach.get("cpu_mhz") else "")
           + (f"), {mach['memory_gb']} GB RAM" if mach.get("memory_gb") else ")"),
           f"- MuJoCo {mach['mujoco']}, NumPy {mach['numpy']}, Python {mach['python']}, "
           f"{mach['platform']}, MUJOCO_GL={mach['mujoco_gl']}",
           f"- measured {st['date_utc']} UTC, {st['sim_seconds']:g} simulated s per "
           f"configuration, seed {st['seed']}; load average before/after: "
           f"{st['load_average_before']} / {st['load_average_after']}", ""]
    if command:
        out += ["Produced by:", "", "```", command, "```", ""]
    out += ["## Results", "", markdown_table(report), ""]
    noise = noise_note(report)
    if noise:
        out += [noise, ""]
    if plot:
        out += [f"![Real seconds per simulated second, stacked by component]({plot})", ""]
    checks = target_checks(report)
    if checks:
        out += ["## Targets", "", "| target | measured | met |", "|---|---|---|"]
        for c in checks:
            out.append(f"| {c['target']} | {c['measured']} | {'yes' if c['met'] else '**no**'} |")
        out.append("")
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
    where = where_time_goes(report)
    if where:
        out += ["## Where the time goes", "", where, ""]
    para = _mimo_paragraph(report)
    if para:
        out += ["## Compared with the original MIMo", "", para, ""]
    return "\n".join(out)


# -- plot ------------------------------------------------------------------------------------
COLOURS = {"physics": "#4C72B0", "actuation": "#DD8452", "proprioception": "#55A868",
           "vestibular": "#C44E52", "task": "#8172B3", "other": "#937860"}


def plot_report(report, path: str | os.PathLike) -> None:
    """A stacked bar per configuration (components), with the original MIMo as reference lines."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    results = report["results"]
    names = [r["name"] for r in results]
    x = np.arange(len(results))
    fig = Figure(figsize=(max(6.0, 0.9 * len(results) + 2.5), 4.8), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    bottom = np.zeros(len(results))
    for comp in COMPONENTS:
        h = np.array([r["components"][comp] for r in results])
        ax.bar(x, h, 0.7, bottom=bottom, label=comp, color=COLOURS[comp])
        bottom += h
    for xi, r in zip(x, results):
        ax.text(xi, r["real_s_per_sim_s"], f"{r['real_s_per_sim_s']:.3f}", ha="center",
                va="bottom", fontsize=7)
    for key, label, style in (("physics_only", "original MIMo, physics only", ":"),
                              ("without_vision", "original MIMo, without vision", "--")):
        ax.axhline(MIMO_REFERENCE[key], color="0.3", linestyle=style, linewidth=1, label=label)
    ax.set_xticks(x)
    ax.set_xticklabels(names, rotation=35, ha="right", fontsize=8)
    ax.set_ylabel("real s per simulated s")
    m = report["machine"]
    ax.set_title(f"mimo_social: time per simulated second ({m['cpu']}, MuJoCo {m['mujoco']})",
                 fontsize=9)
    ax.legend(fontsize=7, ncol=2, loc="upper left")
    ax.set_ylim(0, max(MIMO_REFERENCE["without_vision"], float(bottom.max())) * 1.15)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)


# -- CLI -------------------------------------------------------------------------------------
def add_parser(subparsers) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "bench", help="measure real seconds per simulated second, by component",
        description="Measure real seconds per simulated second (and env build time) for each "
                    "configuration, split by component. Configurations: " + ", ".join(CONFIGS))
    parser.add_argument("--json", default="bench.json", metavar="FILE",
                        help="where to write the results (default: bench.json)")
    parser.add_argument("--sim-seconds", type=float, default=20.0, metavar="S",
                        help="simulated seconds per configuration (default: 20)")
    parser.add_argument("--only", default=None, metavar="NAME,...",
                        help="comma-separated configurations to run (default: all)")
    parser.add_argument("--markdown", default=None, metavar="FILE",
                        help="write a Markdown report there (default: none)")
    parser.add_argument("--update-benchmarks-md", action="store_true",
                        help="write BENCHMARKS.md (and docs/benchmarks.png unless --plot is given)")
    parser.add_argument("--plot", default=None, metavar="FILE.png",
                        help="write a stacked bar chart of the components there")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random actions")
    parser.add_argument("--from-json", default=None, metavar="FILE",
                        help="measure nothing: re-render --markdown/--plot from an earlier --json "
                             "output (its recorded command is kept)")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    parser.add_argument("--no-cold-start", action="store_true",
                        help="skip the fresh-process import and build measurement")
    parser.set_defaults(func=run)
    return parser


def _command(args, markdown, plot) -> str:
    parts = ["mimo-social bench", f"--json {args.json}", f"--sim-seconds {args.sim_seconds:g}"]
    if args.only:
        parts.append(f"--only {args.only}")
    if args.seed:
        parts.append(f"--seed {args.seed}")
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
                                measure_cold_start=not args.no_cold_start)
        report["settings"]["command"] = _command(args, markdown, plot)
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    if plot:
        plot_report(report, plot)
    if markdown:
        md = Path(markdown)
        rel = None
        if plot:
            rel = os.path.relpath(Path(plot).resolve(), md.resolve().parent)
        md.parent.mkdir(parents=True, exist_ok=True)
        md.write_text(markdown_report(report, report["settings"].get("command"), rel) + "\n")
    print(markdown_table(report))
    for c in target_checks(report):
        print(f"target: {c['target']}: {c['measured']} -> {'met' if c['met'] else 'NOT met'}")
    for v in jacobian_verdict(report):
        print(f"jacobian, {v['n_agents']} agent(s): {v['winner']} "
              f"(dense faster by {v['dense_faster_by'] * 100:+.1f} % of physics in the median "
              f"chunk, in {v['dense_faster_in'] * 100:.0f} % of chunks; unstable "
              f"episodes dense {v['dense_unstable']}, sparse {v['sparse_unstable']})")
    written = [p for p in (None if args.from_json else args.json, markdown, plot) if p]
    print("wrote " + ", ".join(written))
    return 0
