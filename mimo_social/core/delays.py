"""Sensorimotor delays of an agent in whole control steps, and the buffers that delay them.

**Units**: a delay of ``ms`` milliseconds is ``k = round(ms / (1000 * dt))`` control steps (halves
round up), ``dt = timestep * frame_skip`` (10 ms by default); a delay below half a step is 0.

**Rule**: the observation of a delayed sense at control step ``t`` is what the sense read at step
``t - k``; before ``k`` steps have passed it is the reading at reset (handed out as copies, so no
array is handed out twice). The controls applied at step ``t`` are those the agent gave at
``t - k``; before, the controls in force at reset (zeros, unless the task set some at reset).

* Senses that are not MuJoCo sensors (proprioception, touch, vision): :class:`SenseDelay`, a ring
  of ``k + 1`` slots holding the dicts of fresh arrays the sense produced (no copy per step).
* Vestibular (MuJoCo's gyro and accelerometer): MuJoCo's own sensor delay
  (:func:`delay_sensors` at build time, :func:`fill_sensor_history` at reset). The delay is set
  to ``k * dt - timestep / 2`` with zero-order hold: the sample read is the last one at or before
  half a physics step after the wanted one, so the time's float rounding never picks a
  neighbour (``k * dt`` exactly does, now and then).
* Motor: :class:`MotorDelay`, a ``(k + 1, n)`` ring of clipped controls.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ..senses.delays import CHANNELS, developmental_delays
from ..util.checks import ConfigError
from .config import DELAY_CHANNELS, DELAY_LIMIT_MS

__all__ = ["delays_ms", "delay_steps", "check_delay_steps", "MAX_DELAY_STEPS", "SenseDelay",
           "MotorDelay", "delay_sensors", "fill_sensor_history", "VESTIBULAR_SENSORS"]


#: the agent's MuJoCo sensors of the vestibular sense (unprefixed names)
VESTIBULAR_SENSORS = ("vestibular_gyro", "vestibular_accel")

#: the most control steps one delay may span. A delayed sense keeps ``k + 1`` readings per agent
#: (a pair of 256x256 eyes: 0.39 MB a reading), MuJoCo ``k * frame_skip + 2`` vestibular samples,
#: so the buffers grow with delay / control step: this bounds them whatever the control step.
#: 1000 steps hold the longest delay allowed (``DELAY_LIMIT_MS``, 1 s: about four times the
#: longest published latency, a newborn's visual 260 ms, ``senses/data/delays.csv``) down to a
#: 1 ms control step, and that latency down to 0.26 ms; at the default 10 ms step 1 s is 100
#: steps. A longer delay is no sensory delay (a reaction, the policy's business).
MAX_DELAY_STEPS = 1000


def delays_ms(config) -> dict[str, float]:
    """Every channel's delay in milliseconds for an :class:`AgentConfig`: none (0) for
    ``delays=None``, the published figures at ``config.motor_age`` (the motor age, which is the
    body age unless ``motor_age_months`` is given) for ``"developmental"``, else the channels
    given (others 0)."""
    given = config.delays
    if given is None:
        return dict.fromkeys(CHANNELS, 0.0)
    if given == "developmental":
        return developmental_delays(config.motor_age)
    return {c: float(given.get(c, 0.0)) for c in CHANNELS}


def delay_steps(config, dt: float) -> dict[str, int]:
    """Every channel's delay in whole control steps of ``dt`` seconds (see the module)."""
    return {c: int(math.floor(ms / (1000.0 * dt) + 0.5 + 1e-9))
            for c, ms in delays_ms(config).items()}


