"""Hearing: two ears per agent, hearing every agent that has a voice (``AgentConfig.voice``).

Turn it on with ``audition=True`` or a mapping of :class:`AuditionConfig` settings. The sounds
are those of the agents' ``"voice"`` actions this control step (``env.sounds``: kind and level
in dB SPL at 1 m, :mod:`mimo_social.expressions.voice`).

Geometry (from the compiled model, every step)
    Each agent's head is its head sphere (the ``head`` geom: centre, radius ``r``, frame; x
    forward through the face, y to the agent's left, z up); adults too. Its ears are at
    ``centre +- r y`` (left: +y). A source is the speaker's mouth, on the face's front at
    ``centre + r x``.

Features, per listener and source (one row per source)
    ``kind one-hot`` (``len(SOUNDS)``), ``level_left``, ``level_right`` (dB SPL), ``ild``
    (dB, left minus right), ``itd`` (ms, the right ear's arrival time minus the left's: > 0
    for a source on the left).

    * level at an ear: the source level minus ``20 log10(d / 1 m)`` (free field, spherical
      spreading: -6.02 dB per doubling of distance), ``d`` the mouth-to-ear distance held at
      :data:`MIN_DISTANCE` or more (closer, the free-field law does not hold), plus the head
      shadow ``+- head_shadow_db / 2 * sin(lateral angle)`` (the near ear gains, the far ear
      loses: ``head_shadow_db`` of interaural level difference for a source at 90 degrees; 8 dB
      by default, our choice of a broadband figure within the few dB at low and 10-20 dB at
      high frequencies measured on human heads, Feddersen et al. 1957, J Acoust Soc Am
      29:988-991);
    * a level at or below ``threshold_db`` (the hearing threshold, 0 dB SPL by default) is not
      heard: 0. A source heard by neither ear (silence, a voice-off agent, too far) is a row of
      silence: one-hot on ``silence``, levels, ILD and ITD 0;
    * ITD: Woodworth's spherical-head formula ``(r / c) (theta + sin theta)`` (Woodworth 1938,
      *Experimental Psychology*, Holt), ``theta`` the lateral angle of the source (its angle to
      the head's median plane, from the source direction in the head frame: 0 in front, behind,
      above; +90 degrees on the left), ``c`` = 343 m/s; 0.66 ms at 90 degrees for an adult head
      of 8.75 cm.

    The speaker hears itself: its mouth is in its median plane, so ILD and ITD are 0 and the
    level is its own at ``r sqrt(2)``.

Observation ``"audition"``: float32 ``(n_sources, len(SOUNDS) + 4)``, the sources in agent index
order (``env.possible_agents`` order, only the agents with voice on); absent when no agent has a
voice. Bounds: one-hot [0, 1]; levels [0, the loudest level of the voice table at
:data:`MIN_DISTANCE` plus half the head shadow]; ILD +- that; ITD +- Woodworth's at 90 degrees
for a head of :data:`MAX_HEAD_RADIUS` (or the largest head of the world, if larger).

All listeners and sources are computed at once in numpy, once per control step (a shared
system, :class:`AuditionSystem`), after the physics, from the head frames.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np
from gymnasium import spaces

from ..expressions.voice import MAX_LEVEL_DB, SOUNDS
from ..util.checks import check_bool, check_number
from .base import SenseEntry
from .waveform import binaural_frames, frame_samples, peak

__all__ = ["AuditionConfig", "AuditionSystem", "Audition", "SENSE", "FEATURES",
           "SPEED_OF_SOUND", "MIN_DISTANCE", "MAX_HEAD_RADIUS", "woodworth_itd"]

#: the columns of a source's row after the kind one-hot
FEATURES = ("level_left", "level_right", "ild", "itd")
SPEED_OF_SOUND = 343.0     # m/s, air at 20 degrees C
_LR = np.array([-1.0, 1.0])   # per ear (left, right): the sign of 2 r y in the squared distance
MIN_DISTANCE = 0.05        # m: mouth-to-ear distances are held at this or more (our choice)
MAX_HEAD_RADIUS = 0.15     # m: larger than any head here (adult ~0.09): the ITD bound


@dataclass(frozen=True)
class AuditionConfig:
    """The hearing threshold and the head shadow."""

    threshold_db: float = 0.0      # dB SPL: a level at or below it is not heard (0)
    head_shadow_db: float = 8.0    # dB: ILD of the head shadow at 90 degrees (our choice)
    # a binaural pressure frame of the step too: "audition_waveform" (:mod:`.waveform`)
    waveform: bool = False

    def __post_init__(self):
        put = partial(object.__setattr__, self)
        put("threshold_db", check_number("audition", "threshold_db", self.threshold_db,
                                         0.0, 120.0))
        put("head_shadow_db", check_number("audition", "head_shadow_db", self.head_shadow_db,
                                           0.0, 30.0))
        put("waveform", check_bool("audition", "waveform", self.waveform))


def woodworth_itd(radius, lateral):
    """Woodworth's ITD in seconds for a spherical head of ``radius`` (m) and a source at
    ``lateral`` (rad, its angle to the median plane; > 0 on the left: the left ear leads)."""
    return np.asarray(radius) / SPEED_OF_SOUND * (lateral + np.sin(lateral))


class AuditionSystem:
    """Every agent's ears, hearing every voiced agent: one computation per control step."""

    name = "audition"

    def __init__(self, world, configs):
        n = len(world.agents)
        self.listeners = np.array([i for i, c in enumerate(configs) if c], np.intp)
        self.sources = np.array([i for i in range(n)
                                 if getattr(world.agent_setups[i].config, "voice", False)],
                                np.intp)
        self.heads = np.array([a.head_geom for a in world.agents], np.intp)
        cfgs = [c or AuditionConfig() for c in configs]
        self.threshold = np.array([c.threshold_db for c in cfgs])
        self.shadow = np.array([c.head_shadow_db for c in cfgs])
        self.width = len(SOUNDS) + len(FEATURES)
        self.features = np.zeros((n, len(self.sources), self.width), np.float32)
        self._silence = np.zeros((len(self.listeners), len(self.sources), self.width),
                                 np.float32)
        self._silence[..., 0] = 1.0            # every source heard as silence
        everyone = np.arange(n)
        self._s_index = (slice(None) if np.array_equal(self.sources, everyone)
                         else self.sources)
        self._l_index = (slice(None) if np.array_equal(self.listeners, everyone)
                         else self.listeners)
        # per agent (n, ...): the head-shadow term per ear (+ left, - right), the threshold
        self._shade = (0.5 * self.shadow)[:, None, None] * _LR[::-1]
        self._thr = self.threshold[:, None, None][self._l_index]
        self._one_hot = np.eye(len(SOUNDS), dtype=np.float32)
        self.sounds = np.zeros((n, 2))   # the env's (kind, dB at 1 m) per agent: connect()
        radius = max(MAX_HEAD_RADIUS, float(world.model.geom_size[self.heads, 0].max()))
        level = MAX_LEVEL_DB - 20.0 * np.log10(MIN_DISTANCE) + max(self.shadow) / 2.0
        itd = 1000.0 * float(woodworth_itd(radius, np.pi / 2))
        low = np.zeros(self.width, np.float32)
        high = np.ones(self.width, np.float32)
        k = len(SOUNDS)
        high[k:k + 3] = level
        low[k + 2], low[k + 3], high[k + 3] = -level, -itd, itd
        shape = (len(self.sources), self.width)
        self.space = spaces.Box(np.broadcast_to(low, shape).copy(),
                                np.broadcast_to(high, shape).copy(), dtype=np.float32)
        # the binaural frames (waveform=True): one control step of samples per ear
        self.wave = any(c.waveform for c in configs if c) and len(self.sources) > 0
        physics = world.physics
        self.n_samples = frame_samples(physics.timestep * physics.frame_skip)
        self.waves = np.zeros((n, 2, self.n_samples if self.wave else 0), np.float32)
        p = peak(len(self.sources), float(level))
        self.wave_space = spaces.Box(-p, p, (2, self.n_samples), np.float32)
        self.reset(world.model, world.data)

    def connect(self, sounds: np.ndarray) -> None:
        """Hear the env's sounds: ``(n_agents, 2)`` kind id and level in dB SPL at 1 m, the
        env's own array (read at every update, never written)."""
        self.sounds = sounds

    def reset(self, model, data) -> None:
        """The head radii (they change only with an age change, at a reset), then hear."""
        r = model.geom_size[self.heads, 0]
        self._radius = r[:, None]                              # (n, 1)
        self._r2 = (r * r)[:, None]
        self._two_r = 2.0 * self._radius
        self._itd_scale = (1000.0 / SPEED_OF_SOUND) * self._radius   # ms per (theta + sin)
        self.update(model, data)

    def update(self, model, data) -> None:
        L, S = self.listeners, self.sources
        out = self.features
        if not len(L) or not len(S):
            return
        sounds = self.sounds
        kind = sounds[S, 0].astype(np.intp)
        if not kind.any():                     # every voice silent: nothing to hear
            out[L] = self._silence
            self.waves[L] = 0.0
            return
        heads, Sx, Lx = self.heads, self._s_index, self._l_index   # slices when all agents
        centre = data.geom_xpos[heads]                         # (n, 3)
        frame = data.geom_xmat[heads].reshape(-1, 3, 3)        # columns: x, y, z axes
        mouth = centre[Sx] + frame[Sx, :, 0] * self._radius[Sx]   # on the face (+x)
        # each mouth in each listener's head frame, (l, s, 3); y: towards the left ear
        local = np.matmul(mouth[None] - centre[Lx][:, None], frame[Lx])
        y = local[..., 1]
        dist2 = (local * local).sum(-1)
        # squared distances to the ears at (0, +-r, 0): dist2 + r^2 -+ 2 r y
        d2 = (dist2 + self._r2[Lx])[..., None] + (y * self._two_r[Lx])[..., None] * _LR
        sin_lat = y / np.sqrt(dist2 + 1e-18)
        np.minimum(np.maximum(sin_lat, -1.0, out=sin_lat), 1.0, out=sin_lat)
        feat = np.empty(d2.shape[:2] + (len(FEATURES),))
        level = feat[..., :2]
        np.log10(np.maximum(d2, MIN_DISTANCE ** 2), out=level)
        level *= -10.0
        level += sounds[S, 1][None, :, None] + sin_lat[..., None] * self._shade[Lx]
        level[level <= self._thr] = 0.0
        heard = (level.max(-1) > 0.0) & (kind != 0)           # (l, s)
        level *= heard[..., None]
        np.subtract(level[..., 0], level[..., 1], out=feat[..., 2])
        np.multiply(np.arcsin(sin_lat) + sin_lat, self._itd_scale[Lx] * heard,
                    out=feat[..., 3])
        k = len(SOUNDS)
        rows = out if isinstance(Lx, slice) else np.empty((len(L),) + out.shape[1:], out.dtype)
        rows[..., :k] = self._one_hot[np.where(heard, kind, 0)]
        rows[..., k:] = feat
        if rows is not out:
            out[L] = rows
        if self.wave:
            self.waves[L] = binaural_frames(kind, level, feat[..., 3], float(data.time),
                                            self.n_samples)


class Audition:
    """One agent's ears: its rows of the system's features."""

    name = "audition"

    def __init__(self, system: AuditionSystem, index: int, config: AuditionConfig):
        self.system, self.index = system, index
        space = system.space   # a Box of its own per agent
        self.spaces = {self.name: spaces.Box(space.low.copy(), space.high.copy(),
                                             dtype=np.float32)}
        self.waveform = bool(config.waveform and system.wave)
        if self.waveform:
            w = system.wave_space
            self.spaces["audition_waveform"] = spaces.Box(w.low.copy(), w.high.copy(),
                                                          dtype=np.float32)

    def observe(self, model, data, out: dict) -> None:
        out[self.name] = self.system.features[self.index].copy()
        if self.waveform:
            out["audition_waveform"] = self.system.waves[self.index].copy()


def build_audition(world, configs):
    system = AuditionSystem(world, configs)
    return system, [Audition(system, i, c) if c else None for i, c in enumerate(configs)]


SENSE = SenseEntry("audition", AuditionConfig, shared=build_audition)
