"""The contacts of every world at once, as the CPU tasks read them (``data.contact``), for the
batched task logic (:mod:`mimo_social.gpu.tasks`).

MuJoCo Warp keeps the contacts of all worlds in one buffer of ``nconmax * nworld`` rows, the
first ``nacon`` of them in use, each with its world (``worldid``). Every question here is a
mask over that buffer, folded into one answer per world by a scatter (``index_add_``): no
loop over worlds or contacts in Python, no copy to the host.
"""

from __future__ import annotations

import numpy as np

__all__ = ["BatchedContacts"]


class BatchedContacts:
    """The contact buffer of a batched env's data as tensors (views, no copy): ``geom``
    ``(naconmax, 2)``, ``dist``, ``pos`` ``(naconmax, 3)`` (the contact point, world frame),
    ``frame`` ``(naconmax, 3, 3)`` (row 0: the normal, from geom 0 to geom 1), ``worldid``,
    ``efc_address`` ``(naconmax, nmaxpyramid)`` (-1: left out of the constraints);
    ``nacon`` ``(1,)``."""

    def __init__(self, model, data, mjm, nworld: int, wp, mjw, torch, on_device):
        c = data.contact
        self._wp, self._mjw, self._torch = wp, mjw, torch
        self._model, self._data, self._on_device = model, data, on_device
        self.nworld = int(nworld)
        self.ngeom = int(mjm.ngeom)
        self.geom = wp.to_torch(c.geom)
        self.dist = wp.to_torch(c.dist)
        self.pos = wp.to_torch(c.pos)
        self.frame = wp.to_torch(c.frame)
        self.worldid = wp.to_torch(c.worldid)
        self.efc_address = wp.to_torch(c.efc_address)
        self.nacon = wp.to_torch(data.nacon)
        n = int(c.dist.shape[0])
        device = c.dist.device
        self._ids = wp.array(np.arange(n, dtype=np.int32), dtype=int, device=device)
        self._force = wp.zeros(n, dtype=wp.spatial_vector, device=device)
        self.force = wp.to_torch(self._force)
        self.rows = torch.arange(n, device=self.dist.device)

    def mask(self, geoms):
        """A bool tensor over the model's geoms, True at ``geoms`` (ids)."""
        t = self._torch
        m = t.zeros(self.ngeom, dtype=t.bool, device=self.dist.device)
        m[t.as_tensor(np.asarray(geoms, dtype=np.int64), device=m.device)] = True
        return m

    def valid(self):
        """The rows in use this step, ``(naconmax,)`` bool."""
        return self.rows < self.nacon[0]

    def sides(self):
        """Each row's two geoms, clamped into the model's ids (rows not in use: any)."""
        g = self.geom.long().clamp(0, self.ngeom - 1)
        return g[:, 0], g[:, 1]

    def between(self, a, b, touching: bool = True):
        """Rows in use joining a geom of mask ``a`` with one of mask ``b`` (either order),
        ``touching``: only those with ``dist <= 0`` (the CPU tasks' ``ContactProbe``)."""
        g0, g1 = self.sides()
        hit = ((a[g0] & b[g1]) | (a[g1] & b[g0])) & self.valid()
        return hit & (self.dist <= 0.0) if touching else hit

    def per_world(self, rows):
        """``(nworld,)`` bool: whether any row of ``rows`` (a mask over the buffer) is in it."""
        t = self._torch
        w = self.worldid.long().clamp(0, self.nworld - 1)
        out = t.zeros(self.nworld, dtype=t.int32, device=rows.device)
        out.index_add_(0, w, rows.to(t.int32))
        return out > 0

    def distinct_per_world(self, rows, keys, size: int):
        """``(nworld,)``: how many distinct values of ``keys`` (per row, each in ``0 .. size -
        1``, e.g. the other geom's id or its body's) the rows of ``rows`` (a mask) carry in each
        world."""
        t = self._torch
        w = self.worldid.long().clamp(0, self.nworld - 1)
        count = t.zeros(self.nworld * size, dtype=t.int32, device=rows.device)
        count.index_add_(0, w * size + keys, rows.to(t.int32))
        return (count.reshape(self.nworld, size) > 0).sum(1)

    def normal_forces(self):
        """Each row's normal force (N; MuJoCo's ``mj_contactForce``, Warp's ``contact_force``;
        0 for rows not in use or left out of the constraints), ``(naconmax,)``."""
        self.force.zero_()
        with self._on_device():
            self._mjw.contact_force(self._model, self._data, self._ids, False, self._force)
        return self.force[:, 0]

    def in_world(self, per_world_values):
        """``per_world_values`` (``(nworld, ...)``) looked up for each row's world."""
        return per_world_values[self.worldid.long().clamp(0, self.nworld - 1)]
