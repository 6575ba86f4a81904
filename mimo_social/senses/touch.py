"""Touch (paper Sec. V-C): a full-body skin of force sensors on every infant, infant-to-infant too.

Turn it on with ``touch=True`` or a mapping of :class:`TouchConfig`
settings (``density``, ``response``, ``frame``, ``normal_only``, ``exclude``, ``cache``), for all
agents or per agent (``per_agent=[...]``).

Observation ``touch`` (flat float32)
    The skin points of every skinned body part, part after part in model body order (see
    :meth:`TouchSystem.layout`); per point the force the touching thing exerts on the skin there,
    3 floats (x, y, z) in the part's body frame (``frame="body"``, default) or the world frame
    (``frame="world"``), or 1 float, the normal (pressing) force, with ``normal_only=True``
    (>= 0: the Box's lower bound; force vectors are unbounded).
    A pressing force points into the body, against the point's outward normal.

How a contact is felt
    Every MuJoCo contact that has a skinned geom on either side is read once per control step
    (after the physics, before any agent observes), for all agents at once. Its force (normal and
    friction, in the contact frame, decoded from ``data.efc_force`` exactly as
    ``mujoco.mj_contactForce`` does) is felt by each skinned side, with the sign for that side: a
    contact between two skinned bodies (self-touch, two infants) is felt by both. Each contact
    point, in the touched part's body frame and moved half a spacing outward along the contact
    normal (so on a thin part it stays on the touched side), is looked up in the part's
    precomputed grid, which names a skin point next to it; the force is spread over that point's
    precomputed surface neighbourhood (:mod:`.skin`), so it never bleeds through a thin part.
    All of it is array operations over all contacts at once (no Python loop over contacts or
    points):

    * ``spread_linear`` (default, the published response): weight ``max(0, (2s - d) / (2s))`` of
      each neighbour at straight-line distance d from the contact (s: the part's spacing),
      normalised to sum 1: the summed normal force over the points equals the contact's normal
      force, and the friction is spread with the same weights (a contact farther than 2 s from
      every point lands on the nearest one);
    * ``nearest``: all of the force on the nearest point of the neighbourhood.

    Where the reach 2 s exceeds a part's thickness (low densities), force that wraps round the
    part's rim within that reach over the surface is felt on the far side near the rim, as the
    published breadth-first search allows; straight through the part it is not.

    ``mj_step`` leaves contacts at the positions before its last integration while the world
    brings body poses up to date after stepping; each contact point is carried along with its
    body over that last step (the body velocities ``mujoco.mj_comVel`` would compute, summed from
    ``cdof`` and ``qvel``; ``data`` is only read) before it is placed on the skin.

Infos
    ``infos[agent]["touch"]``: per body part touched this step (unprefixed name, parts in contact
    only), who touches it: ``{"self": bool, "agents": [names], "object": bool}``; a geom of another
    agent names that agent, a geom of the same agent is ``self``, a world or prop geom (the floor
    too) is ``object``.

For people
    :meth:`TouchSystem.view` gives per part the points, normals and forces in world coordinates;
    :func:`save_skin_png` draws one agent's skin coloured by force (paper Fig. 5b);
    ``mimo-social figure skin-hand-ball out.png`` draws a hand holding a ball
    (:mod:`mimo_social.figures`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import partial
from typing import Sequence

import mujoco
import numpy as np
from gymnasium import spaces

from ..util.checks import (ConfigError, check_bool, check_choice, check_names,
                           check_number)
from ..util.names import reject_old_names
from .base import SenseEntry
from .contact_forces import AR4, PYRAMID, PYRAMIDAL_CONE, SKEW, body_dofs, contact_forces
from .skin import GRID_CELL, Skin, build_skin

__all__ = ["TouchConfig", "build_touch", "TouchSystem", "AgentTouch", "save_skin_png", "SENSE",
           "RESPONSES", "FRAMES"]

RESPONSES = ("spread_linear", "nearest")
FRAMES = ("body", "world")


@dataclass(frozen=True)
class TouchConfig:
    """The full-body skin: sensor points over every body part, each sensing a force vector.

    ``density`` multiplies the published per-part point density (spacing / sqrt(density));
    ``exclude`` lists body parts without skin; ``response`` spreads each contact over nearby
    points; ``frame`` is the frame of the force vectors; ``normal_only`` keeps 1 value a point.
    """

    density: float = 1.0   # times the published points per area (spacing / sqrt(density))
    response: str = "spread_linear"   # how a contact spreads over the points near it
    frame: str = "body"    # the frame of the force vectors: the body part's or the world
    normal_only: bool = False   # one value a point, the pressing force, not 3
    exclude: tuple[str, ...] = ()   # body parts without skin
    cache: bool = True     # read and write the built skin in the disk cache

    def __post_init__(self):
        put = partial(object.__setattr__, self)
        put("density", check_number("touch", "density", self.density, 0.05, 8.0))
        check_choice("touch", "response", self.response, RESPONSES)
        check_choice("touch", "frame", self.frame, FRAMES)
        put("normal_only", check_bool("touch", "normal_only", self.normal_only))
        put("exclude", check_names("touch", "exclude", self.exclude, "body part names"))
        put("cache", check_bool("touch", "cache", self.cache))


LOOKUP_SHIFT = 0.5   # a contact is looked up this many spacings outward along its normal
_SIGN3 = np.array([-1.0, 1.0]).reshape(2, 1, 1)   # per side: geom1, geom2
_SHIFT_ROW = np.array([-LOOKUP_SHIFT / GRID_CELL, 0.0, 0.0])   # in the contact frame, in cells


class AgentTouch:
    """One agent's touch sense: reads its slice of the shared :class:`TouchSystem`."""

    name = "touch"

    def __init__(self, system: "TouchSystem", agent: int):
        self.system = system
        self.agent = agent
        self.config = system.configs[agent]
        self.skin = system.skins[agent]
        self.start, self.stop = system.agent_slices[agent]
        n = self.stop - self.start
        size = n if self.config.normal_only else 3 * n
        # a normal (pressing) force is >= 0; force vectors point any way
        low = 0.0 if self.config.normal_only else -np.inf
        self.space = spaces.Box(low, np.inf, (size,), np.float32)
        self.spaces = {self.name: self.space}
        # where this agent's values lie in the system's force array (see TouchSystem.force_xyz,
        # force_normal): x, y, z of its points, or their normal forces
        n0 = 3 * (system.n_points + 1) + self.start
        self._span = (n0, n0 + n) if self.config.normal_only else (3 * self.start, 3 * self.stop)

    @property
    def n_points(self) -> int:
        return self.stop - self.start

    def observe(self, model, data, out: dict) -> None:
        out[self.name] = self.read()

    def read(self) -> np.ndarray:
        """This agent's ``touch`` vector as of the last update (a new float32 array)."""
        a, b = self._span
        values = self.system.acc[a:b]       # (one call each step: no view property)
        if self.config.normal_only:          # (>= 0: a -0.0 or rounding below 0 reads 0)
            return np.maximum(values, 0.0, out=np.empty(b - a, np.float32))
        return values.astype(np.float32)

    def info(self) -> dict:
        return {"touch": self.system.touched_by(self.agent)}

    def info_spec(self) -> dict:
        """``infos["touch"]`` is a touch info (numeric views count its parts)."""
        return {"touch": "touch"}


