"""Contact forces and body velocities read from MuJoCo's data for many contacts at once: what
``mujoco.mj_contactForce`` and ``mujoco.mj_comVel`` give one by one, as array operations (the
skin, :mod:`mimo_social.senses.touch`, reads every contact of a step through them)."""

from __future__ import annotations

import mujoco
import numpy as np

__all__ = ["PYRAMIDAL_CONE", "PYRAMID", "SKEW", "AR4", "contact_forces", "body_dofs"]

PYRAMIDAL_CONE = int(mujoco.mjtCone.mjCONE_PYRAMIDAL)
AR3 = np.arange(3)
AR4 = np.arange(4)
#: pyramid edge forces (f0+, f0-, f1+, f1-) -> (normal, f0+ - f0-, f1+ - f1-)
PYRAMID = np.array([[1.0, 1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 0.0, 1.0], [1.0, 0.0, -1.0]])
# cross products as matrix products: a x b = [a]x b, with the 3x3 matrix [a]x = (a @ SKEW)
_LEVI_CIVITA = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _LEVI_CIVITA[_i, _j, _k], _LEVI_CIVITA[_i, _k, _j] = 1.0, -1.0
#: (3, 9): ``(a @ SKEW).reshape(3, 3)`` is the cross-product matrix of ``a``
SKEW = np.transpose(_LEVI_CIVITA, (1, 0, 2)).reshape(3, 9)


def contact_forces(c, ci, ea, efc, pyramidal: bool, all_dim3: bool) -> np.ndarray:
    """(len(ci), 3): normal and two friction forces (contact frame) of the contacts ``ci``
    (``c``: ``data.contact``, ``ea``: their ``efc_address``, ``efc``: ``data.efc_force``): what
    ``mujoco.mj_contactForce`` returns, for all contacts at once. ``all_dim3``: every contact
    has condim 3 (the common case, one gather)."""
    if all_dim3:
        if pyramidal:
            f = efc[ea[:, None] + AR4] @ PYRAMID      # normal, p0 - p1, p2 - p3
            f[:, 1:] *= c.friction[ci, :2]
            return f
        return efc[ea[:, None] + AR3]
    dim = c.dim[ci]
    f = np.zeros((len(ci), 3))
    fr = dim >= 3
    if pyramidal:
        rows = np.where(dim > 1, 2 * (dim - 1), 1)
        width = int(rows.max())
        cols = np.arange(width)
        mask = cols < rows[:, None]
        P = np.where(mask, efc[np.where(mask, ea[:, None] + cols, 0)], 0.0)
        f[:, 0] = P.sum(1)
        if width >= 4:
            mu = c.friction[ci]
            f[fr, 1] = (P[fr, 0] - P[fr, 1]) * mu[fr, 0]
            f[fr, 2] = (P[fr, 2] - P[fr, 3]) * mu[fr, 1]
    else:
        f[:, 0] = efc[ea]
        f[fr, 1] = efc[ea[fr] + 1]
        f[fr, 2] = efc[ea[fr] + 2]
    return f


def body_dofs(m, bodies) -> tuple[np.ndarray, np.ndarray]:
    """The dofs that move each body (its own and its ancestors', in dof order), padded to the
    longest list: (n, D) dof indices (padding 0) and (n, D) 1.0 for a dof, 0.0 for padding. A
    body's com velocity ``cvel`` is the sum of ``cdof * qvel`` over these dofs (as
    ``mj_comVel`` adds them up from the root down)."""
    lists = []
    for b in bodies:
        dofs = []
        while b > 0:
            a = int(m.body_dofadr[b])
            dofs[:0] = range(a, a + int(m.body_dofnum[b])) if a >= 0 else []
            b = int(m.body_parentid[b])
        lists.append(dofs)
    D = max((len(x) for x in lists), default=0)
    idx = np.zeros((len(lists), D), dtype=np.intp)
    on = np.zeros((len(lists), D))
    for i, x in enumerate(lists):
        idx[i, :len(x)] = x
        on[i, :len(x)] = 1.0
    return idx, on
