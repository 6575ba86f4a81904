"""The timed runs: every configuration is built (timed), then they advance in turns of
:data:`~.configs.CHUNK` control steps until each has run its simulated seconds.

Every configuration runs the same smooth random actions
(:func:`mimo_social.core.random_actions.random_action_block`: low-pass filtered uniform noise per
motor, seeded, mapped onto each agent's action-space bounds), generated in a block *before* the
timed loop, so their cost is never counted. Resets between episodes are not counted either (their
time is taken out of the total and their sense readings out of the components).

The total of a configuration is split with the env's own ``env.timing`` (actuation, physics,
touch, vision, proprioception, vestibular, task, accumulated inside ``env.step``), the time spent
in the recorder (``Recorder.log_step`` and the final ``close``: ``recording``), and ``other``:
everything else, i.e. the bookkeeping inside ``step`` (building the reward/info dicts,
``env.timing["other"]``) plus the Python overhead around it (the loop, the call, the timer calls
themselves). The components therefore sum to the total.

Running in turns means a drift of the machine's speed during the run (other processes, a shared
virtual host) touches every configuration alike, and the chunk times (``rounds``) of two
configurations can be compared pair by pair (that is how
:func:`~.report.jacobian_verdict` decides between the dense and the sparse Jacobian). A
configuration that cannot be built (e.g. a body or actuation model not available yet) is listed
under ``skipped`` with the reason instead of stopping the run.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Mapping, Sequence

import mujoco
import numpy as np

from ..core.random_actions import random_action_block
from .builds import cold_start, error_text, skin_cache_builds
from .configs import (CHUNK, COMPONENTS, CONFIGS, DEFAULT_SIM_SECONDS, ENV_COMPONENTS,
                      EPISODE_STEPS, WARMUP_STEPS, BenchConfig, check_names, mimo_reference)
from .machine import load_average, machine_info

__all__ = ["run_benchmarks"]


def _zero_timing(env):
    for key in env.timing:
        env.timing[key] = 0.0


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
            self.rec_error = error_text(e)

    def _recorder_failed(self, e: BaseException):
        self.rec_error = error_text(e)
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
                self.rec_error = error_text(e)
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
        touch = self.env.systems.get("touch")
        return int(touch.n_points) if touch is not None else None

    def _skin_cache(self):
        touch = self.env.systems.get("touch")
        if touch is None:
            return None
        return sorted({sk.from_cache or "built" for sk in touch.skins if sk is not None}) or None

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
        self._mj_step = mujoco.mj_step
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

    names = check_names(names)
    if not sim_seconds > 0:
        raise ValueError(f"sim_seconds={sim_seconds}; must be positive")
    load_before = load_average()
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
            print(f"mimo-social bench sim: the throw-away build failed: {error_text(e)}",
                  file=sys.stderr)
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
                    skipped.append({"name": name, "stage": "build", "reason": error_text(e)})
                    bar.update(sim_seconds)
                    print(f"mimo-social bench sim: skipping {name}: {error_text(e)}",
                          file=sys.stderr)
            while not all(r.done for r in runners):
                for r in list(runners):
                    if r.done:
                        continue
                    bar.set_description(r.cfg.name)
                    try:
                        n = r.run_chunk()
                    except Exception as e:  # noqa: BLE001
                        skipped.append({"name": r.cfg.name, "stage": f"run (step {r.k})",
                                        "reason": error_text(e)})
                        bar.update(sim_seconds * (1 - r.k / r.n_steps))
                        runners.remove(r)
                        r.close()
                        continue
                    bar.update(n * sim_seconds / r.n_steps)
                loads.append(load_average())
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
            "load_average_after": load_average(),
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
