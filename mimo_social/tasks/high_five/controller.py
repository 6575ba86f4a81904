"""``HighFiveController``: the scripted solution of the high five (the learner's side).

reads:
    every ``replan_steps`` control steps, from the world: where the partner's right palm centre is
    (the other agent's palm site); each step: its own right arm's joint angles and speeds, and
    MuJoCo's bias and passive-spring forces on them
target:
    the arm posture whose right palm centre reaches the partner's palm, pushed ``push`` (m) further
    along its own heading (toward the partner), the palm facing forward:
    :func:`~mimo_social.partners.hand_offer.offer_posture` (damped least squares on a scratch copy
    of the state, from the offer posture, alternating position and wrist orientation); the fingers
    straight, the thumb at rest
arm:
    PD control per joint toward the target angles, gains from each joint's own inertia (the diagonal
    of the joint-space mass matrix at reset; natural frequency ``frequency`` 3 Hz, damping ratio
    ``damping`` 1), plus compensation of gravity / Coriolis (``qfrc_bias``) and joint springs
    (``qfrc_spring``); the torques become the agent's controls
    (:func:`~mimo_social.partners.base.torque_controls`: spring-damper motors ``u = tau / T_max``,
    muscles the agonist's activation)
acts:
    only through the agent's action (the expression, if any, neutral); it writes no state and
    changes no model value

The palm it aims at moves while the partner brings its hand out, so the posture is solved
again every ``replan_steps`` steps (50 ms by default). Measured success on ``high_five_v0``'s
``scripted_env()``: see the task's table.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...body.joint_groups import RIGHT_SHOULDER_ELBOW, RIGHT_WRIST
from ...core.kinematics import reach_sites
from ...util.checks import check_int, check_number
from ...partners.base import (Partner, agent_index, motor_action, pd_gains, require_motors,
                               torque_controls)
from ...partners.hand_offer import OPEN_FINGERS_DEG, PALMS, offer_posture


__all__ = ["ArmSweep", "HighFiveController"]

ARM = RIGHT_SHOULDER_ELBOW + RIGHT_WRIST
WHO = "HighFiveController"


class HighFiveController(Partner):
    """Bring the right palm onto the partner's right palm (see the module table).

    ``push``: how far (m) beyond the partner's palm centre the own palm aims, along its heading;
    ``palm``: the wrist's goal (``"forward"``, ``"up"`` or ``"posture"``, as in
    :func:`~mimo_social.partners.hand_offer.offer_posture`); ``replan_steps``: control steps
    between two solutions of the posture; ``frequency`` (Hz) and ``damping`` (ratio): the PD
    loop; ``partner``: the other agent's name (default: the first other agent)."""

    def __init__(self, push: float = 0.02, palm: str = "forward", replan_steps: int = 5,
                 frequency: float = 3.0, damping: float = 1.0, partner: str | None = None,
                 tolerance: float = 0.02):
        self.push = check_number(WHO, "push", push, -0.1, 0.1)
        self.tolerance = check_number(WHO, "tolerance", tolerance, 0.0, 1.0)
        if not isinstance(palm, str) or palm not in PALMS:
            raise ValueError(f"{WHO}: palm={palm!r}; allowed: {list(PALMS)}")
        self.palm = palm
        self.replan_steps = check_int(WHO, "replan_steps", replan_steps, 1, 1000)
        self.frequency = check_number(WHO, "frequency", frequency, 0.1, 20.0)
        self.damping = check_number(WHO, "damping", damping, 0.1, 5.0)
        if partner is not None and not isinstance(partner, str):
            raise ValueError(f"{WHO}: partner={partner!r}; allowed: None or an agent's name")
        self.partner = partner

    def __repr__(self):
        return (f"HighFiveController(push={self.push}, palm={self.palm!r}, "
                f"replan_steps={self.replan_steps})")

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        w = env.world
        m, d = w.model, w.data
        i = agent_index(env, agent)
        names = list(env.possible_agents)
        if self.partner is None:
            others = [k for k in range(len(names)) if k != i]
            if not others:
                raise ValueError(f"{WHO}: {agent} has no partner in this env")
            j = others[0]
        elif self.partner in names and self.partner != agent:
            j = names.index(self.partner)
        else:
            raise ValueError(f"{WHO}: partner={self.partner!r} for {agent}; allowed: "
                             f"{[n for n in names if n != agent]}")
        a = w.agents[i]
        require_motors(WHO, agent, a, ARM,
                       "it needs the right arm's motors (shoulder, elbow, wrist) in its action")
        self._i = i
        self._partner_palm = int(w.agents[j].palm_sites[0])
        self._palm = int(a.palm_sites[0])
        self._tips = int(a.fingertip_sites[0])
        self._scratch = mujoco.MjData(m)
        jk = a.actuated_joint_idx
        self._qadr, self._dadr = a.qpos_adr[jk], a.dof_adr[jk]
        self._lo, self._hi = a.joint_range[jk, 0], a.joint_range[jk, 1]
        motor_names = list(a.actuated_names)
        self._arm = np.array([motor_names.index(n) for n in ARM])
        fingers = np.deg2rad([OPEN_FINGERS_DEG.get(n, 0.0) for n in motor_names])
        self.target_angles = np.clip(fingers, self._lo, self._hi)
        shoulder_dof = a.dof_adr[a.joint_names.index(ARM[0])]
        self._shoulder = int(m.jnt_bodyid[m.dof_jntid[shoulder_dof]])
        R = d.xmat[a.root_body].reshape(3, 3)
        heading = np.arctan2(R[1, 0], R[0, 0])
        self._c, self._s = float(np.cos(heading)), float(np.sin(heading))
        self._kp, self._kd = pd_gains(m, d, self._dadr, self.frequency, self.damping)
        self._act = env.actuation[i]
        self._steps = 0
        self._plan(env)

    def _plan(self, env) -> None:
        """Solve the arm posture for the partner's palm where it is now."""
        d = env.world.data
        c, s = self._c, self._s
        goal = d.site_xpos[self._partner_palm] + self.push * np.array([c, s, 0.0])
        rel = goal - d.xpos[self._shoulder]
        target = (c * rel[0] + s * rel[1], -s * rel[0] + c * rel[1], rel[2])
        arm = offer_posture(env.world, self._i, target=target, palm=self.palm)
        lo, hi = self._lo[self._arm], self._hi[self._arm]
        q = np.clip([arm[n] for n in ARM], lo, hi)
        scratch = self._scratch
        m = env.world.model
        scratch.qpos[:] = d.qpos
        scratch.qpos[self._qadr[self._arm]] = q
        mujoco.mj_kinematics(m, scratch)
        self.palm_residual = float(np.linalg.norm(scratch.site_xpos[self._palm] - goal))
        self.fingertips = self.palm_residual > self.tolerance
        if self.fingertips:   # out of reach with the palm forward: the fingertips onto the palm
            reach_sites(m, scratch, self._qadr[self._arm], self._dadr[self._arm], lo, hi,
                        self._tips, goal, iters=60)
            q = scratch.qpos[self._qadr[self._arm]].copy()
        self.goal = goal
        self.target_angles[self._arm] = q

    def _replan_due(self) -> bool:
        return self._steps % self.replan_steps == 0

    def act(self, env, agent, observation):
        if self._steps and self._replan_due():
            self._plan(env)
        self._steps += 1
        d = env.world.data
        q, qd = d.qpos[self._qadr], d.qvel[self._dadr]
        tau = self._kp * (self.target_angles - q) - self._kd * qd
        tau += d.qfrc_bias[self._dadr] - d.qfrc_spring[self._dadr]
        u = torque_controls(self._act, q, tau).astype(np.float32)
        return motor_action(env.action_space(agent), u)


