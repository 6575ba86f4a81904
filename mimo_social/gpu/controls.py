"""Batched actions to MuJoCo controls, as the CPU env turns one agent's action into
``data.ctrl`` (:meth:`mimo_social.core.env.MimoParallelEnv.step`), for every world at once.

Per agent and world: the motor values are clipped into the action Box, delayed by the agent's
motor delay (a ring of ``k + 1`` rows filled at reset with the controls in force then, the
CPU env's :class:`~mimo_social.core.delays.MotorDelay`), then mapped by the actuation model:

* spring-damper: ``ctrl = u T_pos`` for ``u >= 0``, ``u T_neg`` below (the motors' maximum
  voluntary torques; :class:`~mimo_social.body.actuation.SpringDamper`);
* positional: ``ctrl = lo + (u + 1) (hi - lo) / 2``, the target angle of MuJoCo's servo
  (:class:`~mimo_social.body.actuation.Positional`; the servo gains are in the compiled model).

* muscle: the controls are held, and before every physics step the muscles' activations,
  forces and the joints' torques are computed in torch (:class:`~mimo_social.gpu.muscles.
  BatchedMuscle`, called by the batched env's physics loop).
"""

from __future__ import annotations

import numpy as np

from ..body.actuation import Muscle, Positional, SpringDamper
from .muscles import BatchedMuscle

__all__ = ["AgentControls", "SUPPORTED", "check_actuation"]

#: the actuation models the device reproduces (``AgentConfig.actuation``)
SUPPORTED = ("spring_damper", "positional", "muscle")


def check_actuation(agent: str, act) -> None:
    """A ValueError naming ``agent`` and its actuation model when the device cannot run it."""
    if type(act) not in (SpringDamper, Positional, Muscle):
        raise ValueError(f"{agent}: actuation={getattr(act, 'name', type(act).__name__)!r} does "
                         f"not run on the GPU backend; allowed: {', '.join(SUPPORTED)}")


