"""Positional actuation: controls are target joint angles, tracked by a torque-limited servo.

MIMo 1.0 (Mattern et al. 2024, ``mimoActuation.actuation.PositionalModel``) locks each joint
onto the commanded angle with an equality constraint, with no torque limit and zero cost. Here
the target is tracked by the joint's own motor instead, within the joint's own torque limits, so
a pose that the infant's strength cannot hold sags, and the effort is measurable.

**Controls**: one value ``u`` in [-1, 1] per motor (the spring-damper's layout), mapped linearly
onto the joint's range: ``q* = lo + (u + 1) (hi - lo) / 2`` (``-1``: the lower limit, ``+1``: the
upper limit, ``0``: mid-range). :func:`positional_controls` turns a posture (joint -> angle)
into these controls.

**Law** (a PD servo inside MuJoCo, acting at every physics step)::

    tau = clip(kp (q* - q) - kv qdot + k_s (q - q_s),  -T_neg, +T_pos)

``T_neg``, ``T_pos``: the joint's maximum voluntary torques (the spring-damper's limits);
``k_s (q - q_s)`` cancels the joint's passive spring (stiffness ``k_s``, reference ``q_s``, kept
in the joint), so without load the joint comes to rest at ``q*`` exactly; the joint's passive
damping stays too. When the model binds, the agent's motors become MuJoCo affine servos: gain
``kp``, bias ``(-k_s q_s, k_s - kp, -kv)``, control range the joint range (rad), force range
``[-T_neg, T_pos]`` (unchanged). ``data.ctrl`` holds ``q*``. A spring-damper or muscle agent in
the same world keeps its motors and joints as they are.

**Gains**, per joint, from its torque and its inertia ``I = 1 / (M^-1)_ii`` at the model's
reference pose (``model.dof_invweight0``: the joint's inertia with every other joint and the
free base free to move, armature included)::

    kp = min(T_mean / SATURATION_ANGLE, (OMEGA_DT / h)^2 I),  kv = 2 ZETA sqrt(kp I)

``T_mean = (T_neg + T_pos) / 2``; the servo reaches full torque at a ``SATURATION_ANGLE``
(0.1 rad) error, unless the stability bound caps it. **Stability**: the stiffness and the damping
of the servo are explicit forces under the world's semi-implicit Euler integrator (only the
joints' passive damping is implicit), which is stable for one joint while
``(w h)^2 + 4 zeta w h < 4`` (``w = sqrt(kp / I)``), i.e. ``w h < 0.83`` at critical damping;
the gains keep ``w h <= OMEGA_DT = 0.4`` (80 rad/s, 12.7 Hz with 5 ms steps), which leaves room
for the coupling of the joints (the largest ``w h`` of the whole body's ``M^-1 K`` is measured in
``tests/body/test_positional.py``) and follows the timestep.

**Observation**: ``[u, torque]`` per motor, ``torque`` the servo's output (``data.actuator_force``,
within the torque limits). **Costs**: those of the spring-damper with ``u`` replaced by the
torque as a fraction of the limit in its direction, ``v = tau / T_dir``: ``c = sum(v^2) / n``,
``c_w = sum(v^2 T_dir) / (n sum T_dir)``, from the torques of the last physics step.
"""

from __future__ import annotations

from typing import Mapping

import mujoco
import numpy as np

from ..postures import POSTURES, posture_joints
from .spring_damper import SpringDamper

__all__ = ["Positional", "positional_controls", "SATURATION_ANGLE", "OMEGA_DT", "ZETA"]

SATURATION_ANGLE = 0.1   # rad: the error at which the servo reaches the joint's mean torque
OMEGA_DT = 0.4           # the servo's natural frequency times the physics timestep, at most
ZETA = 1.0               # damping ratio of the servo (critical)


