"""The touch skin on the device: every agent's skin points and their forces in every world at
once, in the CPU sense's layout (:mod:`mimo_social.senses.touch`), for the learners'
``touch`` observation (issue 34).

:class:`BatchedSkin` takes the CPU env's touch system (its skins, concatenated into one set of
arrays: the points, their neighbourhoods, each part's grid) and runs the CPU update's
arithmetic on the batched contacts of all worlds with torch: each contact row in use that the
constraint solver kept is felt by each of its skinned sides; its point, carried along with the
touched body over the last physics step and moved half a spacing outward along the normal, is
looked up in the part's grid; its force (Warp's ``contact_force``, MuJoCo's
``mj_contactForce``) is spread over that cell's neighbourhood with the skin's weights
(``spread_linear`` or ``nearest``) and added into each world's point forces. No loop over
worlds or contacts in Python, no copy to the host.

:class:`BatchedTouchSense` is one agent's ``touch`` observation: its points' normal forces
(``normal_only``) or force vectors in the body or world frame, and its delay, as the CPU sense.
What differs from the CPU: the contacts themselves (Warp's collision routines give some
geom pairs other contact points than C MuJoCo's, docs/gpu.md) and float32 arithmetic; fed the
CPU env's own contacts, the two agree to float32 rounding (tests/gpu/test_gpu_skin.py).
"""

from __future__ import annotations

import numpy as np

from ..senses.skin import GRID_CELL
from ..senses.touch import LOOKUP_SHIFT
from .delay_ring import DelayRing

__all__ = ["BatchedSkin", "BatchedTouchSense", "contact_rows"]


def contact_rows(batched) -> dict:
    """The batched contacts of ``batched`` (a :class:`~mimo_social.gpu.BatchedEnv`) as the
    tensors :meth:`BatchedSkin.feel` takes: ``geom`` ``(R, 2)``, ``pos`` ``(R, 3)``, ``frame``
    ``(R, 3, 3)``, ``force`` ``(R, 3)`` (on geom 1, in the contact frame), ``world`` ``(R,)``
    and ``kept`` ``(R,)`` (in use and in the constraints)."""
    c = batched.contacts
    t = batched.torch
    kept = c.valid() & (c.efc_address[:, 0] >= 0)
    c.normal_forces()                          # fills c.force: (R, 6), the first 3 forces
    return {"geom": c.geom.long(), "pos": c.pos, "frame": c.frame, "force": c.force[:, :3],
            "world": c.worldid.long().clamp(0, batched.nworld - 1), "kept": kept.to(t.bool)}


