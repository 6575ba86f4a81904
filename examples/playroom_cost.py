"""What the play room costs per step, against the bare floor (the figures of docs/playroom.md).

Run (headless)::

    MUJOCO_GL=egl python examples/playroom_cost.py [SIM_SECONDS]

1. Whole env steps of free play with 2 infants under smooth random actions, floor against play
   room, without and with 2 x 64 x 64 eyes per infant: the four configurations take turns of 100
   steps in this process (:func:`mimo_social.bench.vision_cost.bench_env`), so a change of the
   machine's speed touches them alike.
2. The eyes alone (2 infants x 2 eyes, 64 x 64, 30 recorded states), CPU time per step (all of
   the process's threads: the renderer's rasterizer threads too), the variants taking turns: the
   floor, the play room, the room drawn without its textures, and without its furniture.
3. Physics alone (``mj_step`` under sine controls, after 3 s of settling), CPU time, taking
   turns: the floor, the play room, and the play room with its resting toys asleep
   (``World.ROOM_SLEEP``, off by default: docs/playroom.md).
"""

from __future__ import annotations

import sys
import time

import mujoco
import numpy as np

from mimo_social.bench.vision_cost import bench_env
from mimo_social.core.world import World
from mimo_social.core.random_actions import smooth_random_actions
from mimo_social.envs import free_play_v0
from mimo_social.render.eye_renderer import Tile, TileRenderer

EYES = {"width": 64, "height": 64}


def whole_steps(sim_seconds: float) -> None:
    configs = {"floor, no eyes": dict(n_agents=2),
               "playroom, no eyes": dict(n_agents=2, scene="playroom"),
               "floor, 2 x 64x64 eyes": dict(n_agents=2, vision=EYES),
               "playroom, 2 x 64x64 eyes": dict(n_agents=2, vision=EYES, scene="playroom")}
    print(f"whole env steps, free play, 2 infants, {sim_seconds:g} simulated s each, interleaved")
    print("| configuration | ms per step | physics | vision |\n|---|---|---|---|")
    for r in bench_env(configs, sim_seconds=sim_seconds):
        ms = 1e3 * 0.01   # real s per simulated s -> ms per 10 ms step
        print(f"| {r['config']} | {r['total'] * ms:.2f} | {r['physics'] * ms:.2f} | "
              f"{r['vision'] * ms:.2f} |")


def _states(scene: str, n: int = 30):
    env = free_play_v0.parallel_env(n_agents=2, scene=scene)
    env.reset(seed=0)
    n_motors = env.action_space("infant_0")["motors"].shape[0]
    motors = [0.3 * smooth_random_actions(n, n_motors, i)[0] for i in range(2)]
    out = []
    for k in range(n):
        env.step({a: {"motors": motors[i][k], "expression": 0}
                  for i, a in enumerate(env.agents)})
        out.append(env.world.data.qpos.copy())
    return env, out


def eyes_alone(rounds: int = 12) -> None:
    floor, room = _states("floor"), _states("playroom")
    m = room[0].world.model
    room_mats = [i for i in range(m.nmat) if m.material(i).name.startswith("playroom/")]
    furniture = [g for g in range(m.ngeom) if m.geom_bodyid[g] == 0
                 and m.geom(g).name.count("/") >= 2]
    variants = {"floor": (floor, None), "playroom": (room, None),
                "playroom, untextured": (room, "untextured"),
                "playroom, no furniture": (room, "no furniture")}
    renderers, cpu = {}, {k: [] for k in variants}
    for k, ((env, _), _) in variants.items():
        cams = [int(c) for a in env.world.agents for c in a.eye_cameras]
        renderers[k] = (TileRenderer([Tile(64, 64) for _ in cams], [[0, 1], [2, 3]]),
                        list(enumerate(cams)))
    for _ in range(rounds):
        for k, ((env, states), change) in variants.items():
            m, d = env.world.model, env.world.data
            texid, group = m.mat_texid.copy(), m.geom_group.copy()
            if change == "untextured":
                m.mat_texid[room_mats] = -1
            elif change == "no furniture":
                m.geom_group[furniture] = 4
            r, jobs = renderers[k]
            r.render(m, d, jobs)
            t = time.process_time()
            for q in states:
                d.qpos[:] = q
                mujoco.mj_kinematics(m, d)
                mujoco.mj_camlight(m, d)
                r.render(m, d, jobs)
            cpu[k].append((time.process_time() - t) / len(states))
            m.mat_texid[:], m.geom_group[:] = texid, group
    print("\nthe eyes alone, 2 infants x 2 eyes 64x64, CPU ms per step (median of "
          f"{rounds} interleaved rounds)")
    print("| variant | CPU ms per step |\n|---|---|")
    for k, v in cpu.items():
        print(f"| {k} | {1e3 * np.median(v):.2f} |")


def physics_alone(rounds: int = 10, steps: int = 300) -> None:
    worlds = {}
    for name, scene, sleep in (("floor", "floor", False), ("playroom", "playroom", False),
                               ("playroom, toys may sleep", "playroom", True)):
        World.ROOM_SLEEP = sleep
        worlds[name] = free_play_v0.parallel_env(n_agents=2, scene=scene).world
    World.ROOM_SLEEP = False
    cpu = {k: [] for k in worlds}
    for w in worlds.values():
        for _ in range(600):
            mujoco.mj_step(w.model, w.data)
    for _ in range(rounds):
        for k, w in worlds.items():
            m, d = w.model, w.data
            phase = np.arange(m.nu)
            t = time.process_time()
            for _ in range(steps):
                d.ctrl[:] = 0.3 * np.sin(3.0 * d.time + phase)
                mujoco.mj_step(m, d)
            cpu[k].append((time.process_time() - t) / steps)
    print(f"\nphysics alone, 2 infants, CPU ms per mj_step (median of {rounds} interleaved rounds)")
    print("| world | nv | CPU ms per mj_step |\n|---|---|---|")
    for k, v in cpu.items():
        print(f"| {k} | {worlds[k].model.nv} | {1e3 * np.median(v):.3f} |")


if __name__ == "__main__":
    whole_steps(float(sys.argv[1]) if len(sys.argv) > 1 else 30.0)
    eyes_alone()
    physics_alone()
