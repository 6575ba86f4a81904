"""Scripted partners for every world at once: the control law of a CPU partner ported to
batched torch, its per-episode plan (targets, gains) computed on the host at each world's
reset, from the CPU partner reset on the CPU env with the world's seed.

One partner is batched: :class:`~mimo_social.partners.hand_offer.HandOffer` without a grip and
without a release (``grip=False, release=None``: the high five's default partner,
:func:`mimo_social.tasks.high_five.default_partner`) on spring-damper motors. Its law, as
:meth:`HandOffer.torques` and :meth:`HandOffer.act`: per motor
``tau = kp (target - q) - kd qdot + qfrc_bias - qfrc_spring`` (the gravity / Coriolis and
passive-spring compensation MuJoCo Warp computes in the same fields), ``u = tau / T_pos`` for
``tau >= 0``, ``tau / T_neg`` below, clipped to [-1, 1]. Its target angles are the CPU
partner's (``target_angles``, solved once per reset by inverse kinematics on the host) and its
gains :func:`~mimo_social.partners.base.pd_gains` at the world's reset pose, as the CPU partner
computes them. Other partners raise a ValueError naming the agent and the partner.
"""

from __future__ import annotations

import numpy as np

from ..body.actuation import SpringDamper
from ..partners.base import pd_gains
from ..partners.hand_offer import HandOffer

__all__ = ["BatchedHandOffer", "batched_partner"]


class BatchedHandOffer:
    """``partner``: the CPU :class:`HandOffer`; ``agent``: its agent's name; ``env``: the
    CPU env (its index tables); ``batched``: the :class:`~mimo_social.gpu.batched.BatchedEnv`."""

    def __init__(self, agent: str, partner, env, batched):
        i = env.possible_agents.index(agent)
        act = env.actuation[i]
        if type(act) is not SpringDamper:
            raise ValueError(f"{agent}: a batched HandOffer needs spring-damper motors; got "
                             f"actuation={act.name!r}")
        torch = batched.torch
        self.agent, self.partner, self.batched = agent, partner, batched
        a = env.world.agents[i]
        jk = a.actuated_joint_idx
        self._dadr_np = a.dof_adr[jk]
        dev = batched.qpos.device
        as_t = lambda x, kind=torch.float32: torch.as_tensor(np.asarray(x), dtype=kind,  # noqa
                                                             device=dev)
        self.qadr, self.dadr = as_t(a.qpos_adr[jk], torch.int64), as_t(self._dadr_np, torch.int64)
        self.tneg, self.tpos = as_t(act.torque_neg), as_t(act.torque_pos)
        n = len(jk)
        self.target = torch.zeros((batched.nworld, n), dtype=torch.float32, device=dev)
        self.kp = torch.zeros_like(self.target)
        self.kd = torch.zeros_like(self.target)

    def capture(self, env) -> dict:
        """The plan of the CPU partner just reset on ``env`` (host work)."""
        m, d = env.world.model, env.world.data
        kp, kd = pd_gains(m, d, self._dadr_np, self.partner.frequency, self.partner.damping)
        return {"target": np.array(self.partner.target_angles, float), "kp": kp, "kd": kd}

    def load(self, idx, captured) -> None:
        """The captured plans (stacked: ``(len(idx), n)`` per key) into the worlds ``idx``."""
        t = self.batched.torch
        for key in ("target", "kp", "kd"):
            getattr(self, key)[idx] = t.as_tensor(captured[key], device=self.kp.device).to(
                t.float32)

    def act(self):
        """Every world's motor commands ``(nworld, n)`` from the current data (read before the
        step, as the CPU partner reads ``MjData`` before the env's step)."""
        t = self.batched.torch
        d = self.batched.tensors
        q = d["qpos"][:, self.qadr].to(t.float32)
        qd = d["qvel"][:, self.dadr].to(t.float32)
        tau = self.kp * (self.target - q) - self.kd * qd
        tau = tau + (d["qfrc_bias"][:, self.dadr] - d["qfrc_spring"][:, self.dadr]).to(t.float32)
        u = t.where(tau >= 0.0, tau / self.tpos, tau / self.tneg)
        return t.clamp(u, -1.0, 1.0)


def batched_partner(agent: str, partner, env, batched):
    """The batched form of the CPU partner ``partner`` of ``agent``, or a ValueError naming the
    agent, the partner and what runs on the device."""
    if type(partner) is HandOffer and not partner.grip and partner.release is None:
        return BatchedHandOffer(agent, partner, env, batched)
    raise ValueError(f"{agent}: scripted partner {partner!r} has no batched form on the GPU "
                     f"backend; allowed: HandOffer(grip=False, release=None) (the high five's "
                     f"default partner), or the agent as a learner (its actions given)")
