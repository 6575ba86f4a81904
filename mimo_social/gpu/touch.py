"""Touch on the device, per body part: the summed normal force each body part of each agent
feels, and who presses it (itself, another agent, an object or the floor), from the batched
contacts of every world at once (issue 34).

The CPU skin (:mod:`mimo_social.senses.touch`) spreads each contact's force over skin points
near the contact, with weights that sum to 1: summed over a body part's points, its normal
force is the sum of the normal forces of the contacts on that part. That sum is what
:class:`BatchedTouch` computes on the device, for every body part with geoms (the skin's parts,
and the parts a skin leaves out), without the points: each contact row in use that the
constraint solver kept gives its normal force (MuJoCo's ``mj_contactForce``, Warp's
``contact_force``) to the part of each of its two geoms, under the agent or object on the
other side. No loop over worlds or contacts in Python, no copy to the host.
"""

from __future__ import annotations

import numpy as np

__all__ = ["BatchedTouch"]


class BatchedTouch:
    """Per body part summed normal forces of a :class:`~mimo_social.gpu.BatchedEnv`'s worlds.

    ``parts``: ``(agent, part)`` for each body part (unprefixed body names, each agent's parts
    in model body order), the columns of :meth:`forces`; ``sources``: the columns of
    :meth:`by_source`'s last axis: ``"object"`` (the floor, props, anything of no agent), then
    the agents."""

    def __init__(self, batched):
        env = batched.env
        world = env.world
        m = world.model
        torch = batched.torch
        self._torch = torch
        self._contacts = batched.contacts
        self.nworld = batched.nworld
        self.agents = list(batched.agents)
        self.sources = ["object"] + self.agents
        body_part = np.full(m.nbody, -1, dtype=np.int64)
        self.parts: list[tuple[str, str]] = []
        for i, name in enumerate(self.agents):
            prefix = f"{name}/"
            for b in sorted(int(b) for b in world.agents[i].body_ids):
                if m.body_geomnum[b] > 0:
                    body_part[b] = len(self.parts)
                    self.parts.append((name, m.body(b).name[len(prefix):]))
        self.nparts = len(self.parts)
        dev = self._contacts.dist.device
        geom_part = body_part[m.geom_bodyid]
        geom_source = np.asarray(world.geom_agent, dtype=np.int64) + 1   # 0: object
        # one more entry at the end: rows not in use read geom -1 as "no part", "object"
        self._geom_part = torch.as_tensor(np.append(geom_part, -1), device=dev)
        self._geom_source = torch.as_tensor(np.append(geom_source, 0), device=dev)
        self._ngeom = int(m.ngeom)

    def index(self, agent: str, part: str) -> int:
        """The column of ``agent``'s body part ``part`` (unprefixed)."""
        try:
            return self.parts.index((agent, part))
        except ValueError:
            known = [p for a, p in self.parts if a == agent]
            raise KeyError(f"{agent!r} has no body part {part!r} with geoms; "
                           f"known: {known or self.agents}") from None

    def by_source(self):
        """``(nworld, nparts, 1 + n_agents)``: per world and body part, the summed normal force
        (N) from contacts with objects (column 0) and with each agent (column 1 + its index;
        its own column: self-touch) after the last step."""
        t = self._torch
        c = self._contacts
        fn = c.normal_forces() * c.valid().to(t.float32)
        g = c.geom.long()
        g = t.where((g >= 0) & (g < self._ngeom), g, t.full_like(g, self._ngeom))
        world = c.worldid.long().clamp(0, self.nworld - 1)
        ns = len(self.sources)
        out = t.zeros(self.nworld * self.nparts * ns, dtype=t.float32, device=fn.device)
        for side in (0, 1):
            part = self._geom_part[g[:, side]]
            src = self._geom_source[g[:, 1 - side]]
            felt = (part >= 0) & (fn > 0)
            flat = (world * self.nparts + part.clamp(min=0)) * ns + src
            out.index_add_(0, flat, t.where(felt, fn, t.zeros_like(fn)))
        return out.reshape(self.nworld, self.nparts, ns)

    def forces(self):
        """``(nworld, nparts)``: per world and body part, the summed normal force (N)."""
        return self.by_source().sum(-1)