class Positional(SpringDamper):
    """Target joint angles in [-1, 1] of each range, tracked by a torque-limited PD servo.

    A spring-damper subclass: the same motors, torque limits and ``[u, torque]`` observation
    layout; only what the control means differs."""

    name = "positional"

    def __init__(self, joints, actuator_ids):
        super().__init__(joints, actuator_ids)
        n = len(self.joints)
        self.lo = np.deg2rad([j.range_deg[0] for j in self.joints]).reshape(n)
        self.hi = np.deg2rad([j.range_deg[1] for j in self.joints]).reshape(n)
        self.kp = np.zeros(n)
        self.kv = np.zeros(n)
        self._by_name = {j.name: k for k, j in enumerate(self.joints)}
        self._model = None                     # the model whose motors were made servos
        self._data = None                      # the data whose torques the costs read

    # -- the mapping -----------------------------------------------------------------------------
    def targets(self, u) -> np.ndarray:
        """Target angles (rad) of controls ``u`` in [-1, 1]."""
        u = np.clip(np.asarray(u, float), -1.0, 1.0)
        return self.lo + 0.5 * (u + 1.0) * (self.hi - self.lo)

    def controls_for(self, angles: Mapping[str, float], default=None) -> np.ndarray:
        """Controls that target ``angles`` (joint name -> rad; clipped to each range).

        Motors not named target ``default`` (a control vector; None: every joint's spring
        reference angle, the relaxed pose). Names that are not motors of this agent are left
        to the caller (:func:`positional_controls` checks them)."""
        span = self.hi - self.lo
        if default is None:
            ref = np.deg2rad([j.springref_deg for j in self.joints])
            u = 2.0 * (ref - self.lo) / span - 1.0
        else:
            u = np.array(default, float).reshape(len(self.joints))
        for name, angle in angles.items():
            k = self._by_name.get(name)
            if k is not None:
                u[k] = 2.0 * (float(angle) - self.lo[k]) / span[k] - 1.0
        return np.clip(u, -1.0, 1.0)

    # -- binding: the agent's motors become servos -------------------------------------------------
    def gains(self, model) -> tuple[np.ndarray, np.ndarray]:
        """``(kp, kv)`` per motor for ``model`` (its timestep and the joints' inertias)."""
        dof = model.jnt_dofadr[model.actuator_trnid[self.actuator_ids, 0]]
        inertia = 1.0 / model.dof_invweight0[dof]
        w_max = OMEGA_DT / model.opt.timestep
        t_mean = 0.5 * (self.torque_neg + self.torque_pos)
        kp = np.minimum(t_mean / SATURATION_ANGLE, w_max * w_max * inertia)
        kv = 2.0 * ZETA * np.sqrt(kp * inertia)
        return kp, kv

    def _bind(self, model) -> None:
        ids = self.actuator_ids
        jnt = model.actuator_trnid[ids, 0]
        k_s = model.jnt_stiffness[jnt]
        q_s = model.qpos_spring[model.jnt_qposadr[jnt]]
        self.kp, self.kv = self.gains(model)
        model.actuator_gaintype[ids] = mujoco.mjtGain.mjGAIN_FIXED
        model.actuator_biastype[ids] = mujoco.mjtBias.mjBIAS_AFFINE
        model.actuator_gainprm[ids] = 0.0
        model.actuator_gainprm[ids, 0] = self.kp
        model.actuator_biasprm[ids] = 0.0
        model.actuator_biasprm[ids, 0] = -k_s * q_s
        model.actuator_biasprm[ids, 1] = k_s - self.kp
        model.actuator_biasprm[ids, 2] = -self.kv
        model.actuator_ctrlrange[ids] = np.stack([self.lo, self.hi], axis=1)
        model.actuator_forcerange[ids] = np.stack([-self.torque_neg, self.torque_pos], axis=1)
        self._model = model

    # -- the interface ---------------------------------------------------------------------------
    def apply(self, model, data, controls):
        if model is not self._model:
            self._bind(model)
        self._data = data
        self._u = np.clip(np.asarray(controls, dtype=float), -1.0, 1.0)
        data.ctrl[self.actuator_ids] = self.targets(self._u)

    def reset(self, model, data):
        """Hold the pose the agent is in (not mid-range): the targets are the current angles."""
        if model is not self._model:
            self._bind(model)
        self._data = data
        q = data.qpos[model.jnt_qposadr[model.actuator_trnid[self.actuator_ids, 0]]]
        self._u = np.clip(2.0 * (q - self.lo) / (self.hi - self.lo) - 1.0, -1.0, 1.0)
        data.ctrl[self.actuator_ids] = self.targets(self._u)

    def torque(self, u):
        raise TypeError("positional controls are target angles, not torques; the servo's torques "
                        "are torques(data)")

    def torques(self, data=None) -> np.ndarray:
        """The servo torques of the last physics step (Nm, within the limits)."""
        data = self._data if data is None else data
        if data is None:
            return np.zeros(len(self.joints))
        return data.actuator_force[self.actuator_ids]

    def observation(self, data):
        return np.concatenate([self._u, self.torques(data)])

    def effort(self) -> tuple[np.ndarray, np.ndarray]:
        """``(v, T_dir)``: each torque as a fraction of the limit in its direction, and that limit."""
        tau = self.torques()
        t = np.where(tau >= 0.0, self.torque_pos, self.torque_neg)
        return tau / t, t

    def cost(self, controls):
        v, _ = self.effort()
        return float(v @ v) / v.size if v.size else 0.0

    def weighted_cost(self, controls):
        v, t = self.effort()
        if not v.size:
            return 0.0
        return float((v * v) @ t) / (v.size * float(t.sum()))

    def costs(self, controls):
        v, t = self.effort()
        if not v.size:
            return 0.0, 0.0
        return float(v @ v) / v.size, float((v * v) @ t) / (v.size * float(t.sum()))

    # -- pickling: the bound model and data never travel -------------------------------------------
    def __getstate__(self):
        state = self.__dict__.copy()
        state["_model"] = state["_data"] = None
        return state