class TouchSystem:
    """The skins of all agents with touch, updated once per control step from the contacts."""

    name = "touch"

    def __init__(self, world, configs: Sequence[TouchConfig | None]):
        m = world.model
        self.world = world
        self.names = list(world.names)
        self.configs = list(configs)
        self.skins: list[Skin | None] = []
        t0 = time.perf_counter()
        for i, cfg in enumerate(configs):
            if cfg is None:
                self.skins.append(None)
                continue
            agent = world.agents[i]
            spacing = world.tables[i].touch_spacing
            prefix = f"{world.names[i]}/"
            known = sorted({m.body(int(b)).name[len(prefix):] for b in agent.body_ids
                            if m.body_geomnum[b] > 0})
            bad = [p for p in cfg.exclude if p not in known]
            if bad:
                raise ConfigError(f"agent {world.names[i]}: touch: exclude={list(cfg.exclude)} "
                                  f"names unknown body part(s) {bad}; known parts: {known}")
            if set(known) <= set(cfg.exclude):
                raise ConfigError(f"agent {world.names[i]}: touch: exclude removes every body "
                                  "part; use touch=False to turn touch off")
            self.skins.append(build_skin(m, agent.body_ids, prefix, spacing, cfg.density,
                                         cfg.exclude, cfg.cache, world.tables[i].scale))
        self.concatenate(m)
        self.build_seconds = time.perf_counter() - t0
        self.reset(m, world.data)

    # -- building --------------------------------------------------------------------------------
    def concatenate(self, m):
        """All agents' skins as one set of arrays (global point and part numbers); again after
        a skin of :attr:`skins` was replaced by one of as many points (an age change)."""
        pts, nrm, scaled, nbr, parts, grids = [], [], [], [], [], []
        part_body, part_agent, part_s, part_start, part_world, part_nearest = [], [], [], [], [], []
        params = []
        self.part_names: list[str] = []
        self.agent_slices: list[tuple[int, int]] = []
        self.agent_parts: list[range] = []
        geom_part = np.full(m.ngeom, -1, dtype=np.intp)
        skins = [(i, sk) for i, sk in enumerate(self.skins) if sk is not None]
        N = sum(sk.n_points for _, sk in skins)      # row N: a sink for padded neighbours
        n0 = cells0 = 0
        for i, skin in enumerate(self.skins):
            if skin is None:
                self.agent_slices.append((n0, n0))
                self.agent_parts.append(range(len(part_body), len(part_body)))
                continue
            cfg = self.configs[i]
            p0 = len(part_body)
            for k, name in enumerate(skin.part_names):
                part_body.append(int(skin.part_bodies[k]))
                part_agent.append(i)
                part_s.append(float(skin.part_spacing[k]))
                part_start.append(n0 + int(skin.part_start[k]))
                part_world.append(cfg.frame == "world")
                part_nearest.append(cfg.response == "nearest")
                self.part_names.append(name)
                geom_part[skin.part_geoms[k]] = p0 + k
                dims = skin.grid_dims[k]
                strides = np.array([dims[1] * dims[2], dims[2], 1], float)
                params.append(np.concatenate([[1.0 / skin.part_spacing[k]], skin.grid_lo[k],
                                              dims - 1.0, strides,
                                              [cells0 + skin.grid_start[k]]]))
            s = skin.part_spacing[skin.point_part][:, None]
            pts.append(skin.points)
            nrm.append(skin.normals)
            scaled.append(skin.points / s)
            nb = skin.nbr.astype(np.intp) + n0
            nb[~np.isfinite(skin.nbr_dist)] = N
            nbr.append(nb)
            parts.append(skin.point_part + p0)
            grids.append(skin.grid.astype(np.intp) + n0)
            self.agent_slices.append((n0, n0 + skin.n_points))
            self.agent_parts.append(range(p0, len(part_body)))
            n0 += skin.n_points
            cells0 += len(skin.grid)
        self.n_points = N
        part_start.append(N)
        K = max(a.shape[1] for a in nbr)
        self.points = np.concatenate(pts)
        self.normals = np.concatenate(nrm)
        # the points in grid cells (GRID_CELL spacings), coordinate after coordinate (3, N + 1)
        # so that the per-contact arithmetic runs along the neighbours; point N lies far away
        self.scaled = np.ascontiguousarray(
            np.concatenate(scaled + [np.full((1, 3), 1e9)]).T * (1.0 / GRID_CELL))
        self.nbr = np.concatenate([np.pad(a, ((0, 0), (0, K - a.shape[1])), constant_values=N)
                                   for a in nbr])
        self.point_part = np.concatenate(parts)
        self.grid = np.concatenate(grids)
        self.part_body = np.array(part_body, dtype=np.intp)
        self.part_root = m.body_rootid[self.part_body].astype(np.intp)
        self.part_agent = np.array(part_agent, dtype=np.intp)
        self.part_spacing = np.array(part_s)
        self.part_start = np.array(part_start, dtype=np.intp)
        self.part_world = np.array(part_world, bool)
        self.part_nearest = np.array(part_nearest, bool)
        # per part: 1 / spacing, grid origin (3), largest cell (3), cell strides (3), first cell
        self.part_params = np.array(params)
        # the same for the update (and the device's skin), a row a part: numbers (1 / (spacing
        # GRID_CELL), grid origin, largest cell, in grid cells; 1 for each dof that moves the
        # part, 0 for padding), integers (body, root, cell strides, first cell, those dofs)
        dofs, on = body_dofs(m, self.part_body)
        self.part_grid = np.concatenate(
            [self.part_params[:, :7] * ([1.0 / GRID_CELL] * 4 + [1.0] * 3), on], axis=1)
        self.part_ints = np.concatenate([self.part_body[:, None], self.part_root[:, None],
                                         self.part_params[:, 7:].astype(np.intp), dofs], axis=1)
        # one more entry, -1, so that the geom id -1 of a flex contact reads as "no skin", "world"
        self.geom_part = np.append(geom_part, -1)
        self.geom_agent = np.append(np.asarray(self.world.geom_agent, dtype=np.intp), -1)
        self._any_world = bool(self.part_world.any())
        self._all_world = bool(self.part_world.all())
        self._any_nearest = bool(self.part_nearest.any())
        # the forces of all points, one flat array, public for the agents' senses to read (never
        # written but by update/reset): [x, y, z of point 0, 1, ..., N | normal force of point
        # 0, 1, ..., N]; point N is the sink of padded neighbours. Per point, the four places it
        # owns in that array:
        self.acc = np.zeros(4 * (N + 1))
        p = np.arange(N + 1)
        self._slots = np.stack([3 * p, 3 * p + 1, 3 * p + 2, 3 * (N + 1) + p], axis=1)
        self._touched = None
        # every contact has 3 rows (pyramidal: 4) when every geom has condim 3 and no pairs
        self._all_dim3 = m.npair == 0 and bool(np.all(m.geom_condim == 3))

    # -- the shared-system interface -------------------------------------------------------------
    def reset(self, model, data) -> None:
        self.acc[:] = 0.0
        self._touched = None
        self._just_reset = True   # the next update reads contacts of mj_forward: no integration
        self._clear()

    def _clear(self):
        if self._touched is not None:   # zero only what the last update wrote
            self.acc[self._touched] = 0.0
            self._touched = None
        self._sides = None
        self._info = {}

    @property
    def _xyz(self) -> np.ndarray:
        return self.acc[:3 * (self.n_points + 1)]

    @property
    def _normal(self) -> np.ndarray:
        return self.acc[3 * (self.n_points + 1):]

    @property
    def force_xyz(self) -> np.ndarray:
        """(3 N,) per point force x, y, z in its agent's output frame (read-only view)."""
        v = self._xyz[:3 * self.n_points]
        v.flags.writeable = False
        return v

    @property
    def force_normal(self) -> np.ndarray:
        """(N,) per point normal force (read-only view)."""
        v = self._normal[:self.n_points]
        v.flags.writeable = False
        return v

    def update(self, model, data) -> None:
        """Read the contacts once and compute every agent's point forces.

        Each numpy call costs a microsecond or two, whatever the size, for the few contacts of
        a step, so the work is a short, fixed sequence of calls over all contacts at once:
        ``take`` rather than fancy indexing, in-place ufuncs, one table row a part, lengths in
        grid cells (no rescaling) and the neighbours of a contact as the inner (long) axis."""
        if self._touched is not None:                    # zero only what the last update wrote
            self.acc[self._touched] = 0.0
            self._touched = None
        self._sides = None
        self._info = {}
        opt = model.opt
        h = 0.0 if self._just_reset else opt.timestep
        self._just_reset = False
        if data.ncon == 0:
            return
        c = data.contact
        geom = c.geom.ravel()                            # geom1, geom2 of each contact
        gp = self.geom_part.take(geom)
        sides = (gp >= 0).nonzero()[0]                   # one row per skinned side of a contact
        if not len(sides):
            return
        ci = sides >> 1
        ea = c.efc_address.take(ci)
        if ea.min() < 0:                                 # contacts MuJoCo left out (no dofs ...)
            keep = ea >= 0
            sides, ci, ea = sides[keep], ci[keep], ea[keep]
            if not len(sides):
                return
        S = len(sides)
        # rows, in the contact frame: the grid look-up's shift (LOOKUP_SHIFT spacings along the
        # normal n, geom1 -> geom2, in grid cells) and the force on geom2
        F = np.empty((S, 2, 3))
        F[:, 0] = _SHIFT_ROW
        efc = data.efc_force
        pyramidal = opt.cone == PYRAMIDAL_CONE               # (read each step: it may change)
        if self._all_dim3 and pyramidal:                 # as mj_contactForce does
            f = F[:, 1]
            np.matmul(efc.take(ea[:, None] + AR4), PYRAMID, out=f)   # normal, p0-p1, p2-p3
            f[:, 1:] *= c.friction.take(ci, 0)[:, :2]
        else:
            F[:, 1] = f = contact_forces(c, ci, ea, efc, pyramidal, self._all_dim3)
        part = gp.take(sides)
        ints = self.part_ints.take(part, 0)             # body, root, cell strides, first cell
        body = ints[:, 0]
        # the same rows in the world frame, for the touched side: geom2 feels +F and its skin's
        # outward normal is -n, geom1 feels -F and has +n: the contact frame times the sign
        frame = c.frame.take(ci, 0).reshape(S, 3, 3)
        frame *= _SIGN3.take(sides, 0, mode="wrap")      # sides & 1: 0 geom1 (-), 1 geom2 (+)
        V = np.empty((S, 3, 3))                          # point (to be made relative), shift, force
        V[:, 0] = c.pos.take(ci, 0)
        np.matmul(F, frame, out=V[:, 1:])
        prm = self.part_grid.take(part, 0)
        if h > 0.0:
            # carry the contact point along with its body over the last physics step: the
            # bodies moved by h times their velocities of now (semi-implicit Euler), expressed in
            # the com frames of the contacts' time (``cdof``, ``subtree_com`` are still those):
            # the body's cvel as mj_comVel computes it, sum of cdof * qvel over its dofs
            # (MjData is only read)
            dofs = ints[:, 6:]
            q = data.qvel.take(dofs)
            q *= prm[:, 7:]                              # padding: 0
            cv = (q[:, None, :] @ data.cdof.take(dofs, 0))[:, 0]   # [angular; linear at com]
            arm = V[:, 0] - data.subtree_com.take(ints[:, 1], 0)
            spin = (cv[:, :3] @ SKEW).reshape(S, 3, 3)  # [w]x
            V[:, 0] += h * (cv[:, 3:] + (spin @ arm[:, :, None])[:, :, 0])
        V[:, 0] -= data.xpos.take(body, 0)
        B = V @ data.xmat.take(body, 0).reshape(S, 3, 3)  # the same rows in the body frame
        # the contact point in grid cells, and the cell of the point moved outward: clipped to
        # the part's grid, then truncated (= rounded down, as it is >= 0)
        qs = B[:, 0] * prm[:, :1]
        x = qs + B[:, 1]
        x -= prm[:, 1:4]
        np.maximum(x, 0.0, out=x)
        np.minimum(x, prm[:, 4:7], out=x)
        cell1 = np.empty((S, 4), np.intp)                # (cell x, y, z, 1)
        cell1[:, :3] = x
        cell1[:, 3] = 1
        flat = (cell1[:, None, :] @ ints[:, 2:6, None]).ravel()    # . (strides, first cell)
        nb = self.nbr.take(self.grid.take(flat), 0)      # (S, K) the cell's neighbourhood
        # distances (in grid cells) from the contact to the neighbours, coordinate by coordinate
        diff = self.scaled.take(nb, 1)                   # (3, S, K)
        diff -= qs.T[:, :, None]
        diff *= diff
        d = np.add.reduce(diff, 0)
        np.sqrt(d, out=d)
        w = d * (-0.5 * GRID_CELL)
        w += 1.0
        np.maximum(w, 0.0, out=w)                        # max(0, 1 - distance / 2 spacings)
        if self._any_nearest:
            near = self.part_nearest.take(part).nonzero()[0]
            if len(near):
                w[near] = 0.0
                w[near, d[near].argmin(1)] = 1.0
        total = np.add.reduce(w, 1)
        if total.min() <= 0.0:                           # no point within 2 s: the nearest
            lone = (total <= 0.0).nonzero()[0]
            w[lone, d[lone].argmin(1)] = 1.0
            total[lone] = 1.0
        # per side: force (output frame) and normal force, divided by the summed weights
        out = np.empty((S, 4))
        np.divide(V[:, 2] if self._all_world else B[:, 2], total[:, None], out=out[:, :3])
        if self._any_world and not self._all_world:
            world = self.part_world.take(part).nonzero()[0]
            out[world, :3] = V[world, 2] / total[world, None]
        np.divide(f[:, 0], total, out=out[:, 3])
        # added up: only the neighbours with weight (a third or so of them)
        w = w.ravel()
        on = w.nonzero()[0]
        slots = self._slots.take(nb.ravel().take(on), 0).ravel()   # 4 places a point
        np.add.at(self.acc, slots, (w.take(on)[:, None] * out.take(on // nb.shape[1], 0)).ravel())
        self._touched = slots
        self._sides = (part, geom.take(sides ^ 1), f[:, 0])

    # -- who touches what ------------------------------------------------------------------------
    def touched_by(self, agent: int) -> dict:
        """Per touched body part of ``agent``: whether itself, other agents, objects touch it.

        Worked out for every agent at the first call after an update (one pass over the
        contacts), then read from there."""
        if self._sides is None:
            return {}
        if not self._info:
            part, other, fn = self._sides
            info: dict = {i: {} for i, sk in enumerate(self.skins) if sk is not None}
            names, part_names = self.names, self.part_names
            for p, owner, src, f in zip(part.tolist(), self.part_agent.take(part).tolist(),
                                        self.geom_agent.take(other).tolist(), fn.tolist()):
                if f <= 0.0:
                    continue
                entry = info[owner].get(part_names[p])
                if entry is None:
                    entry = info[owner][part_names[p]] = {"self": False, "agents": [],
                                                          "object": False}
                if src < 0:
                    entry["object"] = True
                elif src == owner:
                    entry["self"] = True
                elif names[src] not in entry["agents"]:
                    entry["agents"].append(names[src])
            for parts in info.values():
                for entry in parts.values():
                    if len(entry["agents"]) > 1:
                        entry["agents"].sort()
            self._info = info
        return self._info.get(agent, {})

    # -- for people ------------------------------------------------------------------------------
    def _agent_index(self, agent) -> int:
        if isinstance(agent, str):
            if agent not in self.names:
                reject_old_names(agent, self.names)
                raise KeyError(f"unknown agent {agent!r}; agents: {self.names}")
            agent = self.names.index(agent)
        if self.skins[agent] is None:
            raise ValueError(f"{self.names[agent]} has no touch skin (touch is off for it)")
        return int(agent)

    def layout(self, agent) -> dict[str, tuple[int, int]]:
        """Per body part of ``agent``: (first, last + 1) point index in its ``touch`` vector
        (3 floats a point, or 1 with ``normal_only``)."""
        i = self._agent_index(agent)
        a0 = self.agent_slices[i][0]
        return {self.part_names[p]: (int(self.part_start[p] - a0), int(self.part_start[p + 1] - a0))
                for p in self.agent_parts[i]}

    def counts(self, agent) -> dict[str, int]:
        """Number of skin points per body part of ``agent``."""
        return {k: b - a for k, (a, b) in self.layout(agent).items()}

    def view(self, agent, data: mujoco.MjData | None = None) -> dict[str, dict]:
        """Per body part of ``agent``: ``points`` and ``normals`` (n, 3) in world coordinates,
        ``forces`` (n, 3) world frame, ``normal_force`` (n,), ``local_points`` and
        ``local_forces`` (n, 3) in the part's body frame, and ``spacing`` (m), as of the last
        update."""
        i = self._agent_index(agent)
        d = self.world.data if data is None else data
        xyz = self.force_xyz[:3 * self.n_points].reshape(-1, 3)
        out = {}
        for p in self.agent_parts[i]:
            a, b = self.part_start[p], self.part_start[p + 1]
            body = self.part_body[p]
            R = d.xmat[body].reshape(3, 3)
            f = xyz[a:b]
            F, Fl = (f, f @ R) if self.part_world[p] else (f @ R.T, f)
            out[self.part_names[p]] = {
                "points": self.points[a:b] @ R.T + d.xpos[body],
                "normals": self.normals[a:b] @ R.T,
                "forces": np.array(F), "normal_force": self.force_normal[a:b].copy(),
                "local_points": self.points[a:b].copy(), "local_forces": np.array(Fl),
                "spacing": float(self.part_spacing[p]),
            }
        return out


def build_touch(world, configs: Sequence[TouchConfig | None]):
    """The env's hook: the shared touch system and each agent's sense (None where touch is off)."""
    system = TouchSystem(world, configs)
    senses = [AgentTouch(system, i) if cfg is not None else None for i, cfg in enumerate(configs)]
    return system, senses


SENSE = SenseEntry("touch", TouchConfig, shared=build_touch)


# -- pictures --------------------------------------------------------------------------------
def save_skin_png(env, agent, path, parts: Sequence[str] | None = None,
                  elev: float | None = None, azim: float | None = None,
                  title: str | None = None, spheres: Sequence[tuple] = ()) -> str:
    """Save a PNG of one agent's skin points coloured by the force they sense (paper Fig. 5b).

    ``parts``: body parts to draw (default: all). Points without force are small and grey;
    points with force are coloured by its magnitude (N) and sized by it. The default view looks
    at the touched points from outside the body, from at most 40 degrees above or below
    (``elev``, ``azim`` in degrees override it). ``spheres``: ``(centre, radius)`` of objects to
    outline (e.g. a held ball).
    """
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    system = getattr(env, "unwrapped", env).system("touch")
    view = system.view(agent)
    if parts is not None:
        unknown = sorted(set(parts) - set(view))
        if unknown:
            raise ValueError(f"unknown body parts {unknown}; parts with skin: {sorted(view)}")
        view = {k: view[k] for k in parts}
    P = np.concatenate([v["points"] for v in view.values()])
    Nw = np.concatenate([v["normals"] for v in view.values()])
    F = np.concatenate([np.linalg.norm(v["forces"], axis=1) for v in view.values()])
    on = F > 1e-9
    look = Nw[on].mean(0) if on.any() else np.array([1.0, -1.0, 0.5])
    if np.linalg.norm(look) < 1e-6:
        look = np.array([1.0, -1.0, 0.5])
    look = look / np.linalg.norm(look)
    if elev is None:
        elev = float(np.clip(np.degrees(np.arcsin(np.clip(look[2], -1, 1))), -40, 40))
    if azim is None:
        azim = float(np.degrees(np.arctan2(look[1], look[0])))
    fig = plt.figure(figsize=(7.5, 6.5), dpi=120)
    ax = fig.add_subplot(projection="3d")
    ax.scatter(*P[~on].T, s=4, c="0.45", alpha=0.5, depthshade=True, linewidths=0)
    for centre, radius in spheres:
        u, v = np.mgrid[0:2 * np.pi:25j, 0:np.pi:13j]
        ax.plot_wireframe(centre[0] + radius * np.cos(u) * np.sin(v),
                          centre[1] + radius * np.sin(u) * np.sin(v),
                          centre[2] + radius * np.cos(v), color="tab:blue", alpha=0.25,
                          linewidth=0.6)
    if on.any():
        order = np.argsort(F[on])
        Fon = F[on][order]
        sc = ax.scatter(*P[on][order].T, s=10 + 150 * Fon / Fon.max(), c=Fon, cmap="autumn_r",
                        vmin=0.0, edgecolors="darkred", linewidths=0.4, depthshade=False)
        fig.colorbar(sc, ax=ax, shrink=0.6, pad=0.1, label="force on the point (N)")
    centre = (P.max(0) + P.min(0)) / 2
    r = (P.max(0) - P.min(0)).max() / 2
    ax.set_xlim(centre[0] - r, centre[0] + r)
    ax.set_ylim(centre[1] - r, centre[1] + r)
    ax.set_zlim(centre[2] - r, centre[2] + r)
    ax.set_box_aspect((1, 1, 1))
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(4))
    ax.tick_params(labelsize=7)
    ax.view_init(elev=elev, azim=azim)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    name = agent if isinstance(agent, str) else system.names[agent]
    ax.set_title(title or f"{name}: {len(P)} skin points, {int(on.sum())} sensing force "
                          f"(total {F.sum():.2f} N)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return str(path)
