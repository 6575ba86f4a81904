"""How close the env step comes to the physics floor: the env's step against a bare ``mj_step``
loop on the same compiled model, replaying the same trajectory.

For each configuration (free play, 1, 2 or 8 standing infants, spring-damper motors, no eyes,
with or without the skin) the env steps under smooth random actions in chunks of ``chunk``
control steps. Each chunk is then replayed on a second ``MjData`` of the same model: from the
state the chunk started in, for each control step the controls and applied forces the env set,
``frame_skip`` calls of ``mujoco.mj_step`` and nothing else. The two alternate chunk by chunk
(the same load meets both), timed with the thread's CPU clock; the replay ends in the env's state
exactly (checked: a floor of another trajectory would measure nothing). Reported per
configuration: CPU ms per control step of the env and of the floor, their ratio (median over
chunks) and the env's own split (shares of physics, actuation, senses, task, other) from its
timers (wall clock: on a busy machine they include waits the CPU clock does not).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import mujoco
import numpy as np

from ..core.random_actions import random_action_block
from ..envs import free_play_v0

__all__ = ["FloorConfig", "FLOOR_CONFIGS", "measure", "format_results"]

#: the state a chunk's replay starts from (everything that evolves, and the inputs)
STATE = mujoco.mjtState.mjSTATE_INTEGRATION


@dataclass(frozen=True)
class FloorConfig:
    """One configuration: ``n_agents`` standing infants, the skin on or off, the constraint
    Jacobian (None: the default physics)."""

    n_agents: int
    touch: bool
    jacobian: str | None = None

    @property
    def name(self) -> str:
        return f"{self.n_agents} infant{'s' if self.n_agents > 1 else ''}" \
               + (", touch" if self.touch else "") \
               + (f", {self.jacobian} Jacobian" if self.jacobian else "")

    def env(self):
        physics = {"jacobian": self.jacobian} if self.jacobian else None
        return free_play_v0.parallel_env(n_agents=self.n_agents, touch=self.touch,
                                         vision=False, max_steps=10 ** 9, physics=physics)


#: the configurations of BENCHMARKS.md: 1, 2 and 8 infants, without and with touch
FLOOR_CONFIGS = tuple(FloorConfig(n, t) for n in (1, 2, 8) for t in (False, True))


def _cpu() -> float:
    return time.thread_time()


def _chunk(env, actions: list[dict], floor_data, m):
    """One chunk (``actions``: one dict per control step): the env's CPU seconds, the floor's,
    and whether the replay ended in the env's state."""
    w = env.world
    d = w.data
    start = np.empty(mujoco.mj_stateSize(m, STATE))
    mujoco.mj_getState(m, d, start, STATE)
    inputs = []
    t0 = _cpu()
    for step in actions:
        env.step(step)
        inputs.append((d.ctrl.copy(), d.qfrc_applied.copy(), d.xfrc_applied.copy()))
    t_env = _cpu() - t0
    fd = floor_data
    mujoco.mj_setState(m, fd, start, STATE)
    skip = env.frame_skip
    t0 = _cpu()
    for ctrl, qfrc, xfrc in inputs:
        fd.ctrl[:] = ctrl
        fd.qfrc_applied[:] = qfrc
        fd.xfrc_applied[:] = xfrc
        for _ in range(skip):
            mujoco.mj_step(m, fd)
    t_floor = _cpu() - t0
    same = bool(np.array_equal(fd.qpos, d.qpos) and np.array_equal(fd.qvel, d.qvel))
    return t_env, t_floor, same


def measure_one(config: FloorConfig, chunks: int = 10, chunk: int = 100, seed: int = 0) -> dict:
    """The figures of one configuration over ``chunks`` chunks of ``chunk`` control steps."""
    env = config.env()
    env.reset(seed=seed)
    m = env.world.model
    floor_data = mujoco.MjData(m)
    warm = min(chunk, 20)
    block = random_action_block(env, warm + chunks * chunk, seed)   # made before timing
    _chunk(env, block[:warm], floor_data, m)    # warm-up, not counted
    timing0 = dict(env.timing)
    envs, floors, same = [], [], True
    for k in range(chunks):
        t_env, t_floor, ok = _chunk(env, block[warm + k * chunk:warm + (k + 1) * chunk],
                                    floor_data, m)
        envs.append(t_env)
        floors.append(t_floor)
        same &= ok
    env.close()
    steps = chunks * chunk
    spent = {k: env.timing[k] - timing0[k] for k in env.timing}
    total = sum(spent.values()) or 1.0
    env_ms = np.array(envs) * 1e3 / chunk
    floor_ms = np.array(floors) * 1e3 / chunk
    return {"config": config.name, "n_agents": config.n_agents, "touch": config.touch,
            "steps": steps, "env_ms": float(np.median(env_ms)),
            "floor_ms": float(np.median(floor_ms)),
            "ratio": float(np.median(env_ms / np.maximum(floor_ms, 1e-12))),
            "same_trajectory": same,
            "split_pct": {k: 100 * v / total for k, v in {
                "physics": spent["physics"], "actuation": spent["actuation"],
                "senses": sum(v for k, v in spent.items()
                              if k not in ("physics", "actuation", "task", "other")),
                "task": spent["task"], "other": spent["other"]}.items()}}


def measure(configs=FLOOR_CONFIGS, chunks: int = 10, chunk: int = 100, seed: int = 0,
            progress: bool = False) -> list[dict]:
    """:func:`measure_one` for each configuration (a tqdm bar with ``progress``)."""
    from tqdm import tqdm
    return [measure_one(c, chunks, chunk, seed)
            for c in tqdm(configs, disable=not progress, unit="config")]


def format_results(results: list[dict]) -> str:
    """A markdown table: per configuration the env's and the floor's CPU ms per control step,
    their ratio and the env's split."""
    lines = ["| configuration | env ms / step | floor ms / step | env / floor | physics % | "
             "actuation % | senses % | task % | other % | same trajectory |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        s = r["split_pct"]
        lines.append(f"| {r['config']} | {r['env_ms']:.3f} | {r['floor_ms']:.3f} | "
                     f"**{r['ratio']:.2f}** | {s['physics']:.0f} | {s['actuation']:.0f} | "
                     f"{s['senses']:.0f} | {s['task']:.0f} | {s['other']:.0f} | "
                     f"{'yes' if r['same_trajectory'] else 'NO'} |")
    return "\n".join(lines)
