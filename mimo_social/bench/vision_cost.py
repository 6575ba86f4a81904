"""What the eyes cost: milliseconds per eye image for each step of the renderer's design
(:data:`BENCH_VARIANTS`), and real seconds per simulated second of whole env steps with vision.

``mimo-social bench vision`` runs it once per OpenGL backend, each in its own process
(:mod:`mimo_social.cli.bench_vision`); the numbers go to BENCHMARKS.md.
"""

from __future__ import annotations

import ctypes
import json
import math
import os
import subprocess
import sys
import time

import mujoco
import numpy as np

from ..core.random_actions import smooth_random_actions
from ..envs import free_play_v0
from ..render.eye_renderer import Tile, TileRenderer, shared_gl_context

__all__ = ["BENCH_VARIANTS", "bench_states", "bench_images", "bench_env", "measure",
           "measure_backend", "format_results", "FOVEA_CONFIGS", "bench_fovea", "format_fovea"]

#: Per-image variants, each adding one change to the one before (``final`` is what the env uses).
BENCH_VARIANTS = {
    "naive": "one mujoco.Renderer per image size, update_scene + render per eye (model defaults: "
             "4x MSAA, tessellation 28/16, floor grid 0.1 m, RGB read-back per image)",
    "tiles": "one GL context, one MjrContext, eyes as tiles of one buffer sized to them, no MSAA, "
             "no shadows/reflections/skybox/haze, one RGBA read-back per step",
    "floor": "+ floor plane as one quad instead of a 0.1 m grid",
    "tess": "+ coarse capsule/sphere tessellation (slices/stacks 12/6 up to 128 px, 16/8 up "
            "to 320 px, 20/10 up to 640 px)",
    "cull": "+ frustum culling of geoms outside each eye's view",
    "final": "+ both eyes of an agent in one side-by-side stereo mjr_render",
    "final_notex": "final with the face textures off (the cost of the 7 cube textures)",
}


def bench_states(n_agents: int, n_steps: int, seed: int = 0):
    """A world and ``n_steps`` of its qpos under gentle smooth random actions (standing)."""
    env = free_play_v0.parallel_env(n_agents=n_agents)
    env.reset(seed=seed)
    n_motors = env.action_space(env.agents[0])["motors"].shape[0]
    motors = [0.3 * smooth_random_actions(n_steps, n_motors, seed + i)[0] for i in range(n_agents)]
    states = []
    for k in range(n_steps):
        env.step({a: {"motors": motors[i][k], "expression": 0} for i, a in enumerate(env.agents)})
        states.append(env.world.data.qpos.copy())
    return env, states


