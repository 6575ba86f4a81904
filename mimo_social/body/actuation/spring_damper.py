"""Spring-damper actuation (paper Sec. IV-A): one torque motor per movement axis.

Controls ``u`` in [-1, 1] map to the two directional maximum voluntary torques of Table I:
``u = -1`` gives ``-T_neg``, ``u = +1`` gives ``+T_pos`` (linear in between, on each side). The
spring and damper are the joints' passive stiffness and damping (MuJoCo computes them).
The actuation state observed is ``[u, torque]`` per motor.
"""

from __future__ import annotations

import numpy as np

from ...util.indexing import as_slice
from .base import Actuation


class SpringDamper(Actuation):
    name = "spring_damper"

    def __init__(self, joints, actuator_ids):
        super().__init__(joints, actuator_ids)
        self.torque_neg = np.array([j.torque_neg for j in self.joints])
        self.torque_pos = np.array([j.torque_pos for j in self.joints])
        self._low = -np.ones(len(self.joints), dtype=np.float32)
        self._high = np.ones(len(self.joints), dtype=np.float32)
        self._torque = np.zeros(len(self.joints))
        self._u = np.zeros(len(self.joints))
        self._ctrl = as_slice(self.actuator_ids)   # where the torques go in data.ctrl
        self._strength = self.strength(self._u)

    @property
    def control_low(self):
        return self._low

    @property
    def control_high(self):
        return self._high

    def torque(self, u: np.ndarray) -> np.ndarray:
        return u * self.strength(u)

    def apply(self, model, data, controls):
        self._u = np.asarray(controls, dtype=float)
        self._strength = self.strength(self._u)    # kept for the costs of these controls
        self._torque = self._u * self._strength
        data.ctrl[self._ctrl] = self._torque

    def reset(self, model, data):
        self._u[:] = 0.0
        self._strength = self.strength(self._u)
        self._torque[:] = 0.0
        data.ctrl[self._ctrl] = 0.0

    @property
    def observation_size(self):
        return 2 * len(self.joints)

    def observation(self, data):
        return np.concatenate([self._u, self._torque])

    def strength(self, u: np.ndarray) -> np.ndarray:
        """T_i: the maximum torque of each motor in the direction it is driven."""
        return np.where(u >= 0.0, self.torque_pos, self.torque_neg)

    def cost(self, controls):
        u = np.asarray(controls, dtype=float)
        return float(u @ u) / u.size if u.size else 0.0

    def weighted_cost(self, controls):
        u = np.asarray(controls, dtype=float)
        if not u.size:
            return 0.0
        t = self.strength(u)
        return float((u * u) @ t) / (u.size * float(t.sum()))

    def costs(self, controls):
        u = np.asarray(controls, dtype=float)
        if not u.size:
            return 0.0, 0.0
        # the controls just applied (the env's infos): their strengths are known
        t = self._strength if u is self._u else self.strength(u)
        return float(u @ u) / u.size, float((u * u) @ t) / (u.size * float(t.sum()))
