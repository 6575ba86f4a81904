"""Binocular vision (paper Sec. V): two eye cameras per agent, RGB images and optional depth.

Each eye body carries a camera (``right_eye`` / ``left_eye``, 60 degree vertical field of view,
looking along the eye's +x) that moves with the eye joints (+-45 deg horizontal, -47..33
vertical, +-8 torsional). Observation keys per agent with vision on:

* ``eye_left``, ``eye_right``: ``Box(0, 255, (height, width, 3), uint8)``, row 0 at the top;
* with ``depth=True`` also ``depth_left``, ``depth_right``: ``Box(0, inf, (height, width),
  float32)``, the distance in metres from the eye along its viewing axis (z-depth; nothing
  in view reads as the far clipping distance, ``model.vis.map.zfar * model.stat.extent``).

One :class:`VisionSystem` per world renders every agent's eyes once per control step, after the
physics and before any agent observes, every ``every``-th step (``every=1``: every step; the
images of the steps between are the last ones rendered), and at once after a reset. All eyes
of all agents are tiles of one offscreen buffer of one GL context per process (see
:mod:`.eye_renderer` for what makes it fast); the renderer is made lazily in the process that
steps the env and is dropped when the env is pickled, so vector envs in worker processes work
with the ``spawn`` / ``forkserver`` start methods (not ``fork`` after rendering).

Speed (2 cores, Mesa llvmpipe software rendering; ``python -m mimo_social.senses.vision``
measures it, each variant of :data:`BENCH_VARIANTS` against the one before): one infant's two
64x64 eyes every control step cost ~0.05 real s per simulated s (~0.15 ms an image, against
~3.7 ms for a plain ``mujoco.Renderer`` per eye), two 256x256 eyes ~0.2 (~0.5 ms an image);
images with another infant in view cost ~3x more.

Helpers: :func:`vision_system` (the system of an env), :func:`eye_images` (an agent's current
images), :func:`render_now` (re-render after changing the state by hand, e.g. after
``env.world.set_expression`` or writing ``qpos`` and ``mj_forward``), :func:`anaglyph` and
:func:`save_anaglyph` (red-cyan anaglyph of an agent's two eye images, like Fig. 5a of the MIMo
paper).
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np
from gymnasium import spaces

from ..render.png import write_png
from ..render.eye_renderer import Tile, TileRenderer

__all__ = ["VisionSystem", "VisionSense", "build_vision", "vision_system", "eye_images",
           "render_now", "anaglyph", "save_anaglyph", "write_png", "EYES"]

EYES = ("left", "right")


class VisionSystem:
    """Renders the eyes of every agent with vision, once per step (see module docstring)."""

    name = "vision"

    def __init__(self, world, configs: Sequence):
        self.configs = list(configs)
        self.agents = [i for i, c in enumerate(self.configs) if c]
        tiles, groups, self._tile_of = [], [], {}
        self.cameras = {}
        for i in self.agents:
            cfg = self.configs[i]
            right, left = (int(c) for c in world.agents[i].eye_cameras)
            self.cameras[i] = {"left": left, "right": right}
            group = []
            for eye in EYES:
                self._tile_of[i, eye] = len(tiles)
                group.append(len(tiles))
                tiles.append(Tile(cfg.width, cfg.height, cfg.depth))
            groups.append(group)
        self._tiles, self._groups = tiles, groups
        self.renderer: TileRenderer | None = None
        self.images = {i: self._blank(i) for i in self.agents}
        self.fresh = {i: False for i in self.agents}   # images not yet handed out
        self.renders = {i: 0 for i in self.agents}     # how many times each agent's eyes rendered
        self._step = 0

    def _blank(self, i: int) -> dict:
        c = self.configs[i]
        out = {f"eye_{e}": np.zeros((c.height, c.width, 3), np.uint8) for e in EYES}
        if c.depth:
            out.update({f"depth_{e}": np.zeros((c.height, c.width), np.float32) for e in EYES})
        return out

    # -- shared-system interface ---------------------------------------------------------------
    def reset(self, model, data) -> None:
        self._step = 0      # the update that follows a reset renders every agent

    def update(self, model, data) -> None:
        due = [i for i in self.agents if self._step % self.configs[i].every == 0]
        self._step += 1
        if due:
            self.render(model, data, due)

    def render(self, model, data, agents: Sequence[int] | None = None) -> None:
        """Render the eyes of ``agents`` (default: all with vision) from the current state."""
        agents = self.agents if agents is None else [int(i) for i in agents]
        if self.renderer is None:
            self.renderer = TileRenderer(self._tiles, self._groups)
        jobs = [(self._tile_of[i, e], self.cameras[i][e]) for i in agents for e in EYES]
        result = self.renderer.render(model, data, jobs)
        for i in agents:
            imgs = {}
            for e in EYES:
                rgb, depth = result[self._tile_of[i, e]]
                imgs[f"eye_{e}"] = rgb
                if depth is not None:
                    imgs[f"depth_{e}"] = depth
            self.images[i] = imgs
            self.fresh[i] = True
            self.renders[i] += 1

    def observation(self, i: int) -> dict:
        """Agent ``i``'s images, never an array handed out before: with ``every=1`` the newly
        rendered arrays themselves (made for this step only), else copies (held images are
        handed out again on the following steps, and the caller may write into its own)."""
        if self.fresh[i] and self.configs[i].every == 1:
            self.fresh[i] = False
            return dict(self.images[i])
        self.fresh[i] = False
        return {k: v.copy() for k, v in self.images[i].items()}

    def close(self) -> None:
        if self.renderer is not None:
            self.renderer.close()
            self.renderer = None

    def __getstate__(self):
        state = self.__dict__.copy()
        state["renderer"] = None   # GL objects never travel; made again on first render
        return state


class VisionSense:
    """One agent's eyes: the observation keys and spaces, read from the :class:`VisionSystem`."""

    name = "vision"

    def __init__(self, system: VisionSystem, agent: int, config):
        self.system, self.agent, self.config = system, agent, config
        h, w = config.height, config.width
        self.spaces = {f"eye_{e}": spaces.Box(0, 255, (h, w, 3), np.uint8) for e in EYES}
        if config.depth:
            self.spaces.update({f"depth_{e}": spaces.Box(0.0, np.inf, (h, w), np.float32)
                                for e in EYES})

    def observe(self, model, data, out: dict) -> None:
        out.update(self.system.observation(self.agent))