def bench_images(sizes=(64, 256), agents=(1, 2), rounds: int = 5, n_states: int = 30,
                 variants=tuple(BENCH_VARIANTS)) -> list[dict]:
    """Milliseconds per eye image (render + read-back, two eyes per infant), per variant of
    :data:`BENCH_VARIANTS`; the variants take turns (``rounds`` turns over ``n_states`` states
    each) so a change of the machine's speed touches them alike. Also times ``mjv_updateScene``
    per eye and the read-back of one 2x256x256 buffer as RGB (``mjr_readPixels``) and RGBA."""
    out = []
    for n in agents:
        env, states = bench_states(n, n_states)
        m, d = env.world.model, env.world.data
        cams = [int(c) for a in env.world.agents for c in a.eye_cameras]
        heads = [a.head_material for a in env.world.agents]
        for size in sizes:
            tiles = [Tile(size, size) for _ in cams]
            groups = [[2 * i, 2 * i + 1] for i in range(n)]
            jobs = list(enumerate(cams))
            renderers, naive = {}, None
            for v in variants:
                if v == "naive":
                    naive = mujoco.Renderer(m, size, size)
                    continue
                kw = {"tiles": dict(tessellation=(28, 16), floor_quads=False, cull=False,
                                    stereo=False),
                      "floor": dict(tessellation=(28, 16), cull=False, stereo=False),
                      "tess": dict(cull=False, stereo=False),
                      "cull": dict(stereo=False)}.get(v, {})
                renderers[v] = TileRenderer(tiles, groups, **kw)
            d.qpos[:] = states[0]
            mujoco.mj_forward(m, d)
            for _ in range(3):  # warm up: llvmpipe compiles its shaders on first use
                if naive is not None:
                    naive.update_scene(d, cams[0])
                    naive.render()
                for r in renderers.values():
                    r.render(m, d, jobs)
            times = {v: [] for v in variants}
            cpu = {v: [] for v in variants}
            texid = m.mat_texid.copy()
            for _ in range(rounds):
                for v in variants:
                    if v == "final_notex":
                        m.mat_texid[heads] = -1
                    t, c = 0.0, time.process_time()
                    for q in states:
                        d.qpos[:] = q
                        mujoco.mj_kinematics(m, d)
                        mujoco.mj_camlight(m, d)
                        t0 = time.perf_counter()
                        if v == "naive":
                            for cam in cams:
                                naive.update_scene(d, cam)
                                naive.render()
                        else:
                            renderers[v].render(m, d, jobs)
                        t += time.perf_counter() - t0
                    m.mat_texid[:] = texid
                    k = len(states) * len(cams)
                    times[v].append(1e3 * t / k)
                    cpu[v].append(1e3 * (time.process_time() - c) / k)
            if naive is not None:
                naive.close()
            for r in renderers.values():
                r.close()
            for v in variants:
                out.append({"agents": n, "size": size, "variant": v,
                            "ms_per_image": float(np.median(times[v])),
                            "ms_per_image_min": float(np.min(times[v])),
                            "cpu_ms_per_image": float(np.median(cpu[v]))})
        # scene update alone, per eye
        scn, opt, cam = mujoco.MjvScene(m, m.ngeom + 200), mujoco.MjvOption(), mujoco.MjvCamera()
        cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
        t0 = time.perf_counter()
        for q in states:
            for c in cams:
                cam.fixedcamid = c
                mujoco.mjv_updateScene(m, d, opt, None, cam, mujoco.mjtCatBit.mjCAT_ALL, scn)
        out.append({"agents": n, "variant": "mjv_updateScene",
                    "ms_per_image": 1e3 * (time.perf_counter() - t0) / (len(states) * len(cams))})
    # read-back alone: one 512x256 buffer
    r = TileRenderer([Tile(256, 256), Tile(256, 256)], [[0, 1]])
    r.render(m, d, [(0, cams[0]), (1, cams[1])])
    shared_gl_context()
    rect = mujoco.MjrRect(0, 0, 512, 256)
    rgb, rgba = np.empty((256, 512, 3), np.uint8), np.empty((256, 512, 4), np.uint8)

    def read_rgb():
        mujoco.mjr_readPixels(rgb, None, rect, r.render_context)

    def read_rgba():
        r.read_pixels(0, 0, 512, 256, 0x1908, 0x1401, rgba.ctypes.data_as(ctypes.c_void_p))

    for name, fn in (("readback_rgb_mjr_readPixels", read_rgb),
                     ("readback_rgba_glReadPixels", read_rgba)):
        fn()
        t0 = time.perf_counter()
        for _ in range(100):
            fn()
        out.append({"variant": name, "ms_per_2x256x256": 1e3 * (time.perf_counter() - t0) / 100})
    r.close()
    return out


#: steps each configuration of :func:`bench_env` makes, untimed, before its timed ones (the
#: first steps pay one-off costs: the first render compiles llvmpipe's shaders, caches fill)
WARMUP_STEPS = 100
#: steps of one turn of :func:`bench_env`
TURN_STEPS = 100


def bench_env(configs=None, sim_seconds: float = 5.0, seed: int = 0,
              warmup_steps: int = WARMUP_STEPS) -> list[dict]:
    """Real seconds per simulated second of whole env steps (vision and total, from
    ``env.timing`` and the wall clock), the configurations taking turns of
    :data:`TURN_STEPS` steps after ``warmup_steps`` untimed steps each; ``turn_s``: the wall
    seconds of each turn (for the noise of a comparison, turn by turn)."""
    configs = configs or {
        "1 infant, 2 x 64x64": dict(n_agents=1, vision={"width": 64, "height": 64}),
        "1 infant, 2 x 256x256": dict(n_agents=1, vision={"width": 256, "height": 256}),
        "2 infants, 2 x 64x64 each, all senses": dict(
            n_agents=2, vision={"width": 64, "height": 64}, touch=True),
    }
    runs = {}
    for name, kw in configs.items():
        env = free_play_v0.parallel_env(max_steps=10 ** 9, **kw)
        env.reset(seed=seed)
        n_steps = int(round(sim_seconds / env.dt))
        acts = [smooth_random_actions(warmup_steps + n_steps,
                                      env.action_space(a)["motors"].shape[0], seed + i)
                for i, a in enumerate(env.possible_agents)]
        runs[name] = {"env": env, "acts": acts, "k": 0, "n": n_steps, "wall": 0.0,
                      "turns": []}

    def step(r, k):
        r["env"].step({a: {"motors": r["acts"][i][0][k], "expression": int(r["acts"][i][1][k])}
                       for i, a in enumerate(r["env"].possible_agents)})

    for r in runs.values():                  # untimed: the one-off costs of the first steps
        for k in range(warmup_steps):
            step(r, k)
        for key in r["env"].timing:
            r["env"].timing[key] = 0.0
    while any(r["k"] < r["n"] for r in runs.values()):
        for r in runs.values():
            stop = min(r["n"], r["k"] + TURN_STEPS)
            t0 = time.perf_counter()
            for k in range(r["k"], stop):
                step(r, warmup_steps + k)
            r["turns"].append(time.perf_counter() - t0)
            r["wall"] += r["turns"][-1]
            r["k"] = stop
    out = []
    for name, r in runs.items():
        env, sim = r["env"], r["n"] * r["env"].dt
        out.append({"config": name, "sim_s": sim, "vision": env.timing["vision"] / sim,
                    "total": r["wall"] / sim, "turn_s": r["turns"],
                    **{k: v / sim for k, v in env.timing.items() if k != "vision"}})
        env.close()
    return out


