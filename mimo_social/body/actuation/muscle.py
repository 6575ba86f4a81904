"""Muscle actuation (paper Sec. IV-B): two opposing, independently controlled muscles per axis.

Every actuated joint gets a *negative* muscle (it pulls the joint towards its lower limit) and a
*positive* one (towards the upper limit). Their virtual lengths map the joint range linearly onto
``[LCE_MIN, LCE_MAX]``; a muscle is longest when the joint is at the far end of its range::

    phi_min = lo - q_s,  phi_max = hi - q_s                        (q_s: the spring reference)
    m1 = (LCE_MAX - LCE_MIN) / (phi_max - phi_min) > 0,  L1 = m1 (q - q_s) + LCE_MIN - m1 phi_min
    m2 = -m1,                                            L2 = m2 (q - q_s) + LCE_MIN - m2 phi_max
    dL_i = m_i qdot
    F_i = FL(L_i) FV(dL_i / vmax) a_i + FP(L_i)
    tau = -(m1 F1 fmax_neg + m2 F2 fmax_pos)

``FL`` is MuJoCo's muscle force-length curve, ``FV`` the force-velocity curve (``FVMAX`` when
lengthening fast, 0 at ``-vmax``), ``FP`` the passive force of a stretched muscle (see
:func:`force_length`, :func:`force_velocity`, :func:`force_passive`). ``fmax`` and ``vmax`` are
per axis: the joint tables' values, i.e. the shipped calibrated ones of
``body/data/<hands>_muscles.csv`` (``mimo-social calibrate fmax | vmax --write``), else the
published ones.

**Controls**: ``2 n`` values in [0, 1] for ``n`` axes: first the ``n`` negative muscles, then
the ``n`` positive ones, each block in the order of the agent's motors (``control_names`` spells
it out: ``<joint>-`` then ``<joint>+``).

**Activation**: first order, ``da/dt = (u - a) / TAU`` with ``TAU`` = 10 ms, advanced before
every physics step with the exact solution for a control held over the step,
``a <- u + (a - u) exp(-dt / TAU)``, so the step response reaches 63 % after 10 ms whatever the
timestep (the published explicit Euler step, ``a += dt (u - a) / TAU``, reaches 75 % at 10 ms
with 5 ms physics steps).

**Torque**: written every physics step into ``data.ctrl`` of the joint's motor (gear 1). When the
model binds, the motors' control and force ranges are widened to 2.5 times the muscles' peak
isometric torque (``FL FV <= 1.2``, so muscles never reach them), and the joints keep 5 % of the
spring-damper model's stiffness and damping (the paper retains 5 % of the passive spring-damper;
the muscles' own force-velocity curve and passive force supply the rest). A spring-damper agent
in the same world keeps its joints as they are.

**Observation**: ``[activations (2 n), forces F (2 n)]``, forces as fractions of ``fmax``, both
in the control layout. **Costs** (paper eq. for muscles): ``c = sum(a^2) / N`` and
``c_w = sum(a^2 fmax) / (N sum(fmax))`` over the ``N = 2 n`` muscles.
"""

from __future__ import annotations

import numpy as np

from .base import Actuation

__all__ = ["Muscle", "force_length", "force_velocity", "force_passive", "muscle_parameters",
           "LMIN", "LMAX", "FVMAX", "FPMAX", "LCE_MIN", "LCE_MAX", "TAU", "PASSIVE_FRACTION"]

LMIN, LMAX = 0.5, 1.6          # force-length curve support
FVMAX = 1.2                    # force-velocity plateau when lengthening
FPMAX = 1.3                    # passive force at LMAX
LCE_MIN, LCE_MAX = 0.75, 1.05  # the virtual length spans the joint range within these
TAU = 0.01                     # activation time constant, s
PASSIVE_FRACTION = 0.05        # of the spring-damper model's joint stiffness and damping
RANGE_MARGIN = 2.5             # motor ranges: this times the muscles' peak isometric torque


def _bump(x, a, mid, b):
    """MuJoCo's piecewise-quadratic bump: 0 outside (a, b), 1 at mid."""
    x = np.asarray(x, dtype=float)
    left, right = 0.5 * (a + mid), 0.5 * (mid + b)
    out = np.zeros_like(x)
    r1 = (x > a) & (x < left)
    r2 = (x >= left) & (x < mid)
    r3 = (x >= mid) & (x < right)
    r4 = (x >= right) & (x < b)
    out[r1] = 0.5 * ((x[r1] - a) / (left - a)) ** 2
    out[r2] = 1 - 0.5 * ((mid - x[r2]) / (mid - left)) ** 2
    out[r3] = 1 - 0.5 * ((x[r3] - mid) / (right - mid)) ** 2
    out[r4] = 0.5 * ((b - x[r4]) / (b - right)) ** 2
    return out


def force_length(L):
    """Active force-length curve FL (1 at L = 1)."""
    return _bump(L, LMIN, 1.0, LMAX) + 0.15 * _bump(L, LMIN, 0.5 * (LMIN + 0.95), 0.95)


