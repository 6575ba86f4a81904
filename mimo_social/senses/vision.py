"""Binocular vision (paper Sec. V): two eye cameras per agent, RGB images and optional depth.

Each eye body carries a camera (``right_eye`` / ``left_eye``, 60 degree vertical field of view,
looking along the eye's +x) that moves with the eye joints (+-45 deg horizontal, -47..33
vertical, +-8 torsional). ``field_of_view`` (degrees, vertical; 10 to 160) widens or narrows
both eyes of the agent (the cameras' ``cam_fovy`` in the compiled model, set when its vision is
built; a pickled copy keeps it): 60 degrees is a small part of an 18-month-old's field (kinetic
perimetry finds it near adult size around 17 months, Dobson et al. 1998, Vision Res. 38:2743),
and a partner's head above a toy on the floor is out of a 60-degree view that fixates the toy
(docs/training/issue30/pilots/joint_attention_head_turn). A wide perspective image spends its
pixels on the periphery; a ``fovea`` gives the centre back its detail. Observation keys per
agent with vision on:

* ``eye_left``, ``eye_right``: ``Box(0, 255, (height, width, 3), uint8)``, row 0 at the top;
* with ``depth=True`` also ``depth_left``, ``depth_right``: ``Box(0, inf, (height, width),
  float32)``, the distance in metres from the eye along its viewing axis (z-depth; nothing
  in view reads as the far clipping distance, ``model.vis.map.zfar * model.stat.extent``).

Visual development (``acuity``, :mod:`mimo_social.senses.acuity`): None (the default) leaves the
images as rendered; ``"age"`` blurs them to the grating acuity of the agent's age
(:attr:`AgentConfig.age`; none from 24 months on nor for adults); a number is a cut-off in cycles
per degree. The blur is applied right after rendering, before anything reads the images: the
observations, :func:`eye_images`, anaglyphs and recordings all see the blurred images (depth
images stay sharp). ``VisionSystem.cutoffs`` holds each agent's cut-off (None: no blur), and
:class:`AcuityBlur` is the identity where the cut-off is at or above the image's Nyquist
frequency (e.g. 18 months' 12.4 cycles per degree needs eyes 1640 pixels tall to act).

Foveated eyes (``fovea``, :mod:`mimo_social.senses.fovea`): None (the default) leaves the images
as rendered; a strength ``s`` (or ``{"strength": s, "render_scale": k}``) renders each eye ``k``
times larger, blurs it there (acuity, in degrees), then warps it to ``height`` x ``width`` with
the centre magnified ``s`` times and the whole field of view kept; depth images take the same
warp (nearest pixel). The observation spaces keep their shapes. ``VisionSystem.foveas`` holds
each agent's :class:`~mimo_social.senses.fovea.FovealWarp` (None: off).

One :class:`VisionSystem` per world renders every agent's eyes once per control step, after the
physics and before any agent observes, every ``every``-th step (``every=1``: every step; the
images of the steps between are the last ones rendered), and at once after a reset. All eyes
of all agents are tiles of one offscreen buffer of one GL context per process (see
:mod:`mimo_social.render.eye_renderer` for what makes it fast); the renderer is made lazily in
the process that steps the env and is dropped when the env is pickled, so vector envs in worker
processes work with the ``spawn`` / ``forkserver`` start methods (not ``fork`` after rendering).

What it costs: ``mimo-social bench vision`` (each variant of
:data:`mimo_social.bench.vision_cost.BENCH_VARIANTS` against the one before) and BENCHMARKS.md.

Helpers: :func:`vision_system` (the system of an env), :func:`eye_images` (an agent's current
images), :func:`render_now` (re-render after changing the state by hand, e.g. after
``env.world.set_expression`` or writing ``qpos`` and ``mj_forward``), :func:`anaglyph` and
:func:`save_anaglyph` (red-cyan anaglyph of an agent's two eye images, like Fig. 5a of the MIMo
paper).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from gymnasium import spaces

from ..render.eye_renderer import Tile, TileRenderer
from ..render.png import write_png
from ..util.checks import check_bool, check_int, check_number
from ..util.names import reject_old_names
from .acuity import acuity_blur, check_acuity, cutoff_for
from .base import SenseEntry
from .fovea import FoveaConfig, check_fovea, foveal_warp

__all__ = ["VisionConfig", "VisionSystem", "VisionSense", "build_vision", "vision_system",
           "eye_images", "render_now", "anaglyph", "save_anaglyph", "write_png", "render_scale",
           "EYES", "SENSE"]

EYES = ("left", "right")


def render_scale(config: "VisionConfig") -> int:
    """How many times the eye images are rendered larger than observed, per side: the fovea's
    render scale (the centre magnified from rendered detail), else 1."""
    return config.fovea.render_scale if config.fovea else 1


@dataclass(frozen=True)
class VisionConfig:
    """Two eye cameras (60 degree field of view, or ``field_of_view``) rendering RGB images,
    optionally depth."""

    width: int = 256        # pixels, each eye
    height: int = 256       # pixels, each eye
    depth: bool = False     # depth images too (metres), `depth_left` / `depth_right`
    every: int = 1          # render every k-th control step, holding the last images between
    acuity: float | str | None = None   # None | "age" | cut-off in cycles per degree
    # Foveated eyes: None (off), True (strength 4), a strength (the magnification at the
    # image centre, 1 to 16) or a mapping {"strength": ..., "render_scale": ...}; the eye is
    # rendered render_scale (1 to 8, default: the strength rounded up) times larger and warped
    # to width x height, centre magnified, the whole field of view kept (docs/senses.md)
    fovea: FoveaConfig | float | dict | None = None
    # The eyes' vertical field of view in degrees, 10 to 160 (None: the body's 60)
    field_of_view: float | None = None

    def __post_init__(self):
        for key in ("width", "height"):
            object.__setattr__(self, key, check_int("vision", key, getattr(self, key), 8, 2048))
        object.__setattr__(self, "depth", check_bool("vision", "depth", self.depth))
        object.__setattr__(self, "every", check_int("vision", "every", self.every, 1, 1000))
        object.__setattr__(self, "acuity", check_acuity(self.acuity))
        object.__setattr__(self, "fovea", check_fovea(self.fovea, self.width, self.height))
        if self.field_of_view is not None:
            object.__setattr__(self, "field_of_view", check_number(
                "vision", "field_of_view", self.field_of_view, 10.0, 160.0,
                "degrees, vertical; None: the body's 60"))


class VisionSystem:
    """Renders the eyes of every agent with vision, once per step (see module docstring)."""

    name = "vision"

    def __init__(self, world, configs: Sequence):
        self.configs = list(configs)
        self.agents = [i for i, c in enumerate(self.configs) if c]
        tiles, groups, self._tile_of = [], [], {}
        self.cameras, self.cutoffs, self.blurs, self.foveas = {}, {}, {}, {}
        for i in self.agents:
            cfg = self.configs[i]
            right, left = (int(c) for c in world.agents[i].eye_cameras)
            self.cameras[i] = {"left": left, "right": right}
            if cfg.field_of_view is not None:
                world.model.cam_fovy[[left, right]] = cfg.field_of_view
            self.foveas[i] = foveal_warp(cfg.fovea, cfg.height, cfg.width) if cfg.fovea else None
            self._set_blur(i, world.model, world.agent_setups[i].config.age)
            k = render_scale(cfg)
            group = []
            for eye in EYES:
                self._tile_of[i, eye] = len(tiles)
                group.append(len(tiles))
                tiles.append(Tile(cfg.width * k, cfg.height * k, cfg.depth))
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

    def set_age(self, model, i: int, age_months: float | None) -> None:
        """Agent ``i``'s acuity blur for the body age ``age_months`` (an age change at reset)."""
        self._set_blur(i, model, age_months)

    def _set_blur(self, i: int, model, age_months: float | None) -> None:
        # with a fovea the eye is rendered k times larger, blurred there (in degrees), warped
        cfg, k = self.configs[i], render_scale(self.configs[i])
        self.cutoffs[i] = cutoff_for(cfg.acuity, age_months)
        self.blurs[i] = acuity_blur(self.cutoffs[i], cfg.height * k, cfg.width * k,
                                    float(model.cam_fovy[self.cameras[i]["left"]]))

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
            imgs, blur, fovea = {}, self.blurs[i], self.foveas[i]
            for e in EYES:
                rgb, depth = result[self._tile_of[i, e]]
                rgb = rgb if blur is None else blur(rgb)
                imgs[f"eye_{e}"] = rgb if fovea is None else fovea.rgb(rgb)
                if depth is not None:
                    imgs[f"depth_{e}"] = depth if fovea is None else fovea.depth(depth)
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


SENSE = SenseEntry("vision", VisionConfig, shared=build_vision)


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
        reject_old_names(agent, base.possible_agents)
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
