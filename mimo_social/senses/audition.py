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

Where each mouth is, seen from each head, MuJoCo computes in C: one ``framepos`` sensor per
listener and source (:func:`add_hearing_sensors`: the source's ``mouth`` site in the listener's
``head_centre`` frame, the head sphere's frame), read as one block of ``sensordata``; the
acoustics follow once per control step (a shared system, :class:`AuditionSystem`), after the
physics: with up to :data:`SCALAR_PAIRS` listener-source pairs in one pass of Python floats,
with more in numpy over all pairs at once (on a few pairs numpy's cost per call outweighs its
speed per value: ``mimo-social bench development --hearing`` times both ways).
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from functools import partial

import mujoco
import numpy as np
from gymnasium import spaces

from ..expressions.voice import MAX_LEVEL_DB, SOUNDS
from ..util.checks import check_bool, check_number
from .base import SenseEntry
from .echoic import EchoicMemory
from .waveform import binaural_frames, frame_samples, peak

__all__ = ["AuditionConfig", "AuditionSystem", "Audition", "SENSE", "FEATURES",
           "SPEED_OF_SOUND", "MIN_DISTANCE", "MAX_HEAD_RADIUS", "woodworth_itd",
           "add_hearing_sensors", "sensor_name"]

#: the columns of a source's row after the kind one-hot
FEATURES = ("level_left", "level_right", "ild", "itd")
SPEED_OF_SOUND = 343.0     # m/s, air at 20 degrees C
_LR = np.array([-1.0, 1.0])   # per ear (left, right): the sign of 2 r y in the squared distance
_SILENT_DB = -1000.0       # a silent source's level: below every threshold
#: at most this many (listener, source) pairs are heard with Python floats, more with numpy
#: arrays: with few pairs numpy's cost per call outweighs its speed per value (docs/senses.md)
SCALAR_PAIRS = 48
MIN_DISTANCE = 0.05        # m: mouth-to-ear distances are held at this or more (our choice)
MAX_HEAD_RADIUS = 0.15     # m: larger than any head here (adult ~0.09): the ITD bound


@dataclass(frozen=True)
class AuditionConfig:
    """The hearing threshold, the head shadow, the binaural frame and the echoic memory."""

    threshold_db: float = 0.0      # dB SPL: a level at or below it is not heard (0)
    head_shadow_db: float = 8.0    # dB: ILD of the head shadow at 90 degrees (our choice)
    # a binaural pressure frame of the step too: "audition_waveform" (:mod:`.waveform`)
    waveform: bool = False
    # echoic memory (:mod:`.echoic`): "audition_memory", the loudest level heard from each source
    # in each bin of memory_bin_s over the last memory_s seconds (0: off)
    memory_s: float = 0.0
    # s: the width of one bin of the echoic memory (rounded to whole control steps, at least one)
    memory_bin_s: float = 0.1

    def __post_init__(self):
        put = partial(object.__setattr__, self)
        put("memory_s", check_number("audition", "memory_s", self.memory_s, 0.0, 10.0))
        put("memory_bin_s", check_number("audition", "memory_bin_s", self.memory_bin_s,
                                         0.001, 10.0))
        put("threshold_db", check_number("audition", "threshold_db", self.threshold_db,
                                         0.0, 120.0))
        put("head_shadow_db", check_number("audition", "head_shadow_db", self.head_shadow_db,
                                           0.0, 30.0))
        put("waveform", check_bool("audition", "waveform", self.waveform))


def woodworth_itd(radius, lateral):
    """Woodworth's ITD in seconds for a spherical head of ``radius`` (m) and a source at
    ``lateral`` (rad, its angle to the median plane; > 0 on the left: the left ear leads)."""
    return np.asarray(radius) / SPEED_OF_SOUND * (lateral + np.sin(lateral))


def sensor_name(listener: str, source: str) -> str:
    """The MuJoCo sensor of ``source``'s mouth in ``listener``'s head frame."""
    return f"hearing/{listener}/{source}"


def add_hearing_sensors(spec, names, configs) -> None:
    """One ``framepos`` sensor per listener (an agent with audition on) and source (an agent
    with voice on), listener-major, so that the whole block is one slice of ``sensordata``."""
    sources = [n for n, c in zip(names, configs) if c.voice]
    for listener, c in zip(names, configs):
        if c.audition is None:
            continue
        for source in sources:
            spec.add_sensor(name=sensor_name(listener, source),
                            type=mujoco.mjtSensor.mjSENS_FRAMEPOS,
                            objtype=mujoco.mjtObj.mjOBJ_SITE, objname=f"{source}/mouth",
                            reftype=mujoco.mjtObj.mjOBJ_SITE, refname=f"{listener}/head_centre")


def _sensor_block(model, names, listeners, sources) -> slice:
    """The ``sensordata`` slice of every (listener, source) sensor, listener-major."""
    adr = [int(model.sensor_adr[model.sensor(sensor_name(names[i], names[j])).id])
           for i in listeners for j in sources]
    start = adr[0] if adr else 0
    if adr != list(range(start, start + 3 * len(adr), 3)):
        raise RuntimeError(f"audition: the hearing sensors are not one block: {adr}")
    return slice(start, start + 3 * len(adr))


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
        # the listeners' constants, (l, 1, ...) against the (l, s, ...) pair arrays
        L = self.listeners
        self._shade = (0.5 * self.shadow[L])[:, None, None] * _LR[::-1]   # + left, - right
        self._thr = self.threshold[L][:, None, None]
        self._block = _sensor_block(world.model, world.names, L, self.sources)
        self._pairs = (len(L), len(self.sources), 3)
        self._source_list = self.sources.tolist()
        # the rows are written in place when every agent listens, else into a buffer first
        self._in_place = np.array_equal(L, np.arange(n))
        self._rows = self.features if self._in_place else np.zeros(
            (len(L), len(self.sources), self.width), np.float32)
        #: Python floats for at most SCALAR_PAIRS pairs, numpy arrays for more
        self.scalar = len(L) * len(self.sources) <= SCALAR_PAIRS
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
        self.level_max = float(level)
        # echoic memory of the listeners that have it on: listener row -> its memory
        dt = physics.timestep * physics.frame_skip
        self.memories = {}
        for row, i in enumerate(self.listeners):
            c = configs[i]
            if c.memory_s > 0:
                bin_steps = max(1, int(round(c.memory_bin_s / dt)))
                frames = int(np.ceil(c.memory_s / (bin_steps * dt) - 1e-9))
                self.memories[int(i)] = (row, EchoicMemory(len(self.sources), frames, bin_steps))
        self.reset(world.model, world.data)

    def connect(self, sounds: np.ndarray) -> None:
        """Hear the env's sounds: ``(n_agents, 2)`` kind id and level in dB SPL at 1 m, the
        env's own array (read at every update, never written)."""
        self.sounds = sounds

    def reset(self, model, data) -> None:
        """The head radii (they change only with an age change, at a reset), the echoic
        memories cleared, then hear."""
        for _, memory in self.memories.values():
            memory.reset()
        r = model.geom_size[self.heads[self.listeners], 0][:, None, None]    # (l, 1, 1)
        self._r2 = r[..., 0] ** 2                              # (l, 1)
        self._two_r = 2.0 * r * _LR                            # (l, 1, 2): the ears' -+ 2 r y
        self._itd_scale = (1000.0 / SPEED_OF_SOUND) * r[..., 0]   # ms per (theta + sin theta)
        # the same per listener as Python floats: r^2, 2 r, half the shadow, threshold, ITD scale
        self._listener_floats = list(zip(
            self._r2[:, 0].tolist(), (2.0 * r[:, 0, 0]).tolist(),
            self._shade[:, 0, 0].tolist(), self._thr[:, 0, 0].tolist(),
            self._itd_scale[:, 0].tolist()))
        self.update(model, data)

    def update(self, model, data) -> None:
        L, S = self.listeners, self.sources
        if not len(L) or not len(S):
            return
        kind = self.sounds[S, 0]
        if not kind.any():                     # every voice silent: nothing to hear
            self.features[L] = self._silence
            self.waves[L] = 0.0
            for _, memory in self.memories.values():
                memory.push(0.0)
            return
        # each mouth in each listener's head frame (MuJoCo's sensors, brought up to the poses
        # the senses read: mj_step computed them before its last integration), (l, s, 3)
        mujoco.mj_sensorPos(model, data)
        local = data.sensordata[self._block]
        rows = self._rows
        if self.scalar:
            self._hear_floats(local, rows)
        else:
            self._hear_arrays(local.reshape(self._pairs), kind, rows)
        if not self._in_place:
            self.features[L] = rows
        if self.memories:
            k = len(SOUNDS)
            loudest = np.maximum(rows[..., k], rows[..., k + 1])     # (l, s): the louder ear
            for row, memory in self.memories.values():
                memory.push(loudest[row])
        if self.wave:
            k = len(SOUNDS)
            self.waves[L] = binaural_frames(kind.astype(np.intp), rows[..., k:k + 2],
                                            rows[..., k + 3], float(data.time), self.n_samples)

    def _hear_arrays(self, local, kind, rows) -> None:
        """Every pair's row at once in numpy (many pairs); ``local`` (l, s, 3)."""
        y = local[..., 1]
        dist2 = (local * local).sum(-1)
        # the level at each ear, (l, s, 2): the squared distance to the ears at (0, +-r, 0) is
        # dist2 + r^2 -+ 2 r y; the source's level, spherical spreading, the head shadow
        level = y[..., None] * self._two_r
        level += (dist2 + self._r2)[..., None]
        np.maximum(level, MIN_DISTANCE ** 2, out=level)
        np.log10(level, out=level)
        level *= -10.0
        level += np.where(kind != 0, self.sounds[self.sources, 1], _SILENT_DB)[:, None]
        sin_lat = y / np.sqrt(dist2 + 1e-18)
        np.minimum(np.maximum(sin_lat, -1.0, out=sin_lat), 1.0, out=sin_lat)
        level += sin_lat[..., None] * self._shade
        level *= level > self._thr             # at or below the threshold: not heard (0)
        heard = level.any(-1)                  # (l, s); a silent source is never heard
        k = len(SOUNDS)
        rows[..., :k] = self._one_hot[np.where(heard, kind, 0).astype(np.intp)]
        rows[..., k:k + 2] = level
        np.subtract(level[..., 0], level[..., 1], out=rows[..., k + 2])
        itd = np.arcsin(sin_lat)
        itd += sin_lat
        itd *= self._itd_scale
        itd *= heard
        rows[..., k + 3] = itd

    def _hear_floats(self, local, rows) -> None:
        """Every pair's row with Python floats, the same formulas as :meth:`_hear_arrays` (few
        pairs: there numpy's cost per call outweighs its speed per value)."""
        k, width = len(SOUNDS), self.width
        loc = local.tolist()
        sounds = self.sounds.tolist()
        voices = [sounds[j] for j in self._source_list]
        values = [0.0] * (len(loc) // 3 * width)
        floor = MIN_DISTANCE ** 2
        p = 0
        for r2, two_r, shade, threshold, itd_scale in self._listener_floats:
            for kind, db in voices:
                base = p // 3 * width
                if kind:
                    x, y, z = loc[p], loc[p + 1], loc[p + 2]
                    dist2 = x * x + y * y + z * z
                    s = y / math.sqrt(dist2 + 1e-18)
                    s = 1.0 if s > 1.0 else (-1.0 if s < -1.0 else s)
                    near, side = dist2 + r2, two_r * y
                    left = db - 10.0 * math.log10(max(near - side, floor)) + s * shade
                    right = db - 10.0 * math.log10(max(near + side, floor)) - s * shade
                    left = left if left > threshold else 0.0
                    right = right if right > threshold else 0.0
                    if left or right:
                        values[base + int(kind)] = 1.0
                        values[base + k:base + k + 4] = (
                            left, right, left - right, (math.asin(s) + s) * itd_scale)
                        p += 3
                        continue
                values[base] = 1.0             # heard as silence
                p += 3
        rows.reshape(-1)[:] = values             # a view: rows are contiguous


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
        self.memory = system.memories.get(index, (0, None))[1]
        if self.memory is not None:
            self.spaces["audition_memory"] = spaces.Box(
                0.0, system.level_max, (self.memory.frames, len(system.sources)), np.float32)

    def observe(self, model, data, out: dict) -> None:
        out[self.name] = self.system.features[self.index].copy()
        if self.waveform:
            out["audition_waveform"] = self.system.waves[self.index].copy()
        if self.memory is not None:
            out["audition_memory"] = self.memory.read()


def build_audition(world, configs):
    system = AuditionSystem(world, configs)
    return system, [Audition(system, i, c) if c else None for i, c in enumerate(configs)]


SENSE = SenseEntry("audition", AuditionConfig, shared=build_audition,
                   add_to_spec=add_hearing_sensors)