def build_vision(world, configs: Sequence):
    """The world's :class:`VisionSystem` and one :class:`VisionSense` (or None) per agent."""
    system = VisionSystem(world, configs)
    return system, [VisionSense(system, i, c) if c else None for i, c in enumerate(configs)]


# -- helpers -------------------------------------------------------------------------------------
def vision_system(env) -> VisionSystem:
    """The :class:`VisionSystem` of an env of this package (wrappers are looked through)."""
    return getattr(env, "unwrapped", env).system("vision")


def _agent_index(env, agent) -> int:
    base = getattr(env, "unwrapped", env)
    if isinstance(agent, (int, np.integer)):
        return int(agent)
    try:
        return base.possible_agents.index(agent)
    except ValueError:
        raise KeyError(f"unknown agent {agent!r}; agents: {base.possible_agents}") from None


def render_now(env, agents: Sequence | None = None) -> None:
    """Re-render eyes from the env's current state (after changing it by hand)."""
    system = vision_system(env)
    base = getattr(env, "unwrapped", env)
    idx = None if agents is None else [_agent_index(env, a) for a in agents]
    system.render(base.world.model, base.world.data, idx)


def eye_images(env, agent) -> dict:
    """Agent ``agent``'s (index or name) current eye images (copies): keys ``eye_left``,
    ``eye_right`` and, with depth on, ``depth_left``, ``depth_right``."""
    system = vision_system(env)
    i = _agent_index(env, agent)
    if i not in system.images:
        raise ValueError(f"agent {agent!r} has no vision")
    if system.renders[i] == 0:
        render_now(env, [i])
    return {k: v.copy() for k, v in system.images[i].items()}


