"""Contact events in a recording: a body part of one agent starts or stops touching one of another.

One lookup of all ``data.contact`` geom pairs in a table of "two different agents" per step;
the pairs of bodies in contact are remembered, so only changes become events. Each event is one
full line of text in the ``/events/contacts`` TextLog (its time is the row's ``sim_time``):

* start: ``infant_0 right_hand touches infant_1 right_fingers (0.84 N)``: who touches whom,
  with which body parts (the bodies' names, as in the 3D view's entity paths), and the normal
  force between the two parts at that step;
* end: ``infant_0 right_hand stops touching infant_1 right_fingers after 0.42 s (peak 3.10 N)``;
  a contact still on when the episode is reset or the recording closed ends there, with
  ``(episode reset)`` / ``(end of recording)`` after it.

A contact ends only when the two parts have been apart for ``gap_s`` (0.1 s by default): hands
that rest on each other make and break contact every few physics steps (the demo's 6 s made 152
events with no gap, mostly finger segments chattering), and a touch that comes back within the
gap is the same touch. The end line is stamped when the gap has passed and gives the duration
up to the last step the parts touched.

The forces are read (``mj_contactForce``) only for contacts between two agents, so a step where
agents do not touch costs one table lookup.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pyarrow as pa
import rerun as rr

from .columns import TEXTS, component_field, index_columns, index_fields, offsets

__all__ = ["CONTACTS_PATH", "ContactLog"]

CONTACTS_PATH = "/events/contacts"


class ContactLog:
    """Contacts between body parts of two different agents of ``world`` that start or stop, as
    text (see the module docstring); ``agents``: the agents' names."""

    def __init__(self, world, agents: list[str], gap_s: float = 0.1):
        m = world.model
        self.gap_s = float(gap_s)
        self.model = m
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
        # body pairs of different agents in contact: key -> [start time, peak normal force,
        # last time seen touching]
        self._on: dict[int, list[float]] = {}
        self._force = np.zeros(6)
        self.schema = pa.schema(index_fields() + [component_field(
            f"{CONTACTS_PATH}:text", CONTACTS_PATH, rr.TextLog.descriptor_text(), TEXTS)])

    def reset(self) -> None:
        """A new episode: contacts at its reset are new ones (end the old ones first:
        :meth:`end_all`)."""
        self._on = {}

    def _names(self, key: int) -> tuple[str, str]:
        nbody = len(self._body_part)
        a, b = sorted(divmod(key, nbody), key=lambda b: (self._body_agent[b], b))
        return (f"{self.names[self._body_agent[a]]} {self._body_part[a]}",
                f"{self.names[self._body_agent[b]]} {self._body_part[b]}")

    def _end(self, key: int, why: str = "") -> str:
        start, peak, last = self._on.pop(key)     # touching from start to last (sim time)
        a, b = self._names(key)
        return (f"{a} stops touching {b} after {last - start:.2f} s (peak {peak:.2f} N)"
                + (f" ({why})" if why else ""))

    def end_all(self, out: list, t: float, step: int, why: str) -> int:
        """Append to ``out`` an end event, as (t, step, text), for every contact still on;
        return how many."""
        keys = sorted(self._on)
        out += [(t, step, self._end(key, why)) for key in keys]
        return len(keys)

    def note(self, data, out: list, t: float, step: int) -> int:
        """Append to ``out`` the contacts between agents that started or stopped (a contact at
        zero or negative distance) since the last call, as (t, step, text) (usually none);
        return how many."""
        keys: dict[int, float] = {}
        if data.ncon:
            c = data.contact
            geoms = c.geom                                   # (ncon, 2)
            hit = self._geom_pairs.take(geoms.dot(self._geom_stride))
            if np.count_nonzero(hit):                        # (cheaper than hit.any())
                hit &= c.dist <= 0.0
                index = np.flatnonzero(hit)
                bodies = self._geom_body[geoms[index]]
                nbody = len(self._body_part)
                f = self._force
                for k, key in zip(index.tolist(),
                                  (bodies.min(axis=1) * nbody + bodies.max(axis=1)).tolist()):
                    mujoco.mj_contactForce(self.model, data, k, f)
                    keys[key] = keys.get(key, 0.0) + abs(float(f[0]))
        if not keys and not self._on:
            return 0
        n = len(out)
        for key in sorted(self._on.keys() - keys.keys()):
            last = self._on[key][2]
            if t - last >= self.gap_s - 1e-9:       # apart for the whole gap: it ended
                out.append((t, step, self._end(key)))
        for key in sorted(keys):
            force = keys[key]
            on = self._on.get(key)
            if on is None:
                self._on[key] = [t, force, t]
                a, b = self._names(key)
                out.append((t, step, f"{a} touches {b} ({force:.2f} N)"))
            else:
                on[1] = max(on[1], force)
                on[2] = t
        return len(out) - n

    def batch(self, contacts) -> pa.RecordBatch:
        """Contact events as one record batch: a row per event (events of one step share it)."""
        columns = index_columns([t for t, _, _ in contacts], [s for _, s, _ in contacts])
        texts = [text for _, _, text in contacts]
        columns.append(pa.ListArray.from_arrays(offsets(np.ones(len(texts), np.int32)),
                                                pa.array(texts, pa.utf8()), type=TEXTS))
        return pa.RecordBatch.from_arrays(columns, schema=self.schema)
