"""Vestibular sense (paper Sec. V): a gyroscope and an accelerometer at the head centre,
both in the head's frame (MuJoCo's gyro and accelerometer sensors)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from .base import SenseEntry, components

__all__ = ["VestibularConfig", "Vestibular", "SENSE", "COMPONENTS"]

COMPONENTS = ("gyro", "accel")


@dataclass(frozen=True)
class VestibularConfig:
    """Angular velocity (gyro, rad/s) and linear acceleration (accel, m/s^2) at the head centre."""

    components: tuple[str, ...] = COMPONENTS   # gyro (rad/s) and accel (m/s^2), in order

    def __post_init__(self):
        object.__setattr__(self, "components", components(
            "vestibular", self.components, COMPONENTS))


class Vestibular:
    name = "vestibular"

    def __init__(self, config, agent):
        self.config = config
        idx = []
        if "gyro" in config.components:
            idx += range(agent.gyro_adr, agent.gyro_adr + 3)
        if "accel" in config.components:
            idx += range(agent.accel_adr, agent.accel_adr + 3)
        self.idx = np.array(idx, dtype=np.intp)
        self.size = len(idx)
        self.space = spaces.Box(-np.inf, np.inf, (self.size,), np.float32)
        self.spaces = {self.name: self.space}

    def observe(self, model, data, out: dict) -> None:
        out[self.name] = data.sensordata[self.idx].astype(np.float32)

    def read(self, model, data) -> np.ndarray:
        return data.sensordata[self.idx].astype(np.float32)


def _build(config: VestibularConfig, world, index: int, actuation) -> Vestibular:
    return Vestibular(config, world.agents[index])


SENSE = SenseEntry("vestibular", VestibularConfig, per_agent=_build)
