"""Face perception: where the other agents' faces are and where they look, read only while a face
is in the agent's view.

A model of what an infant's visual system makes of a face it sees, without reading it from the
pixels: from a few months on infants orient to faces and from about 10 months they follow a
partner's head and eye direction (docs/senses.md, "Faces"). Learning to read a partner's eyes
from 96 x 96 images was measured as the limit of joint attention (the eyes about 3 pixels
across; docs/training/issue30/pilots/joint_attention_probe); this sense is the named option that
gives a learner what a trained face perception would, and nothing a look could not give.

Per other agent, in agent order (the agent itself skipped), the switched-on ``components``:

* ``seen`` (1): 1 while the face is seen, else 0;
* ``position`` (3): its head centre relative to the point between the agent's eyes, metres;
* ``head`` (3): the direction the face is turned to (its head's forward axis), a unit vector;
* ``gaze`` (3): its line of sight (the mean of its eyes' viewing axes), a unit vector.

Vectors are in the agent's head frame (x forward, y to its left, z up with the head upright).
A face is **seen** when its head centre lies inside the frustum of one of the agent's eyes
(square, ``field_of_view`` degrees a side: None takes the eye cameras' own ``cam_fovy``, the
vision sense's ``field_of_view`` when vision is on, else the body's 60 degrees), when it is
turned towards the agent (its forward axis within ``turn_deg`` of the line to the agent's eyes:
90, a profile still shows where the eyes point), and, with ``occlusion`` (the default), when the
first thing on the line from between the agent's eyes to that head centre is the partner's head
(MuJoCo's ``mj_ray``; the agent's own head and eyes excluded). Not seen, the components of that
face read 0 (``seen`` tells a zero from a face straight ahead).

No noise is added and the reading is exact: a researcher who wants an infant's imprecision adds
it in a wrapper; the sense's delay is the face-sensitive evoked potential's
(``delays="developmental"``: the infant N290 and the adult N170, senses/data/delays.csv).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from gymnasium import spaces

from ..body.sight import gaze_rays, in_view
from ..util.checks import check_bool, check_number
from .base import SenseEntry, components

__all__ = ["FacesConfig", "Faces", "SENSE", "COMPONENTS", "SIZES"]

COMPONENTS = ("seen", "position", "head", "gaze")
#: numbers per face of each component
SIZES = {"seen": 1, "position": 3, "head": 3, "gaze": 3}
FOV_RANGE = (10.0, 170.0)


@dataclass(frozen=True)
class FacesConfig:
    """The other agents' faces while in view: seen, position, head and gaze direction."""

    components: tuple[str, ...] = COMPONENTS  # per face: seen, position, head, gaze (in order)
    # degrees, each eye's square view; None: the eye cameras' own (vision's, else 60)
    field_of_view: float | None = None
    turn_deg: float = 90.0     # a face turned further away than this (degrees) is not seen
    occlusion: bool = True     # a face behind something (a body, a prop) is not seen

    def __post_init__(self):
        put = object.__setattr__
        put(self, "components", components("faces", self.components, COMPONENTS))
        if self.field_of_view is not None:
            put(self, "field_of_view", check_number("faces", "field_of_view",
                                                    self.field_of_view, *FOV_RANGE,
                                                    "degrees, or None: the eyes' own"))
        put(self, "turn_deg", check_number("faces", "turn_deg", self.turn_deg, 0.0, 180.0))
        put(self, "occlusion", check_bool("faces", "occlusion", self.occlusion))