class AgentControls:
    """One agent's actions for ``nworld`` worlds: clipping, motor delay, actuation mapping.

    ``act``: the agent's actuation object in the CPU env; ``delay``: its motor delay in
    control steps; ``reset_controls``: its controls in force at reset (``env.controls[i]``);
    ``reset_observed``: the controls its proprioception reports at reset (None: those; a
    positional agent reports the targets of the pose it holds, :meth:`Positional.reset`)."""

    def __init__(self, agent: str, act, delay: int, reset_controls, nworld: int, torch, device,
                 reset_observed=None, model=None):
        check_actuation(agent, act)
        self.agent = agent
        self.positional = isinstance(act, Positional)
        self.nworld = int(nworld)
        self.n = act.n_controls
        self.delay = int(delay)
        self._torch = torch
        as_t = lambda x: torch.as_tensor(np.asarray(x, np.float32), device=device)  # noqa: E731
        self.low, self.high = as_t(act.control_low), as_t(act.control_high)
        self.ids = torch.as_tensor(np.asarray(act.actuator_ids, np.int64), device=device)
        #: the muscles' state and update (None: no muscles); needs the bound ``model``
        self.muscle = None if not isinstance(act, Muscle) else BatchedMuscle(
            act, model, nworld, torch, device)
        if self.positional:
            self.a, self.b = as_t(act.lo), as_t(0.5 * (act.hi - act.lo))
        elif self.muscle is not None:
            self.a = self.b = None
        else:
            self.a, self.b = as_t(act.torque_neg), as_t(act.torque_pos)
        self._reset = as_t(reset_controls)
        self._observed = self._reset if reset_observed is None else as_t(reset_observed)
        self.ring = torch.zeros((self.delay + 1, self.nworld, self.n), dtype=torch.float32,
                                device=device)
        self.applied = torch.zeros((self.nworld, self.n), dtype=torch.float32, device=device)
        self._next = 0
        self.reset()

    def reset(self, worlds=None, controls=None, observed=None, rows=None) -> None:
        """The controls in force at reset, in every slot of the ring (``worlds``: a bool mask
        of the worlds to reset; None: all). ``controls`` / ``observed``: ``(k, n)`` rows (numpy or torch) of
        the worlds ``rows`` (indices; the same worlds as the mask) in place of the reset's given
        at construction (``observed`` None: ``controls``)."""
        if worlds is None:
            self.ring[:] = self._reset
            self.applied[:] = self._observed
            self._next = 0
        elif controls is None:
            self.ring[:, worlds] = self._reset
            self.applied[worlds] = self._observed
        else:
            t, dev = self._torch, self.low.device
            c = t.as_tensor(controls, device=dev).to(t.float32)
            o = c if observed is None else t.as_tensor(observed, device=dev).to(t.float32)
            self.ring[:, rows] = c
            self.applied[rows] = o
        if self.muscle is not None:
            self.muscle.reset(worlds)
            self.muscle.hold(self.applied)

    def check(self, u):
        """``u`` as a float32 tensor ``(nworld, n)`` on the device; a ValueError naming the agent,
        the field (its motors), the value and what is allowed for a wrong shape or dtype or
        NaN/inf."""
        t = self._torch
        try:
            u = t.as_tensor(u, device=self.low.device)
        except (TypeError, ValueError, RuntimeError) as e:
            raise ValueError(f"{self.agent}: motors {type(u).__name__} not allowed ({e}); "
                             f"allowed: a ({self.nworld}, {self.n}) array of real numbers "
                             f"(torch or numpy)") from None
        if tuple(u.shape) != (self.nworld, self.n):
            raise ValueError(f"{self.agent}: motors of shape {tuple(u.shape)}; expected "
                             f"({self.nworld}, {self.n}): one row of {self.n} motor values per "
                             f"world")
        if u.dtype.is_complex or u.dtype == t.bool or not u.dtype.is_floating_point and \
                u.dtype not in (t.int8, t.int16, t.int32, t.int64, t.uint8):
            raise ValueError(f"{self.agent}: motors of dtype {u.dtype}; expected real numbers "
                             f"(a float or integer dtype)")
        u = u.to(t.float32)
        if not bool(t.isfinite(u).all()):
            raise ValueError(f"{self.agent}: motors hold NaN/inf; values must be finite, in "
                             f"[{float(self.low.min()):g}, {float(self.high.max()):g}]")
        return u

    def step(self, u, ctrl) -> None:
        """Clip ``u`` (checked), push it through the delay ring and write the agent's controls
        into ``ctrl`` (the batched ``data.ctrl`` as a tensor, ``(nworld, nu)``)."""
        t = self._torch
        clipped = t.minimum(t.maximum(u, self.low), self.high)
        if self.delay:
            self.ring[self._next] = clipped
            self._next = (self._next + 1) % (self.delay + 1)
            self.applied = self.ring[self._next].clone()
        else:
            self.applied = clipped
        if self.muscle is not None:      # held; the torques come before each physics step
            self.muscle.hold(self.applied)
            return
        ctrl[:, self.ids] = self.map(self.applied).to(ctrl.dtype)

    def map(self, u):
        """The MuJoCo controls of applied controls ``u`` (see the module)."""
        if self.positional:
            return self.a + (u + 1.0) * self.b
        return u * self._torch.where(u >= 0.0, self.b, self.a)

    def observation(self, data_tensors):
        """The actuation part of proprioception, ``[u, torque]`` per motor: spring-damper the
        applied torque, positional the servo's output (``actuator_force``)."""
        t = self._torch
        if self.muscle is not None:      # [activations, forces], as the CPU muscle reports
            return self.muscle.observation()
        if self.positional:
            torque = data_tensors["actuator_force"][:, self.ids]
        else:
            torque = self.applied * t.where(self.applied >= 0.0, self.b, self.a)
        return t.cat([self.applied, torque.to(t.float32)], dim=1)
