"""Head and eyes turned to fixate a body in every world at once, as the CPU task's
:class:`~mimo_social.core.kinematics.Gaze` turns them (the angles of
:class:`~mimo_social.core.kinematics.LookAt`): the gaze joints zeroed, the target read, the head
swivelled and tilted to face it from the neck, each eye turned to it from its own centre, the
angles clipped into the joints' ranges and set on the state with their speeds zeroed. Three
kinematics passes of the batched worlds (MuJoCo Warp's), as the CPU's three ``mj_kinematics``.
"""

from __future__ import annotations

__all__ = ["BatchedGaze"]


class BatchedGaze:
    """The gaze of the agent whose CPU :class:`~mimo_social.core.kinematics.LookAt` is ``look``,
    in every world of ``batched`` (a :class:`~mimo_social.gpu.batched.BatchedEnv`)."""

    def __init__(self, look, batched):
        torch = batched.torch
        dev = batched.qpos.device
        self._torch, self._batched = torch, batched
        self.qpos = torch.as_tensor(look.qpos.astype("int64"), device=dev)
        self.dof = torch.as_tensor(look.dof.astype("int64"), device=dev)
        self.lo = torch.as_tensor(look.lo, dtype=torch.float32, device=dev)
        self.hi = torch.as_tensor(look.hi, dtype=torch.float32, device=dev)
        self.swivel, self.tilt, self.head = look.swivel, look.tilt, int(look.head_body)
        self.eyes = list(look.eyes)
        self.n = len(look.joints)

    def _local(self, target, body):
        """``target - xpos[body]`` in the head's frame, ``(nworld, 3)``."""
        d = self._batched.tensors
        R = d["xmat"][:, self.head].reshape(-1, 3, 3).to(self._torch.float32)
        v = target - d["xpos"][:, body].to(self._torch.float32)
        return (R.transpose(1, 2) @ v[:, :, None])[:, :, 0]

    def fixate(self, body: int) -> None:
        """Every world's head and eyes turned to body ``body``'s origin."""
        t, b = self._torch, self._batched
        if not self.n:
            return
        d = b.tensors
        d["qpos"][:, self.qpos] = 0.0
        b.kinematics()
        target = d["xpos"][:, body].to(t.float32).clone()
        q = t.zeros((b.nworld, self.n), dtype=t.float32, device=target.device)
        if self.swivel is not None:
            v = self._local(target, self.head)
            q[:, self.swivel] = t.atan2(v[:, 1], v[:, 0])
            if self.tilt is not None:
                q[:, self.tilt] = -t.atan2(v[:, 2], t.hypot(v[:, 0], v[:, 1]))
            q = t.minimum(t.maximum(q, self.lo), self.hi)
            d["qpos"][:, self.qpos] = q.to(d["qpos"].dtype)
            b.kinematics()
        for eye_body, sign, horizontal, vertical in self.eyes:
            v = self._local(target, eye_body)
            if horizontal is not None:
                q[:, horizontal] = sign * t.atan2(v[:, 1], v[:, 0])
            if vertical is not None:
                q[:, vertical] = t.atan2(v[:, 2], t.hypot(v[:, 0], v[:, 1]))
        q = t.minimum(t.maximum(q, self.lo), self.hi)
        d["qpos"][:, self.qpos] = q.to(d["qpos"].dtype)
        d["qvel"][:, self.dof] = 0.0
        b.kinematics()
