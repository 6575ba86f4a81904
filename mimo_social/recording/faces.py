"""Expression changes in a recording: a text row for each, a face image and head texture for
those shown long enough.

A change is seen as a change of the texture of an agent's head material (one byte comparison of
``model.mat_texid`` per step). Every component's values are stacked over the expressions once,
so an event batch is made by picking rows.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import rerun as rr

from ..expressions.faces import EXPRESSIONS, SKIN_RGB, face_images
from .columns import Rows, component_field, entity, index_fields
from .geometry import RGB_ROLE

__all__ = ["HEAD_SKIN_RGB", "HEAD_TEXTURE_SIZE", "FaceLog", "head_texture"]

#: the skin of a head in the 3D view: warmer and darker than the face images' (the viewer's
#: light washes a pale albedo out to grey), so that the face stands out from the room
HEAD_SKIN_RGB = (222, 160, 118)
#: the head textures' edge (pixels; at least): lines stay sharp on a head seen close up
HEAD_TEXTURE_SIZE = 128
#: how much stronger a feature (brow, lash line, mouth, cheek) departs from the skin on a head
_HEAD_CONTRAST = 1.4


def head_texture(face: np.ndarray) -> np.ndarray:
    """A face image (H x W x 3 uint8, on :data:`~mimo_social.expressions.faces.SKIN_RGB`) as a
    head's texture in the 3D view: the skin :data:`HEAD_SKIN_RGB`, every feature's departure
    from the skin made stronger. The face images of the recording and the model's own texture
    (what the agents' eyes see) are unchanged."""
    departure = face[..., :3].astype(np.float64) - np.array(SKIN_RGB, np.float64)
    out = np.array(HEAD_SKIN_RGB, np.float64) + _HEAD_CONTRAST * departure
    return np.clip(np.round(out), 0, 255).astype(np.uint8)


class FaceLog:
    """Each agent's expression of ``world``: its TextLog at ``/agents/<agent>/expression``, its
    face Image at ``/agents/<agent>/face`` and (textured heads) its head mesh's texture.

    Face images and head textures of an expression are due once it has been shown
    ``hold_steps`` steps (0: at once); they are stamped with the step it appeared.
    """

    def __init__(self, world, agents: list[str], hold_steps: int):
        self.world = world
        self.agents = agents
        self.hold_steps = int(hold_steps)
        self.pending: dict[int, tuple[float, int, int, int]] = {}  # agent -> image not yet due
        self._head_mats = np.array([a.head_material for a in world.agents], dtype=np.intp)
        faces = getattr(world, "faces", None)      # texture id -> expression id, for speed
        self._expression_of_texture = ({world.model.texture(name).id: e
                                        for e, name in enumerate(faces.names)} if faces else {})
        self.expression_paths = [entity("agents", a, "expression") for a in agents]
        self.face_paths = [entity("agents", a, "face") for a in agents]

    def build_columns(self, head_paths: list[str | None], face_size: int) -> None:
        """Arrow schema and values of what is logged when an agent's expression changes.

        Per agent: the TextLog, the face Image and (a path in ``head_paths``) the head's texture.
        The values of each component are stacked over the expressions (row e: expression e).
        """
        images = face_images(face_size)
        textures = [head_texture(img) for img in face_images(max(face_size, HEAD_TEXTURE_SIZE))]
        per_expression = {
            "expression": [rr.TextLog(name) for name in EXPRESSIONS],
            "face": [rr.Image(img) for img in images],
            "texture": [rr.Mesh3D(vertex_positions=np.zeros((1, 3), np.float32), albedo_texture=img)
                        for img in textures]}
        stacked: dict[str, list] = {}
        for kind, archetypes in per_expression.items():
            batches = [a.as_component_batches() for a in archetypes]
            for k, first in enumerate(batches[0]):
                desc = first.component_descriptor()
                if kind == "texture" and "albedo_texture" not in desc.component:
                    continue
                values = [b[k].as_arrow_array() for b in batches]    # one row per expression
                stacked.setdefault(kind, []).append((desc, values))
        fields = index_fields()
        self._columns: list[tuple[int, bool, list[pa.Array]]] = []  # agent, image?, values
        for i in range(len(self.agents)):
            paths = {"expression": self.expression_paths[i], "face": self.face_paths[i],
                     "texture": head_paths[i]}
            for kind, components in stacked.items():
                if paths[kind] is None:
                    continue
                for desc, values in components:
                    dtype = pa.list_(pa.field("item", values[0].type, nullable=False))
                    fields.append(component_field(f"{paths[kind]}:{desc.component}", paths[kind],
                                                  desc, dtype))
                    self._columns.append((i, kind != "expression", values))
        self._schema = pa.schema(fields)
        self._fields = fields[2:]

    # -- per step -------------------------------------------------------------------------------
    def reset(self, mat_texid: np.ndarray) -> None:
        """A new episode (``mat_texid``: the model's ``mat_texid``, read at every step)."""
        self._mat_texid = mat_texid
        self._tex_raw = mat_texid.tobytes()
        self._tex_shown = mat_texid[self._head_mats, RGB_ROLE]

    def changed(self) -> np.ndarray | None:
        """The agents whose expression changed since the last call (None: no material did)."""
        raw = self._mat_texid.tobytes()          # a cheap test for "some material changed"
        if raw == self._tex_raw:
            return None
        self._tex_raw = raw
        shown = self._mat_texid[self._head_mats, RGB_ROLE]
        changed = np.flatnonzero(shown != self._tex_shown)
        self._tex_shown = shown
        return changed

    def note(self, rows: Rows, agents, t: float, step: int, at_once: bool = False) -> None:
        """Note the current expression of ``agents`` in ``rows``: always as text; as face image
        and head texture once it has been shown ``hold_steps`` (or ``at_once``)."""
        for i in agents:
            event = (t, step, int(i), self._expression_of(int(i)))
            rows.texts.append(event)
            if at_once or self.hold_steps == 0:
                self.pending.pop(int(i), None)
                rows.images.append(event)
            else:
                self.pending[int(i)] = event     # replaces a shorter-lived one

    def _expression_of(self, i: int) -> int:
        """Agent ``i``'s expression id, read from its head material's texture."""
        e = self._expression_of_texture.get(int(self._tex_shown[i]))
        return self.world.expression_of(i) if e is None else e

    def commit(self, rows: Rows, step: int, everything: bool = False) -> None:
        """Queue the face images of expressions shown long enough at ``step`` (or of all,
        ``everything``)."""
        for i, event in list(self.pending.items()):
            if everything or step - event[1] >= self.hold_steps:
                rows.images.append(event)
                del self.pending[i]

    def batch(self, texts, images) -> pa.RecordBatch:
        """Expression changes as one record batch: a row per step with a change; per agent its
        text (every change) and face image and head texture (changes held long enough) where it
        changed, no data elsewhere."""
        steps = sorted({step: t for t, step, _, _ in texts + images}.items())
        row_of = {step: r for r, (step, _) in enumerate(steps)}
        na = len(self.agents)
        shown = {False: [[-1] * na for _ in steps], True: [[-1] * na for _ in steps]}
        for is_image, events in ((False, texts), (True, images)):
            for _, step, i, e in events:
                shown[is_image][row_of[step]][i] = e
        times = np.round(np.array([t for _, t in steps]) * 1e9).astype(np.int64)
        columns = [pa.array(times, pa.duration("ns")),
                   pa.array(np.array([step for step, _ in steps], dtype=np.int64))]
        picks = {}    # (agent, image?) -> (expressions of the rows with data, offsets, nulls)
        for is_image, table in shown.items():
            for i in range(na):
                picked = [row[i] for row in table]
                present = np.array([e >= 0 for e in picked])
                offs = np.zeros(len(picked) + 1, dtype=np.int32)
                np.cumsum(present, out=offs[1:])
                picks[i, is_image] = ([e for e in picked if e >= 0], pa.array(offs),
                                      pa.array(~present))
        for (i, is_image, values), field in zip(self._columns, self._fields):
            picked, offs, nulls = picks[i, is_image]
            items = (pa.concat_arrays([values[e] for e in picked]) if picked
                     else values[0].slice(0, 0))
            columns.append(pa.ListArray.from_arrays(offs, items, type=field.type, mask=nulls))
        return pa.RecordBatch.from_arrays(columns, schema=self._schema)