def positional_controls(env, agent, pose, degrees: bool = False) -> np.ndarray:
    """The controls of a positional ``agent`` (name or index) of ``env`` that target ``pose``.

    ``pose``: a posture name of :data:`~mimo_social.body.postures.POSTURES` (its joint angles for
    the agent's body, :func:`~mimo_social.body.postures.posture_joints`; the rest at their spring
    reference, as the world places a posture), or a mapping joint name
    -> angle in rad (``degrees=True``: in degrees), e.g. the held angles of a task. Motors not
    named target their spring reference; joints of the body that are not motors of this agent
    (coupled, held or left out of the action) are skipped; names that are not joints of its body
    raise a ValueError. Use it per control step to hold a pose, or with a sequence of poses to
    move through them."""
    names = list(env.possible_agents)
    i = agent if isinstance(agent, (int, np.integer)) and not isinstance(agent, bool) else (
        names.index(agent) if agent in names else None)
    if i is None or not 0 <= i < len(names):
        raise ValueError(f"agent={agent!r} not in this env; allowed: {names} or 0..{len(names) - 1}")
    act = env.actuation[i]
    if not isinstance(act, Positional):
        raise ValueError(f"{names[i]}: actuation={getattr(act, 'name', act)!r}; positional "
                         f"controls need actuation='positional'")
    if isinstance(pose, str):
        if pose not in POSTURES:
            raise ValueError(f"{names[i]}: posture {pose!r} unknown; allowed: {sorted(POSTURES)}")
        pose, degrees = posture_joints(pose, env.world.tables[i].body), True
    if not isinstance(pose, Mapping):
        raise ValueError(f"{names[i]}: pose={pose!r} not allowed; allowed: a posture name "
                         f"{sorted(POSTURES)} or a mapping joint name -> angle")
    known = {j.name for j in env.world.tables[i].joints}
    unknown = sorted(set(pose) - known)
    if unknown:
        raise ValueError(f"{names[i]}: pose names {unknown}, not joints of this body; allowed: "
                         f"its joints, e.g. {act.control_names[:4]}")
    angles = {}
    for k, v in pose.items():
        try:
            a = float(v)
        except (TypeError, ValueError):
            a = np.nan
        if not np.isfinite(a):
            raise ValueError(f"{names[i]}: pose angle of {k} is {v!r}; allowed: a finite number "
                             f"({'degrees' if degrees else 'rad'})")
        angles[k] = np.deg2rad(a) if degrees else a
    return act.controls_for(angles).astype(np.float32)