def anaglyph(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """Red-cyan anaglyph: red from the left eye, green and blue from the right eye (view with
    the red filter over the left eye)."""
    if left.shape != right.shape or left.ndim != 3 or left.shape[2] != 3:
        raise ValueError(f"need two RGB images of one shape, got {left.shape} and {right.shape}")
    out = right.copy()
    out[..., 0] = left[..., 0]
    return out


def save_anaglyph(env, agent, path, scale: int = 1) -> np.ndarray:
    """Save a red-cyan anaglyph of ``agent``'s (index or name) current eye images as PNG;
    ``scale`` > 1 enlarges it (nearest neighbour). Returns the anaglyph (before scaling)."""
    imgs = eye_images(env, agent)
    img = anaglyph(imgs["eye_left"], imgs["eye_right"])
    scale = int(scale)
    if scale < 1:
        raise ValueError(f"scale={scale}; a positive integer")
    big = img.repeat(scale, axis=0).repeat(scale, axis=1) if scale > 1 else img
    write_png(path, big)
    return img


# -- benchmark -----------------------------------------------------------------------------------
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


def _bench_states(n_agents: int, n_steps: int, seed: int = 0):
    """A world and ``n_steps`` of its qpos under gentle smooth random actions (standing)."""
    from ..core.random_actions import smooth_random_actions
    from ..envs import free_play_v0

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
    import time

    import mujoco

    from ..render.eye_renderer import TileRenderer, shared_gl_context

    out = []
    for n in agents:
        env, states = _bench_states(n, n_states)
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
    import ctypes

    def read_rgb():
        mujoco.mjr_readPixels(rgb, None, rect, r._con)

    def read_rgba():
        r._read(0, 0, 512, 256, 0x1908, 0x1401, rgba.ctypes.data_as(ctypes.c_void_p))

    for name, fn in (("readback_rgb_mjr_readPixels", read_rgb),
                     ("readback_rgba_glReadPixels", read_rgba)):
        fn()
        t0 = time.perf_counter()
        for _ in range(100):
            fn()
        out.append({"variant": name, "ms_per_2x256x256": 1e3 * (time.perf_counter() - t0) / 100})
    r.close()
    return out


def bench_env(configs=None, sim_seconds: float = 5.0, seed: int = 0) -> list[dict]:
    """Real seconds per simulated second of whole env steps (vision and total, from
    ``env.timing`` and the wall clock), the configurations taking turns of 100 steps."""
    import time

    from ..core.random_actions import smooth_random_actions
    from ..envs import free_play_v0

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
        acts = [smooth_random_actions(n_steps, env.action_space(a)["motors"].shape[0], seed + i)
                for i, a in enumerate(env.possible_agents)]
        for k in env.timing:
            env.timing[k] = 0.0
        runs[name] = {"env": env, "acts": acts, "k": 0, "n": n_steps, "wall": 0.0}
    while any(r["k"] < r["n"] for r in runs.values()):
        for r in runs.values():
            env, acts = r["env"], r["acts"]
            stop = min(r["n"], r["k"] + 100)
            t0 = time.perf_counter()
            for k in range(r["k"], stop):
                env.step({a: {"motors": acts[i][0][k], "expression": int(acts[i][1][k])}
                          for i, a in enumerate(env.possible_agents)})
            r["wall"] += time.perf_counter() - t0
            r["k"] = stop
    out = []
    for name, r in runs.items():
        env, sim = r["env"], r["n"] * r["env"].dt
        out.append({"config": name, "sim_s": sim, "vision": env.timing["vision"] / sim,
                    "total": r["wall"] / sim,
                    **{k: v / sim for k, v in env.timing.items() if k != "vision"}})
    return out


def _bench_main(argv=None) -> None:
    import argparse
    import json
    import os
    import subprocess
    import sys

    p = argparse.ArgumentParser(
        prog="python -m mimo_social.senses.vision",
        description="Vision benchmark: ms per eye image by variant, and real s per simulated s "
                    "of whole env steps; each backend in its own process.")
    p.add_argument("--backends", default="egl,osmesa", help="MUJOCO_GL values to compare")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--sim-seconds", type=float, default=5.0)
    p.add_argument("--json", default=None, help="write all results here")
    p.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.worker:
        res = {"images": bench_images(rounds=args.rounds),
               "env": bench_env(sim_seconds=args.sim_seconds)}
        print("JSON" + json.dumps(res))
        return
    results = {}
    for backend in args.backends.split(","):
        envvars = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
        proc = subprocess.run([sys.executable, "-m", "mimo_social.senses.vision", "--worker",
                               "--rounds", str(args.rounds), "--sim-seconds",
                               str(args.sim_seconds)], env=envvars, capture_output=True,
                              text=True)
        line = [ln for ln in proc.stdout.splitlines() if ln.startswith("JSON")]
        if proc.returncode or not line:
            print(f"{backend}: failed\n{proc.stderr[-2000:]}")
            continue
        results[backend] = json.loads(line[0][4:])
    print("ms per eye image (median over rounds; render + read-back):")
    print("| variant | " + " | ".join(f"{b} {n} inf. {s}px" for b in results
                                      for n in (1, 2) for s in (64, 256)) + " |")
    for v in BENCH_VARIANTS:
        cells = []
        for b, res in results.items():
            for n in (1, 2):
                for s in (64, 256):
                    x = [r for r in res["images"] if r.get("agents") == n
                         and r.get("size") == s and r["variant"] == v]
                    cells.append(f"{x[0]['ms_per_image']:.3f}" if x else "-")
        print(f"| {v} | " + " | ".join(cells) + " |")
    for b, res in results.items():
        extra = [r for r in res["images"] if "size" not in r]
        parts = []
        for r in extra:
            who = f" ({r['agents']} inf.)" if "agents" in r else ""
            ms = r.get("ms_per_image", r.get("ms_per_2x256x256"))
            parts.append(f"{r['variant']}{who}: {ms:.3f} ms")
        print(b, "; ".join(parts))
    print("\nreal s per simulated s (whole env steps):")
    for b, res in results.items():
        for r in res["env"]:
            print(f"{b} | {r['config']} | vision {r['vision']:.4f} | total {r['total']:.4f} | "
                  f"physics {r['physics']:.4f} | touch {r.get('touch', 0):.4f}")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    _bench_main()