def force_velocity(V):
    """Force-velocity curve FV of the normalised lengthening speed V = dL / vmax."""
    V = np.asarray(V, dtype=float)
    c = FVMAX - 1.0
    return np.where(V < -1.0, 0.0,
                    np.where(V <= 0.0, (V + 1.0) ** 2,
                             np.where(V <= c, FVMAX - (c - V) ** 2 / c, FVMAX)))


def force_passive(L):
    """Passive force FP of a stretched muscle (0 up to L = 1)."""
    L = np.asarray(L, dtype=float)
    b = 0.5 * (1.0 + LMAX)
    return np.where(L <= 1.0, 0.0,
                    np.where(L <= b, 0.25 * FPMAX * ((L - 1.0) / (b - 1.0)) ** 3,
                             0.25 * FPMAX * (1.0 + 3.0 * (L - b) / (b - 1.0))))


# Lookup tables: linear interpolation on these grids is within 1e-5 of the curves, and one
# np.interp call costs less than the piecewise formulas (small grids search fastest). Outside the
# grids np.interp holds the end values, which are the curves' own (FL = 0, FV = 0 or FVMAX); only
# FP, which grows linearly past L = 1.3, is held from L = 2 (a joint 300 % of its range past a
# limit, which never happens).
_L_GRID = np.linspace(0.4, 2.0, 1601)
_FL_TABLE = force_length(_L_GRID)
_FP_TABLE = force_passive(_L_GRID)
_V_GRID = np.linspace(-1.2, 0.4, 801)
_FV_TABLE = force_velocity(_V_GRID)