class Faces:
    """One agent's face perception (module table). ``world``: the compiled world (its agents'
    index tables); ``index``: the agent."""

    name = "faces"

    def __init__(self, config: FacesConfig, world, index: int):
        m = world.model
        self.config = config
        me = world.agents[index]
        self.others = [a for k, a in enumerate(world.agents) if k != index]
        self.cams = np.asarray(me.eye_cameras, dtype=np.intp)                  # (2,)
        self.head_body = int(m.site_bodyid[me.head_site])
        fov = (np.full(2, config.field_of_view) if config.field_of_view is not None
               else np.asarray(m.cam_fovy[self.cams], dtype=float))
        self.half_tan = np.tan(np.deg2rad(fov) / 2.0)                           # (2,)
        self.cos_turn = float(np.cos(np.deg2rad(config.turn_deg)))
        self.sites = np.array([a.head_site for a in self.others], dtype=np.intp)
        self.heads = np.array([m.site_bodyid[a.head_site] for a in self.others], dtype=np.intp)
        self.their_cams = np.array([a.eye_cameras for a in self.others], dtype=np.intp)
        # what counts as the face when the line of sight hits it: each partner's head and eyes
        self.face_bodies = [frozenset([int(h), *(int(m.cam_bodyid[c]) for c in a.eye_cameras)])
                            for h, a in zip(self.heads, self.others)]
        self.own_bodies = frozenset([self.head_body, *(int(m.cam_bodyid[c]) for c in self.cams)])
        self._slots, at = {}, 0
        for c in config.components:
            self._slots[c] = slice(at, at + SIZES[c])
            at += SIZES[c]
        self.per_face = at
        # one face's bounds (seen in [0, 1], unit vectors in [-1, 1]), repeated per face
        lo, hi = np.full(at, -np.inf, np.float32), np.full(at, np.inf, np.float32)
        for c, bound in (("seen", 0.0), ("head", -1.0), ("gaze", -1.0)):
            if c in self._slots:
                lo[self._slots[c]], hi[self._slots[c]] = bound, 1.0
        n = len(self.others) * at
        low, high = np.tile(lo, len(self.others)), np.tile(hi, len(self.others))
        self.space = spaces.Box(low, high, (n,), np.float32)
        self.spaces = {self.name: self.space}
        self._geomid = np.zeros(1, np.int32)

    def seen(self, model, data) -> np.ndarray:
        """Whether each other agent's face is seen now (module table), shape ``(n_others,)``."""
        faces = data.site_xpos[self.sites]                                       # (k, 3)
        seen = in_view(data, self.cams, faces, self.half_tan).any(axis=1)
        origin = data.cam_xpos[self.cams].mean(axis=0)
        to_me = origin[None] - faces
        forward = data.xmat[self.heads].reshape(-1, 3, 3)[:, :, 0]
        turned = np.einsum("kc,kc->k", forward, to_me) >= (
            self.cos_turn * np.linalg.norm(to_me, axis=1))
        out = seen & turned
        if self.config.occlusion:
            for k in np.flatnonzero(out):
                out[k] = self._unblocked(model, data, origin, faces[k], k)
        return out

    def _unblocked(self, model, data, origin, face, k: int) -> bool:
        """Whether the first geom on the line from ``origin`` to face ``k``'s centre belongs to
        that face (the agent's own head and eyes skipped: the line starts inside them)."""
        start = origin
        for _ in range(4):      # step past own geoms (the head, each eye) the line starts in
            direction = face - start
            body, frac = self._first_hit(model, data, start, direction)
            if body is None or body not in self.own_bodies:
                break
            start = start + direction * (frac + 1e-4)
        return body is not None and body in self.face_bodies[k]

    def _first_hit(self, model, data, start, direction):
        """The body of the first geom on the segment ``start`` + t ``direction``, t in [0, 1],
        and its t (None, -1 when nothing is hit there)."""
        frac = mujoco.mj_ray(model, data, start, direction, None, 1, -1, self._geomid)
        g = int(self._geomid[0])
        if g < 0 or frac > 1.0 + 1e-9:
            return None, -1.0
        return int(model.geom_bodyid[g]), float(frac)

    def read(self, model, data) -> np.ndarray:
        out = np.zeros(self.space.shape, np.float32)
        seen = self.seen(model, data)
        if not seen.any():
            return out
        head = data.xmat[self.head_body].reshape(3, 3)
        origin = data.cam_xpos[self.cams].mean(axis=0)
        block = out.reshape(len(self.others), self.per_face)
        rows = np.flatnonzero(seen)
        parts = {"seen": np.ones((len(rows), 1)),
                 "position": (data.site_xpos[self.sites[rows]] - origin) @ head,
                 "head": data.xmat[self.heads[rows]].reshape(-1, 3, 3)[:, :, 0] @ head}
        if "gaze" in self._slots:
            parts["gaze"] = gaze_rays(data, self.their_cams[rows])[1] @ head
        for c, s in self._slots.items():
            block[rows, s] = parts[c]
        return out

    def observe(self, model, data, out: dict) -> None:
        out[self.name] = self.read(model, data)


def _build(config: FacesConfig, world, index: int, actuation) -> Faces:
    return Faces(config, world, index)


SENSE = SenseEntry("faces", FacesConfig, per_agent=_build)
