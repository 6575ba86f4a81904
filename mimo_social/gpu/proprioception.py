"""Proprioception of one agent for every world at once, in the CPU sense's layout
(:class:`mimo_social.senses.proprioception.Proprioception`): the components the agent has on,
in its order, each as the CPU sense computes it, and its delay.

* ``qpos``: the joint angles, clipped to the range widened by ``JOINT_OVERSHOOT``;
* ``qvel``: the joint velocities; ``torque``: ``qfrc_actuator`` of the joints' dofs;
* ``limits``: 1 - distance / margin, floored at 0, on each side (upper minus lower);
* ``actuation``: ``[u, torque]`` per motor (:meth:`AgentControls.observation`).

A delay of ``k`` control steps hands out the reading of ``k`` steps before (the reading at reset
until then), as the CPU env's :class:`~mimo_social.core.delays.SenseDelay` does.
"""

from __future__ import annotations

import numpy as np

from ..senses.proprioception import JOINT_OVERSHOOT
from .delay_ring import DelayRing

__all__ = ["BatchedProprioception"]


class BatchedProprioception:
    """``sense``: the agent's proprioception object in the CPU env; ``delay``: its delay in
    control steps; ``controls``: the agent's :class:`AgentControls`."""

    name = "proprioception"

    def __init__(self, sense, delay: int, controls, nworld: int, torch, device, face=None):
        self._torch = torch
        self._face = face     # () -> (nworld, 7) one-hot of the agent's expression
        self.controls = controls
        self.slices = dict(sense.slices)
        self.size = max(s.stop for s in self.slices.values())
        agent = sense.agent
        lo, hi = agent.joint_range[:, 0], agent.joint_range[:, 1]
        limited = hi > lo
        inv = 1.0 / float(sense.margin)
        as_t = lambda x, kind=torch.float64: torch.as_tensor(np.asarray(x), dtype=kind,  # noqa
                                                             device=device)
        self.qpos_adr = as_t(agent.qpos_adr, torch.int64)
        self.dof_adr = as_t(agent.dof_adr, torch.int64)
        self.q_lo = as_t(np.where(limited, lo - JOINT_OVERSHOOT, -np.inf))
        self.q_hi = as_t(np.where(limited, hi + JOINT_OVERSHOOT, np.inf))
        self.inv_margin = inv
        self.upper = as_t(1.0 - hi * inv)     # the CPU sense's folded constants
        self.lower = as_t(1.0 + lo * inv)
        self.delay = int(delay)
        self.ring = DelayRing(delay, nworld, self.size, torch, device)
        self.device = device

    def read(self, data):
        """This step's reading, ``(nworld, size)`` float32; ``data``: the batched data's
        arrays as tensors by name."""
        t = self._torch
        out = t.empty((data["qpos"].shape[0], self.size), dtype=t.float32,
                      device=self.device)
        q = data["qpos"][:, self.qpos_adr].to(t.float64)
        q = t.minimum(t.maximum(q, self.q_lo), self.q_hi)
        for c, sl in self.slices.items():
            if c == "qpos":
                out[:, sl] = q
            elif c == "qvel":
                out[:, sl] = data["qvel"][:, self.dof_adr]
            elif c == "torque":
                out[:, sl] = data["qfrc_actuator"][:, self.dof_adr]
            elif c == "limits":
                s = q * self.inv_margin
                out[:, sl] = t.clamp(self.upper + s, min=0.0) - t.clamp(self.lower - s, min=0.0)
            elif c == "face":
                out[:, sl] = self._face()
            else:
                out[:, sl] = self.controls.observation(data)
        return out

    def reset(self, data, worlds=None):
        """The reading at reset, in every slot of the delay ring (``worlds``: a bool mask of
        the worlds reset; None: all); returns the observation."""
        return self.ring.reset(self.read(data), worlds)

    def observe(self, data):
        """This step's observation: the reading of ``delay`` steps before."""
        return self.ring.push(self.read(data))