class ArmSweep(HighFiveController):
    """A hack policy (for baselines): sweeps the right arm back and forth in front of the body
    without looking for the partner's hand, hoping to hit it. The shoulder's horizontal joint
    follows a sine over the middle ``amplitude`` (0.8) of its range at ``sweep_hz`` (1 Hz), the
    shoulder's abduction a sine of half that frequency; the elbow and wrist stay at the middle of
    their ranges; the same PD loop as :class:`HighFiveController` drives the motors."""

    def __init__(self, sweep_hz: float = 1.0, amplitude: float = 0.8, **kwargs):
        super().__init__(**kwargs)
        self.sweep_hz = check_number("ArmSweep", "sweep_hz", sweep_hz, 0.01, 10.0)
        self.amplitude = check_number("ArmSweep", "amplitude", amplitude, 0.0, 1.0)

    def __repr__(self):
        return f"ArmSweep(sweep_hz={self.sweep_hz}, amplitude={self.amplitude})"

    def _plan(self, env) -> None:
        k = self._arm
        lo, hi = self._lo[k], self._hi[k]
        mid, half = 0.5 * (lo + hi), 0.5 * self.amplitude * (hi - lo)
        t = self._steps * env.dt * 2 * np.pi * self.sweep_hz
        q = mid.copy()
        q[0] += half[0] * np.sin(t)          # shoulder horizontal: across the front
        q[1] += half[1] * np.sin(0.5 * t)    # shoulder abduction: up and down, slower
        self.goal = None
        self.target_angles[k] = q

    def _replan_due(self) -> bool:
        return True   # a new target every step
