"""Contact events in a recording: a body part of one agent starts touching one of another.

One lookup of all ``data.contact`` geom pairs in a table of "two different agents" per step;
the pairs of bodies in contact are remembered, so only new ones become events.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import rerun as rr

from .columns import TEXTS, component_field, index_columns, index_fields, offsets

__all__ = ["CONTACTS_PATH", "ContactLog"]

CONTACTS_PATH = "/events/contacts"


class ContactLog:
    """New contacts between body parts of two different agents of ``world``, as text
    ("infant_0 right_hand touches infant_1 right_fingers"); ``agents``: the agents' names."""

    def __init__(self, world, agents: list[str]):
        m = world.model
        self.names = agents
        # [geom a, geom b]: the geoms belong to two different agents; the extra last row and
        # column (geom id -1, as flex contacts have) are False
        agent = np.append(np.asarray(world.geom_agent, dtype=np.intp), -1)
        pairs = (agent[:, None] != agent[None, :]) & (agent[:, None] >= 0) & (agent[None, :] >= 0)
        self._geom_pairs = pairs.ravel()                   # looked up at geom a * stride + geom b
        self._geom_stride = np.array([pairs.shape[1], 1], dtype=np.intp)
        self._geom_body = np.append(m.geom_bodyid.astype(np.intp), 0)
        self._body_agent = np.asarray(world.body_agent, dtype=np.intp)
        self._body_part = [m.body(b).name.split("/", 1)[-1] for b in range(m.nbody)]
        self._pairs: set[int] = set()     # body pairs of different agents in contact
        self.schema = pa.schema(index_fields() + [component_field(
            f"{CONTACTS_PATH}:text", CONTACTS_PATH, rr.TextLog.descriptor_text(), TEXTS)])

    def reset(self) -> None:
        """A new episode: contacts at its reset are new ones."""
        self._pairs = set()

    def note(self, data) -> list[str]:
        """The pairs of bodies of two different agents that started touching (a contact at zero
        or negative distance) since the last call, as text (usually none)."""
        if data.ncon == 0:
            self._pairs = set()
            return []
        c = data.contact
        geoms = c.geom                                   # (ncon, 2)
        hit = self._geom_pairs.take(geoms.dot(self._geom_stride))
        if not np.count_nonzero(hit):                    # (cheaper than hit.any())
            self._pairs = set()
            return []
        hit &= c.dist <= 0.0
        bodies = self._geom_body[geoms[hit]]
        nbody = len(self._body_part)
        keys = set((bodies.min(axis=1) * nbody + bodies.max(axis=1)).tolist())
        new = keys - self._pairs
        self._pairs = keys
        out = []
        for key in sorted(new):
            a, b = sorted(divmod(key, nbody), key=lambda b: (self._body_agent[b], b))
            out.append(f"{self.names[self._body_agent[a]]} {self._body_part[a]} touches "
                       f"{self.names[self._body_agent[b]]} {self._body_part[b]}")
        return out

    def batch(self, contacts) -> pa.RecordBatch:
        """Contact events as one record batch: a row per event (events of one step share it)."""
        columns = index_columns([t for t, _, _ in contacts], [s for _, s, _ in contacts])
        texts = [text for _, _, text in contacts]
        columns.append(pa.ListArray.from_arrays(offsets(np.ones(len(texts), np.int32)),
                                                pa.array(texts, pa.utf8()), type=TEXTS))
        return pa.RecordBatch.from_arrays(columns, schema=self.schema)
