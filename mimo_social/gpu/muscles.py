"""Muscle actuation on the device: one agent's opposing muscles in every world at once, in torch,
as the CPU model computes them (:class:`mimo_social.body.actuation.muscle.Muscle`).

Before every physics step, per world and muscle: the activation follows the held control
(``a <- a + (1 - exp(-dt / TAU)) (u - a)``), the virtual length and speed come from the joint's
angle and velocity, the force is ``F = FL(L) FV(V) a + FP(L)`` and the joint's torque
``-(m1 F1 fmax_neg + m2 F2 fmax_pos)`` goes into its motor's ``ctrl``. The curves are read from
tables on the CPU model's grids by linear interpolation, as the CPU model does (``np.interp``).

Why not MuJoCo's own muscle actuators (which MuJoCo Warp runs): their force-velocity curve is
this model's, but their force-length curve lacks the published model's second, ascending bump
and their passive force rises another way; over the virtual lengths a joint's range maps to
(0.75 to 1.05) the active force differs by up to 23 % (tests/body/test_muscle_native.py), more
than the 5 % issue 34 allows.
"""

from __future__ import annotations

import numpy as np

from ..body.actuation.muscle import TAU, force_length, force_passive, force_velocity

__all__ = ["BatchedMuscle"]

#: the curves' tables: (first x, last x, points), as the CPU model's look-up tables
L_TABLE = (0.4, 2.0, 1601)
V_TABLE = (-1.2, 0.4, 801)


class _Table:
    """A curve sampled on a uniform grid, read by linear interpolation (the end values held
    outside it, as ``np.interp``)."""

    def __init__(self, curve, grid, torch, device):
        lo, hi, n = grid
        self.lo, self.n = float(lo), int(n)
        self.step = (float(hi) - float(lo)) / (self.n - 1)
        self.values = torch.as_tensor(curve(np.linspace(lo, hi, n)), dtype=torch.float64,
                                      device=device)

    def __call__(self, x):
        s = ((x - self.lo) / self.step).clamp(0.0, self.n - 1.0)
        i = s.floor().clamp(max=self.n - 2).long()
        f = s - i
        return self.values[i] * (1.0 - f) + self.values[i + 1] * f


class BatchedMuscle:
    """The muscles of one agent (``act``: its :class:`Muscle` in the CPU env, bound to ``model``)
    in ``nworld`` worlds: :attr:`activation` and :attr:`force` ``(nworld, 2, n)`` (rows:
    negative, positive muscles), the held controls set by :meth:`hold`, the torques written by
    :meth:`substep`."""

    def __init__(self, act, model, nworld: int, torch, device):
        self._torch = torch
        self.nworld, self.n = int(nworld), int(act.n_axes)
        as_t = lambda x, kind=torch.float64: torch.as_tensor(np.asarray(x), dtype=kind,  # noqa
                                                             device=device)
        ids = np.asarray(act.actuator_ids, dtype=np.int64)
        jnt = model.actuator_trnid[ids, 0]
        self.ids = as_t(ids, torch.int64)
        self.qadr = as_t(model.jnt_qposadr[jnt], torch.int64)
        self.dofadr = as_t(model.jnt_dofadr[jnt], torch.int64)
        self.moment, self.offset = as_t(act.moment), as_t(act.offset)
        self.speed = as_t(act.moment / act.vmax)
        self.gain = as_t(act.gain)
        self.alpha = 1.0 - float(np.exp(-float(model.opt.timestep) / TAU))
        self.fl = _Table(force_length, L_TABLE, torch, device)
        self.fp = _Table(force_passive, L_TABLE, torch, device)
        self.fv = _Table(force_velocity, V_TABLE, torch, device)
        shape = (self.nworld, 2, self.n)
        self.activation = torch.zeros(shape, dtype=torch.float64, device=device)
        self.force = torch.zeros(shape, dtype=torch.float64, device=device)
        self.u = torch.zeros(shape, dtype=torch.float64, device=device)

    def hold(self, applied) -> None:
        """The controls in force from now on, ``(nworld, 2 n)`` in [0, 1] (the agent's control
        layout: the negative muscles, then the positive ones)."""
        self.u = applied.to(self._torch.float64).reshape(self.nworld, 2, self.n)

    def reset(self, worlds=None, activation=None, force=None) -> None:
        """``worlds`` (a bool mask or indices; None: all) at rest (activations and forces 0) or
        given ``activation`` / ``force`` ``(k, 2, n)``."""
        sel = slice(None) if worlds is None else worlds
        if activation is None:
            self.activation[sel] = 0.0
            self.force[sel] = 0.0
            return
        t = self._torch
        self.activation[sel] = t.as_tensor(activation, device=self.activation.device).to(
            t.float64)
        self.force[sel] = t.as_tensor(force, device=self.force.device).to(t.float64)

    def substep(self, data) -> None:
        """One physics step's update of every world (``data``: the batched data's tensors):
        the activations, the forces and the torques into ``ctrl``."""
        a = self.activation
        a += self.alpha * (self.u - a)
        q = data["qpos"][:, self.qadr].to(a.dtype)[:, None, :]
        qd = data["qvel"][:, self.dofadr].to(a.dtype)[:, None, :]
        L = self.moment * q + self.offset
        F = self.fl(L) * self.fv(self.speed * qd) * a + self.fp(L)
        self.force = F
        ctrl = data["ctrl"]
        ctrl[:, self.ids] = (self.gain * F).sum(1).to(ctrl.dtype)

    def observation(self):
        """The actuation part of proprioception, ``[activations (2 n), forces (2 n)]``."""
        t = self._torch
        return t.cat([self.activation.reshape(self.nworld, -1),
                      self.force.reshape(self.nworld, -1)], dim=1).to(t.float32)
