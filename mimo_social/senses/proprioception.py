"""Proprioception (paper Sec. V): joint angles, velocities, actuator torques, limit sensors,
and the actuation model's state, each component switchable.

Limit sensors rise linearly from 0 to 1 over the last ``limit_margin_deg`` before a joint limit:
positive near the upper limit, negative near the lower one, 0 elsewhere.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from ..util.checks import check_number
from .base import SenseEntry, components

__all__ = ["ProprioceptionConfig", "Proprioception", "SENSE", "COMPONENTS"]

COMPONENTS = ("qpos", "qvel", "torque", "limits", "actuation")


@dataclass(frozen=True)
class ProprioceptionConfig:
    """Joint positions, velocities, actuator torques, limit proximity, actuation state."""

    components: tuple[str, ...] = COMPONENTS
    limit_margin_deg: float = 5.0  # a limit sensor rises from 0 to 1 over this last stretch

    def __post_init__(self):
        object.__setattr__(self, "components", components(
            "proprioception", self.components, COMPONENTS))
        object.__setattr__(self, "limit_margin_deg", check_number(
            "proprioception", "limit_margin_deg", self.limit_margin_deg, 0.01, 90.0))


class Proprioception:
    name = "proprioception"

    def __init__(self, config, agent, actuation):
        self.config = config
        self.agent = agent
        self.actuation = actuation
        self.margin = np.deg2rad(config.limit_margin_deg)
        self._inv_margin = 1.0 / self.margin
        self._lo = agent.joint_range[:, 0].copy()
        self._hi = agent.joint_range[:, 1].copy()
        n = len(agent.joint_names)
        sizes = {"qpos": n, "qvel": n, "torque": n, "limits": n,
                 "actuation": actuation.observation_size}
        self.slices, start = {}, 0
        for c in config.components:
            self.slices[c] = slice(start, start + sizes[c])
            start += sizes[c]
        self.size = start
        self.space = spaces.Box(-np.inf, np.inf, (self.size,), np.float32)
        self.spaces = {self.name: self.space}

    def observe(self, model, data, out: dict) -> None:
        out[self.name] = self.read(model, data)

    def read(self, model, data) -> np.ndarray:
        a = self.agent
        out = np.empty(self.size, np.float32)
        q = data.qpos[a.qpos_adr]
        for c, sl in self.slices.items():
            if c == "qpos":
                out[sl] = q
            elif c == "qvel":
                out[sl] = data.qvel[a.dof_adr]
            elif c == "torque":
                out[sl] = data.qfrc_actuator[a.dof_adr]
            elif c == "limits":  # 1 - distance/margin, floored at 0, on each side
                lo = np.maximum(1.0 - (q - self._lo) * self._inv_margin, 0.0)
                hi = np.maximum(1.0 - (self._hi - q) * self._inv_margin, 0.0)
                out[sl] = hi - lo
            else:
                out[sl] = self.actuation.observation(data)
        return out


def _build(config: ProprioceptionConfig, world, index: int, actuation) -> Proprioception:
    return Proprioception(config, world.agents[index], actuation)


SENSE = SenseEntry("proprioception", ProprioceptionConfig, per_agent=_build)