def check_delay_steps(agent: str, config, dt: float) -> dict[str, int]:
    """:func:`delay_steps` of ``agent``'s config, else a ConfigError naming the agent, the
    channel, the delay and the most allowed when a channel that is on (its sense on, or the
    motor command) spans more than :data:`MAX_DELAY_STEPS` control steps of ``dt`` seconds."""
    steps = delay_steps(config, dt)
    # a channel whose sense is off has no buffer (nothing to delay)
    over = [c for c, k in steps.items() if k > MAX_DELAY_STEPS
            and (c == "motor" or getattr(config, c, None))]
    if over:
        c, ms = over[0], delays_ms(config)[over[0]]
        age = "an adult" if config.motor_age is None else f"{config.motor_age:g} months"
        given = (f"delays='developmental' ({age}) gives {c} {ms:g} ms"
                 if config.delays == "developmental" else f"delays[{c!r}]={ms:g} ms")
        longest = MAX_DELAY_STEPS * dt * 1000.0
        raise ConfigError(
            f"agent {agent}: {given}: {steps[c]} control steps of {dt * 1000.0:g} ms; allowed: "
            f"at most {MAX_DELAY_STEPS} steps, {longest:g} ms at this control step (physics "
            f"timestep x frame_skip; a step of {DELAY_LIMIT_MS / MAX_DELAY_STEPS:g} ms or "
            f"more allows the full {DELAY_LIMIT_MS:g} ms)")
    return steps


class SenseDelay:
    """Delays one sense of one agent by ``k`` control steps (``k >= 1``)."""

    def __init__(self, k: int):
        self.k = int(k)
        self._slots: list = [None] * (self.k + 1)
        self._next = 0
        self._repeats = 0

    def reset(self, reading: dict) -> dict:
        """Fill the ring with the reading at reset; return it (the reset observation)."""
        self._slots = [reading] * (self.k + 1)
        self._next = 0
        self._repeats = self.k
        return reading

    def push(self, reading: dict) -> dict:
        """Store this step's reading; return the one of ``k`` steps ago."""
        slots = self._slots
        slots[self._next] = reading
        self._next = (self._next + 1) % (self.k + 1)
        old = slots[self._next]
        if self._repeats:      # the reset reading, once per step for the first k steps
            self._repeats -= 1
            return {key: np.array(v, copy=True) for key, v in old.items()}
        return old


class MotorDelay:
    """Delays one agent's controls by ``k`` control steps (``k >= 1``)."""

    def __init__(self, k: int, n_controls: int):
        self.k = int(k)
        self.ring = np.zeros((self.k + 1, n_controls))
        self._next = 0

    def reset(self, controls: np.ndarray) -> None:
        """Every pending control is the one in force at reset."""
        self.ring[:] = controls
        self._next = 0

    def slot(self) -> np.ndarray:
        """The row this step's (clipped) controls are written into."""
        return self.ring[self._next]

    def advance(self) -> np.ndarray:
        """After writing :meth:`slot`: the controls given ``k`` steps ago, to apply now."""
        self._next = (self._next + 1) % (self.k + 1)
        return self.ring[self._next]


def delay_sensors(spec, prefix: str, k: int, timestep: float, frame_skip: int) -> None:
    """Set MuJoCo's sensor delay of ``k`` control steps on an attached agent's vestibular
    sensors (before compiling): ``k * frame_skip + 2`` samples, one per physics step, zero-order
    hold, delay ``k * dt - timestep / 2``."""
    for name in VESTIBULAR_SENSORS:
        sensor = spec.sensor(prefix + name)
        sensor.nsample = k * frame_skip + 2
        sensor.interp = 0              # zero-order hold: a stored sample, never a blend
        sensor.delay = k * timestep * frame_skip - 0.5 * timestep


def fill_sensor_history(model, data, sensors) -> None:
    """Fill the history of each delayed sensor (ids) with its current, undelayed reading, at the
    physics steps before ``data.time``; ``data.sensordata`` ends holding those readings (the
    delayed sensors read the reset reading until ``k`` steps have passed). Runs ``mj_forward``
    once with the delays off: it computes, and changes no state."""
    if not len(sensors):
        return
    delays = model.sensor_delay[sensors].copy()
    model.sensor_delay[sensors] = 0.0
    try:
        mujoco.mj_forward(model, data)
    finally:
        model.sensor_delay[sensors] = delays
    ts = model.opt.timestep
    for s in sensors:
        n = int(model.sensor_history[s, 0])
        adr, dim = int(model.sensor_adr[s]), int(model.sensor_dim[s])
        times = (data.time + ts * np.arange(-n, 0, dtype=float)).reshape(n, 1)
        values = np.tile(data.sensordata[adr:adr + dim], (n, 1))
        mujoco.mj_initSensorHistory(model, data, int(s), times, values, 0.0)