def muscle_parameters(joints) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(vmax, fmax_neg, fmax_pos)`` per joint, from the joint tables (which hold the shipped,
    calibrated values of ``body/data/<hands>_muscles.csv``, else the published ones)."""
    out = np.array([(j.vmax, j.fmax_neg, j.fmax_pos) for j in joints], dtype=float).reshape(-1, 3)
    bad = [j.name for j, r in zip(joints, out) if np.isnan(r).any() or (r <= 0).any()]
    if bad:
        raise ValueError(f"muscle parameters missing or not positive for {bad}")
    return out[:, 0], out[:, 1], out[:, 2]


class Muscle(Actuation):
    name = "muscle"
    needs_substep = True

    def __init__(self, joints, actuator_ids, vmax=None, fmax_neg=None, fmax_pos=None):
        """``joints``: JointSpec per motor (action order); ``actuator_ids``: their MuJoCo ids.
        ``vmax``, ``fmax_neg``, ``fmax_pos``: per-axis arrays overriding the shipped values."""
        super().__init__(joints, actuator_ids)
        n = len(self.joints)
        self.n_axes = n
        lo = np.deg2rad([j.range_deg[0] for j in self.joints]).reshape(n)
        hi = np.deg2rad([j.range_deg[1] for j in self.joints]).reshape(n)
        qs = np.deg2rad([j.springref_deg for j in self.joints]).reshape(n)
        phi_min, phi_max = lo - qs, hi - qs
        m1 = (LCE_MAX - LCE_MIN) / (phi_max - phi_min)
        m2 = -m1
        self.moment = np.stack([m1, m2])                                   # (2, n)
        # L = m q + offset, the published L_ref folded together with the spring reference
        self.offset = np.stack([LCE_MIN - m1 * phi_min - m1 * qs, LCE_MIN - m2 * phi_max - m2 * qs])
        self.stiffness = np.array([j.stiffness for j in self.joints], float).reshape(n)
        self.damping = np.array([j.damping for j in self.joints], float).reshape(n)
        self.torque_neg = np.array([j.torque_neg for j in self.joints], float).reshape(n)
        self.torque_pos = np.array([j.torque_pos for j in self.joints], float).reshape(n)
        v, fn, fp = muscle_parameters(self.joints) if n else (np.zeros(0),) * 3
        self.set_parameters(vmax if vmax is not None else v,
                            fmax_neg if fmax_neg is not None else fn,
                            fmax_pos if fmax_pos is not None else fp)
        self._low = np.zeros(2 * n, dtype=np.float32)
        self._high = np.ones(2 * n, dtype=np.float32)
        self.activation = np.zeros((2, n))       # a, rows: negative, positive muscles
        self.force = np.zeros((2, n))            # F (fraction of fmax)
        self.joint_torque = np.zeros(n)           # the last torque written to the motors
        self._u = np.zeros((2, n))
        self._model = None                       # the model whose joints/motors were adapted
        self._data = None                        # the data whose array views are kept
        self._alpha = 0.0

    # -- parameters ------------------------------------------------------------------------------
    def set_parameters(self, vmax=None, fmax_neg=None, fmax_pos=None) -> None:
        """Change vmax / fmax of every axis (calibration); ``None`` keeps a value."""
        n = len(self.joints)
        if vmax is not None:
            self.vmax = np.array(vmax, dtype=float).reshape(n)
        if fmax_neg is not None:
            self.fmax_neg = np.array(fmax_neg, dtype=float).reshape(n)
        if fmax_pos is not None:
            self.fmax_pos = np.array(fmax_pos, dtype=float).reshape(n)
        self.fmax = np.stack([self.fmax_neg, self.fmax_pos])                   # (2, n)
        self._speed = self.moment / self.vmax                                  # dL / vmax per qdot
        self.gain = -self.moment * self.fmax                                   # tau = sum(gain F)
        self._model = None                                                     # re-widen ranges

    def isometric_torque(self, q, activation=1.0) -> tuple[np.ndarray, np.ndarray]:
        """Torques (negative, positive direction) of fully held joints at angles ``q`` (rad)."""
        L = self.moment * np.asarray(q, float) + self.offset
        F = force_length(L) * activation + force_passive(L)
        t = self.gain * F
        return t[0], t[1]

    # -- the interface ---------------------------------------------------------------------------
    @property
    def control_low(self):
        return self._low

    @property
    def control_high(self):
        return self._high

    @property
    def control_names(self) -> list[str]:
        names = [j.name for j in self.joints]
        return [n + "-" for n in names] + [n + "+" for n in names]

    def _bind(self, model) -> None:
        """Adapt this agent's joints and motors in ``model`` (once per model object)."""
        ids = self.actuator_ids
        jnt = model.actuator_trnid[ids, 0]
        self._qadr = model.jnt_qposadr[jnt].astype(np.intp)
        self.dof_adr = model.jnt_dofadr[jnt].astype(np.intp)   # the motors' dof addresses
        model.jnt_stiffness[jnt] = PASSIVE_FRACTION * self.stiffness
        model.dof_damping[self.dof_adr] = PASSIVE_FRACTION * self.damping
        peak = np.abs(self.moment * self.fmax) * (FVMAX + force_passive(LCE_MAX))
        lo, hi = -RANGE_MARGIN * peak[0], RANGE_MARGIN * peak[1]
        model.actuator_ctrlrange[ids] = np.stack([lo, hi], axis=1)
        model.actuator_forcerange[ids] = np.stack([lo, hi], axis=1)
        self._alpha = 1.0 - float(np.exp(-model.opt.timestep / TAU))
        self._model = model

    def apply(self, model, data, controls):
        if model is not self._model:
            self._bind(model)
        u = np.asarray(controls, dtype=float).reshape(2, self.n_axes)
        np.clip(u, 0.0, 1.0, out=self._u)

    def _bind_data(self, data) -> None:
        """Views of ``data``'s arrays and work buffers (MjData arrays never move)."""
        n = self.n_axes
        self._qpos, self._qvel, self._ctrl = data.qpos, data.qvel, data.ctrl
        self._q, self._qd = np.empty(n), np.empty(n)
        self._L, self._V, self._tmp = np.empty((2, n)), np.empty((2, n)), np.empty((2, n))
        self._data = data

    def substep(self, model, data):
        if model is not self._model:
            self._bind(model)
        if data is not self._data:
            self._bind_data(data)
        a, tmp, L, V = self.activation, self._tmp, self._L, self._V
        np.subtract(self._u, a, out=tmp)                # a <- a + (1 - exp(-dt/tau)) (u - a)
        tmp *= self._alpha
        a += tmp
        np.take(self._qpos, self._qadr, out=self._q)    # virtual lengths and speeds
        np.multiply(self.moment, self._q, out=L)
        L += self.offset
        np.take(self._qvel, self.dof_adr, out=self._qd)
        np.multiply(self._speed, self._qd, out=V)
        F = np.interp(L, _L_GRID, _FL_TABLE)             # F = FL FV a + FP
        F *= np.interp(V, _V_GRID, _FV_TABLE)
        F *= a
        F += np.interp(L, _L_GRID, _FP_TABLE)
        self.force = F
        np.multiply(self.gain, F, out=tmp)
        np.add(tmp[0], tmp[1], out=self.joint_torque)
        self._ctrl[self.actuator_ids] = self.joint_torque

    def reset(self, model, data):
        if model is not self._model:
            self._bind(model)
        self.activation[:] = 0.0
        self.force[:] = 0.0
        self._u[:] = 0.0
        self.joint_torque[:] = 0.0
        data.ctrl[self.actuator_ids] = 0.0

    @property
    def observation_size(self):
        return 4 * self.n_axes

    def observation(self, data):
        return np.concatenate([self.activation.ravel(), self.force.ravel()])

    def cost(self, controls):
        a = self.activation
        return float(np.sum(a * a)) / a.size if a.size else 0.0

    def weighted_cost(self, controls):
        a = self.activation
        if not a.size:
            return 0.0
        return float(np.sum(a * a * self.fmax)) / (a.size * float(self.fmax.sum()))

    # -- pickling: the bound model and data never travel --------------------------------------------------
    def __getstate__(self):
        state = self.__dict__.copy()
        state["_model"] = state["_data"] = None
        for key in ("_qpos", "_qvel", "_ctrl"):
            state.pop(key, None)
        return state
