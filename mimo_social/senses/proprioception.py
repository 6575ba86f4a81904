"""Proprioception (paper Sec. V): joint angles, velocities, actuator torques, limit sensors,
and the actuation model's state, each component switchable; and, when asked for, the face.

``face`` (off by default: not in :data:`DEFAULT_COMPONENTS`): the expression the agent's own face
shows now, one-hot over the 7 expressions (what its facial muscles report; the face is changed
by the agent's action and shown on its head's material, so it reads the world's model, not
MjData). A policy without memory that chooses its face every step cannot otherwise tell the
face it holds from the one it would switch to: measured on contingency with the gaze free, a
categorical face sampled every step flickered 18 onsets a second (issue 30, ninth session).

Limit sensors rise linearly from 0 to 1 over the last ``limit_margin_deg`` before a joint limit:
positive near the upper limit, negative near the lower one, 0 elsewhere.

Bounds of the observation Box: joint angles within the joint's range widened by
:data:`JOINT_OVERSHOOT` on each side (MuJoCo's joint limits are soft: a joint pushed hard passes
its range, by up to 23 degrees over 6000 bang-bang steps of free play), limit sensors within the
values of those angles, the spring-damper state within [-1, 1] (controls) and its torque limits,
muscle activations within [0, 1]; an angle beyond the widened range (only a diverging
simulation gets there) is clipped to it. Velocities, torques and muscle forces are unbounded.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from ..expressions.faces import EXPRESSIONS
from ..util.checks import check_number
from ..util.indexing import as_slice
from ..body.actuation.muscle import Muscle
from ..body.actuation.spring_damper import SpringDamper
from .base import SenseEntry, components

__all__ = ["ProprioceptionConfig", "Proprioception", "SENSE", "COMPONENTS", "DEFAULT_COMPONENTS",
           "JOINT_OVERSHOOT"]

#: how far (rad) past its range a joint angle may read (the Box's bound; clipped beyond)
JOINT_OVERSHOOT = np.pi / 2

#: every component, in the order observed
COMPONENTS = ("qpos", "qvel", "torque", "limits", "actuation", "face")
#: the components of the default config (the face is asked for)
DEFAULT_COMPONENTS = COMPONENTS[:5]


@dataclass(frozen=True)
class ProprioceptionConfig:
    """Joint positions, velocities, actuator torques, limit proximity, actuation state."""

    # the parts observed, in COMPONENTS' order ("face": the own expression, one-hot; off unless
    # listed)
    components: tuple[str, ...] = DEFAULT_COMPONENTS
    limit_margin_deg: float = 5.0  # a limit sensor rises from 0 to 1 over this last stretch

    def __post_init__(self):
        object.__setattr__(self, "components", components(
            "proprioception", self.components, COMPONENTS))
        object.__setattr__(self, "limit_margin_deg", check_number(
            "proprioception", "limit_margin_deg", self.limit_margin_deg, 0.01, 90.0))


class Proprioception:
    name = "proprioception"

    def __init__(self, config, agent, actuation, faces=None):
        self.config = config
        self.faces = faces           # the world's face textures (the "face" component reads them)
        self.agent = agent
        self.actuation = actuation
        self.margin = np.deg2rad(config.limit_margin_deg)
        self._inv_margin = 1.0 / self.margin
        self._lo = agent.joint_range[:, 0].copy()
        self._hi = agent.joint_range[:, 1].copy()
        n = len(agent.joint_names)
        sizes = {"qpos": n, "qvel": n, "torque": n, "limits": n,
                 "actuation": actuation.observation_size, "face": len(EXPRESSIONS)}
        self.slices, start = {}, 0
        for c in config.components:
            self.slices[c] = slice(start, start + sizes[c])
            start += sizes[c]
        self.size = start
        # joint angles: the range widened by JOINT_OVERSHOOT (unlimited joints: unbounded)
        limited = self._hi > self._lo
        self._q_lo = np.where(limited, self._lo - JOINT_OVERSHOOT, -np.inf)
        self._q_hi = np.where(limited, self._hi + JOINT_OVERSHOOT, np.inf)
        low = np.full(self.size, -np.inf)
        high = np.full(self.size, np.inf)
        for c, sl in self.slices.items():
            if c == "qpos":
                low[sl], high[sl] = self._q_lo, self._q_hi
            elif c == "limits":
                lo, hi = self._limit_values(self._q_lo), self._limit_values(self._q_hi)
                low[sl] = np.where(limited, lo, -np.inf)
                high[sl] = np.where(limited, hi, np.inf)
            elif c == "actuation":
                low[sl], high[sl] = _actuation_bounds(actuation)
            elif c == "face":
                low[sl], high[sl] = 0.0, 1.0
        if "face" in self.slices and faces is None:
            raise ValueError("proprioception: the face component needs the world's face "
                             "textures (faces=world.faces)")
        self.space = spaces.Box(low.astype(np.float32), high.astype(np.float32), dtype=np.float32)
        self.spaces = {self.name: self.space}
        # the agent's joints in MuJoCo's arrays: a slice (a view) when consecutive, as they are
        self._qpos = as_slice(agent.qpos_adr)
        self._dof = as_slice(agent.dof_adr)
        self._q = np.empty(n)                    # the clipped angles, float64 (limits read them)
        # limit sensors as max(A + q/m, 0) - max(B - q/m, 0): the formula of _limit_values with
        # its constants folded (equal to it within rounding)
        self._A = 1.0 - self._hi * self._inv_margin
        self._B = 1.0 + self._lo * self._inv_margin
        self._s, self._t = np.empty(n), np.empty(n)

    def _limit_values(self, q: np.ndarray) -> np.ndarray:
        """The limit sensors at joint angles ``q``: 1 - distance/margin, floored at 0, each side
        (at most 1 + overshoot/margin past a limit; rising with q)."""
        lo = np.maximum(1.0 - (q - self._lo) * self._inv_margin, 0.0)
        hi = np.maximum(1.0 - (self._hi - q) * self._inv_margin, 0.0)
        return hi - lo

    def observe(self, model, data, out: dict) -> None:
        out[self.name] = self.read(model, data)

    def read(self, model, data) -> np.ndarray:
        out = np.empty(self.size, np.float32)
        q = self._q
        np.minimum(np.maximum(data.qpos[self._qpos], self._q_lo, out=q), self._q_hi, out=q)
        for c, sl in self.slices.items():
            if c == "qpos":
                out[sl] = q
            elif c == "qvel":
                out[sl] = data.qvel[self._dof]
            elif c == "torque":
                out[sl] = data.qfrc_actuator[self._dof]
            elif c == "limits":  # 1 - distance/margin, floored at 0, on each side
                s, t = self._s, self._t
                np.multiply(q, self._inv_margin, out=s)
                np.maximum(np.subtract(self._B, s, out=t), 0.0, out=t)     # lower side
                np.maximum(np.add(self._A, s, out=s), 0.0, out=s)          # upper side
                np.subtract(s, t, out=out[sl])
            elif c == "face":
                out[sl] = 0.0
                out[sl.start + self.faces.shown(model, self.agent.head_material)] = 1.0
            else:
                out[sl] = self.actuation.observation(data)
        return out


def _actuation_bounds(actuation) -> tuple[np.ndarray, np.ndarray]:
    """Bounds of the actuation state: spring-damper ``[u, torque]``: [-1, 1] and the motors'
    torque limits; muscles ``[activation, force]``: [0, 1] and unbounded; another model:
    unbounded."""
    n = actuation.observation_size
    low, high = np.full(n, -np.inf), np.full(n, np.inf)
    if isinstance(actuation, SpringDamper):
        k = len(actuation.joints)
        low[:k], high[:k] = -1.0, 1.0
        low[k:], high[k:] = -np.abs(actuation.torque_neg), np.abs(actuation.torque_pos)
    elif isinstance(actuation, Muscle):
        k = n // 2
        low[:k], high[:k] = 0.0, 1.0
    return low, high


def _build(config: ProprioceptionConfig, world, index: int, actuation) -> Proprioception:
    return Proprioception(config, world.agents[index], actuation, world.faces)


SENSE = SenseEntry("proprioception", ProprioceptionConfig, per_agent=_build)
