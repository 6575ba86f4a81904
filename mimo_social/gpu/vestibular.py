"""The vestibular sense of one agent for every world at once, in the CPU sense's layout
(:class:`mimo_social.senses.vestibular.Vestibular`): the gyro (rad/s) and the accelerometer
(m/s^2) at the head centre, in the head's frame, as the model's own sensors compute them.

MuJoCo Warp computes the model's sensors into ``sensordata`` at every physics step, with
MuJoCo's own sensor delay (the CPU env delays the vestibular sense that way:
:func:`mimo_social.core.delays.delay_sensors`), so this sense only picks the agent's entries:
no ring of its own, no noise (the CPU sense has none).
"""

from __future__ import annotations

import numpy as np

__all__ = ["BatchedVestibular"]


class BatchedVestibular:
    """``sense``: the agent's vestibular object in the CPU env (its ``idx``: the entries of
    ``sensordata`` it reads, gyro then accelerometer as configured)."""

    name = "vestibular"

    def __init__(self, sense, torch, device):
        self._torch = torch
        self.idx = torch.as_tensor(np.asarray(sense.idx, np.int64), device=device)
        self.size = int(sense.size)

    def read(self, data):
        """This step's reading, ``(nworld, size)`` float32 (a copy)."""
        return data["sensordata"][:, self.idx].to(self._torch.float32)

    def reset(self, data, worlds=None):
        """The reading at reset (the sensors' history is part of the world's state)."""
        return self.read(data)

    def observe(self, data):
        """This step's observation (delayed by MuJoCo's sensor delay, when the agent has one)."""
        return self.read(data)