def measure(rounds: int = 5, sim_seconds: float = 5.0) -> dict:
    """Both benchmarks in this process (with the OpenGL backend it has)."""
    return {"images": bench_images(rounds=rounds), "env": bench_env(sim_seconds=sim_seconds)}


def measure_backend(backend: str, rounds: int = 5, sim_seconds: float = 5.0) -> dict:
    """:func:`measure` in a new process with ``MUJOCO_GL=backend``; raises a RuntimeError
    with the end of its error output when it fails."""
    env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
    code = ("import json; from mimo_social.bench.vision_cost import measure; "
            f"print('JSON' + json.dumps(measure({int(rounds)}, {float(sim_seconds)!r})))")
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    line = [ln for ln in proc.stdout.splitlines() if ln.startswith("JSON")]
    if proc.returncode or not line:
        raise RuntimeError(f"{backend}: failed\n{proc.stderr[-2000:]}")
    return json.loads(line[0][4:])


def format_results(results: dict) -> str:
    """The results of :func:`measure` per backend as tables (markdown) and lines."""
    lines = ["ms per eye image (median over rounds; render + read-back):",
             "| variant | " + " | ".join(f"{b} {n} inf. {s}px" for b in results
                                        for n in (1, 2) for s in (64, 256)) + " |"]
    for v in BENCH_VARIANTS:
        cells = []
        for res in results.values():
            for n in (1, 2):
                for s in (64, 256):
                    x = [r for r in res["images"] if r.get("agents") == n
                         and r.get("size") == s and r["variant"] == v]
                    cells.append(f"{x[0]['ms_per_image']:.3f}" if x else "-")
        lines.append(f"| {v} | " + " | ".join(cells) + " |")
    for b, res in results.items():
        parts = []
        for r in res["images"]:
            if "size" in r:
                continue
            who = f" ({r['agents']} inf.)" if "agents" in r else ""
            ms = r.get("ms_per_image", r.get("ms_per_2x256x256"))
            parts.append(f"{r['variant']}{who}: {ms:.3f} ms")
        lines.append(b + " " + "; ".join(parts))
    lines.append("\nreal s per simulated s (whole env steps):")
    for b, res in results.items():
        for r in res["env"]:
            lines.append(f"{b} | {r['config']} | vision {r['vision']:.4f} | total "
                         f"{r['total']:.4f} | physics {r['physics']:.4f} | touch "
                         f"{r.get('touch', 0):.4f}")
    return "\n".join(lines)


#: :func:`bench_fovea`'s configurations: one infant, eyes of each size, fovea off and on
FOVEA_CONFIGS = {f"{size}x{size}, fovea {name}": dict(
    n_agents=1, vision={"width": size, "height": size, "fovea": fovea})
    for size in (64, 128) for name, fovea in (("off", None), ("2", 2), ("4", 4))}


def bench_fovea(sim_seconds: float = 5.0, seed: int = 0) -> list[dict]:
    """What a fovea costs: :func:`bench_env` over :data:`FOVEA_CONFIGS` (taking turns), with
    milliseconds per control step of the vision system and of the whole step."""
    env = free_play_v0.parallel_env(n_agents=1)
    dt = env.dt
    env.close()
    out = bench_env(FOVEA_CONFIGS, sim_seconds=sim_seconds, seed=seed)
    for r in out:        # seconds per simulated second -> milliseconds per control step
        r["vision_ms_per_step"] = 1e3 * r["vision"] * dt
        r["total_ms_per_step"] = 1e3 * r["total"] * dt
    return out


def format_fovea(results: list[dict]) -> str:
    """:func:`bench_fovea`'s results as a markdown table."""
    lines = ["| eyes (1 infant, 2 eyes) | fovea (strength; rendered side) | vision ms / step | "
             "step ms | real s / simulated s |", "|---|---|---|---|---|"]
    for r in results:
        size, fovea = FOVEA_CONFIGS[r["config"]]["vision"]["width"], \
            FOVEA_CONFIGS[r["config"]]["vision"]["fovea"]
        what = "off" if fovea is None else f"{fovea:g}; {size * math.ceil(fovea)} px"
        lines.append(f"| {size}x{size} | {what} | {r['vision_ms_per_step']:.2f} | "
                     f"{r['total_ms_per_step']:.2f} | {r['total']:.3f} |")
    return "\n".join(lines)