class BatchedSkin:
    """The skins of every agent with touch in ``nworld`` worlds: ``system`` is the CPU env's
    touch system (:class:`~mimo_social.senses.touch.TouchSystem`), ``model`` its MuJoCo model.
    :attr:`acc` ``(nworld, N + 1, 4)``: per world and skin point (global numbering; row N the
    sink of padded neighbours) the force x, y, z in its agent's output frame and the normal
    force, as of the last :meth:`feel`."""

    def __init__(self, system, model, nworld: int, torch, device):
        self._torch = torch
        self.nworld = int(nworld)
        self.n_points = int(system.n_points)
        as_t = lambda x, kind=torch.float32: torch.as_tensor(np.asarray(x), dtype=kind,  # noqa
                                                             device=device)
        # the CPU system's concatenated arrays (senses/touch.py, TouchSystem.concatenate)
        self.geom_part = as_t(system.geom_part, torch.int64)       # (ngeom + 1,), -1: no skin
        self.part_grid = as_t(system.part_grid)
        self.part_ints = as_t(system.part_ints, torch.int64)
        self.part_world = as_t(system.part_world, torch.bool)
        self.part_nearest = as_t(system.part_nearest, torch.bool)
        self.nbr = as_t(system.nbr, torch.int64)                   # (N, K)
        self.grid = as_t(system.grid, torch.int64)
        self.scaled = as_t(system.scaled.T)                        # (N + 1, 3), in grid cells
        self.ngeom = int(model.ngeom)
        self.timestep = float(model.opt.timestep)
        #: the reading of the CPU env's state as given (its reset): what :meth:`reset` puts back
        self.start = as_t(self.reading(system))
        self.acc = self.start.expand(self.nworld, -1, -1).clone()

    # -- resets ----------------------------------------------------------------------------------
    @staticmethod
    def reading(system) -> np.ndarray:
        """The CPU system's point forces as one world's row of :attr:`acc` ``(N + 1, 4)``
        (what a world loaded from that state starts with)."""
        n = system.n_points + 1
        acc = np.asarray(system.acc, dtype=np.float64)
        return np.concatenate([acc[:3 * n].reshape(n, 3), acc[3 * n:, None]], axis=1)

    def reset(self, worlds=None) -> None:
        """``worlds`` (a bool mask; None: all) back to the reset state's reading."""
        if worlds is None:
            self.acc[:] = self.start
        else:
            self.acc[worlds] = self.start

    def load(self, idx, readings) -> None:
        """Worlds ``idx`` (an int64 tensor) given the readings ``(len(idx), N + 1, 4)``."""
        self.acc[idx] = self._torch.as_tensor(readings, device=self.acc.device).to(
            self.acc.dtype)

    # -- the update ------------------------------------------------------------------------------
    def feel(self, rows: dict, data: dict, h: float | None = None) -> None:
        """The point forces of every world from the contact ``rows`` (:func:`contact_rows`)
        and the batched ``data`` tensors (``qvel``, ``cdof``, ``subtree_com``, ``xpos``,
        ``xmat``); ``h``: the last physics step's length over which each contact point is
        carried along with its body (None: the model's timestep; 0: none, as after a reset)."""
        t = self._torch
        h = self.timestep if h is None else float(h)
        self.acc.zero_()
        geom = rows["geom"]
        g = t.where((geom >= 0) & (geom < self.ngeom), geom, t.full_like(geom, self.ngeom))
        gp = self.geom_part[g]                                     # (R, 2)
        felt = (gp >= 0) & rows["kept"][:, None]
        ci, side = felt.nonzero(as_tuple=True)                     # one row a skinned side
        if not len(ci):
            return
        part = gp[ci, side]
        world = rows["world"][ci]
        sign = (2.0 * side - 1.0).to(t.float32)[:, None, None]     # geom 1: -1, geom 2: +1
        frame = rows["frame"][ci].to(t.float32) * sign             # (S, 3, 3), rows n, t1, t2
        f = rows["force"][ci].to(t.float32)                        # (S, 3), contact frame
        shift = (-LOOKUP_SHIFT / GRID_CELL) * frame[:, 0]                # outward, in grid cells
        force = t.einsum("sj,sjk->sk", f, frame)                   # the side's force, world
        ints = self.part_ints[part]            # body, root, cell strides (3), first cell, dofs
        prm = self.part_grid[part]             # 1/(s GRID_CELL), origin (3), top cell (3), dofs
        body = ints[:, 0]
        pos = rows["pos"][ci].to(t.float32)
        if h > 0.0:                            # carried along over the last physics step
            dofs = ints[:, 6:]
            q = data["qvel"][world[:, None], dofs].to(t.float32) * prm[:, 7:]
            cv = t.einsum("sd,sdk->sk", q, data["cdof"][world[:, None], dofs].to(t.float32))
            arm = pos - data["subtree_com"][world, ints[:, 1]].to(t.float32)
            pos = pos + h * (cv[:, 3:] + t.linalg.cross(cv[:, :3], arm))
        R = data["xmat"][world, body].to(t.float32).reshape(-1, 3, 3)
        rel = pos - data["xpos"][world, body].to(t.float32)
        # rows in the body frame: the point, the shift, the force
        B = t.einsum("snj,sjk->snk", t.stack([rel, shift, force], 1), R)
        qs = B[:, 0] * prm[:, :1]                                  # the point in grid cells
        x = t.minimum(t.maximum(qs + B[:, 1] - prm[:, 1:4], t.zeros_like(qs)), prm[:, 4:7])
        flat = (x.long() * ints[:, 2:5]).sum(1) + ints[:, 5]
        nb = self.nbr[self.grid[flat]]                             # (S, K)
        d = (self.scaled[nb] - qs[:, None, :]).norm(dim=2)         # in grid cells
        w = (1.0 - 0.5 * GRID_CELL * d).clamp(min=0.0)
        nearest = t.nn.functional.one_hot(d.argmin(1), d.shape[1]).to(w.dtype)
        w = t.where(self.part_nearest[part][:, None], nearest, w)
        total = w.sum(1)
        lone = total <= 0.0                                        # no point within 2 s
        w = t.where(lone[:, None], nearest, w)
        total = t.where(lone, t.ones_like(total), total)
        xyz = t.where(self.part_world[part][:, None], force, B[:, 2])
        out = t.cat([xyz, f[:, :1]], 1) / total[:, None]           # (S, 4)
        spread = (w[:, :, None] * out[:, None, :]).reshape(-1, 4)
        slot = (world[:, None] * (self.n_points + 1) + nb).reshape(-1)
        self.acc.view(-1, 4).index_add_(0, slot, spread)


class BatchedTouchSense:
    """One agent's ``touch`` observation from a :class:`BatchedSkin`: ``sense`` is the CPU
    env's touch sense of the agent (its config and points), ``delay`` its delay in control
    steps (the reading of ``delay`` steps before; the reading at reset until then)."""

    name = "touch"

    def __init__(self, skin: BatchedSkin, sense, delay: int, nworld: int, torch, device):
        self._torch = torch
        self.skin = skin
        self.start, self.stop = sense.start, sense.stop
        self.normal_only = bool(sense.config.normal_only)
        n = self.stop - self.start
        self.size = n if self.normal_only else 3 * n
        self.delay = int(delay)
        self.ring = DelayRing(delay, nworld, self.size, torch, device)

    def read(self, data=None):
        """This step's reading, ``(nworld, size)`` float32 (a pressing force is >= 0)."""
        rows = self.skin.acc[:, self.start:self.stop]
        if self.normal_only:
            return rows[:, :, 3].clamp(min=0.0)
        return rows[:, :, :3].reshape(rows.shape[0], -1).clone()

    def reset(self, data, worlds=None):
        """The reading at reset in every slot of the delay ring (``worlds``: a bool mask of the
        worlds reset; None: all); returns the observation."""
        return self.ring.reset(self.read(), worlds)

    def observe(self, data):
        """This step's observation: the reading of ``delay`` steps before."""
        return self.ring.push(self.read())
