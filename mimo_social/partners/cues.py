"""What a learner shows its caregiver, read from the world's state: :func:`learner_cues`.

The cues a contingent caregiver (:mod:`.contingent`) responds to, and what the social paradigms
(still face, contingency, imitation) measure, from one computation:

- ``expression``: the learner's face id (:data:`~mimo_social.expressions.faces.EXPRESSIONS`),
  ``smiling``: that face is ``"happy"``;
- ``gaze_on_face``: the learner's line of sight passes within :data:`GAZE_ON_FACE_DEG` (10
  degrees) of the caregiver's face centre (its ``head_centre`` site). The line of sight starts
  midway between the learner's two eye cameras and points along the mean of their optical axes
  (a MuJoCo camera looks along its frame's -z), so it follows the head and the eyes; a learner
  without eye joints looks where its head points. 10 degrees is about the angle an adult's face
  (radius ~ 9 cm) subtends at 0.5 m, the near end of face-to-face play: looking anywhere on
  the face counts, looking past it does not;
- ``gaze_point``: where that line meets the floor plane (z = ``plane_z``, default 0), or None
  when it points level or up, or meets the plane farther than :data:`GAZE_RANGE` (3 m);
- ``touching``: a contact between a geom of either of the learner's hands (the hand body and
  everything below it: :func:`~mimo_social.core.kinematics.hand_geoms`) and any geom of the
  caregiver's body (``world.geom_agent``).

A scripted partner may read the world's state (partners/base.py); nothing here is an
observation of the learner's.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from ..body.sight import gaze_rays
from ..core.kinematics import hand_geoms
from ..expressions.faces import EXPRESSIONS
from ..util.names import reject_old_names

__all__ = ["Cues", "learner_cues", "gaze_line", "touching_hands", "GAZE_ON_FACE_DEG", "GAZE_RANGE", "HAPPY",
           "NEUTRAL"]

#: degrees: the learner looks at the caregiver's face when its line of sight passes within this
#: angle of the face centre
GAZE_ON_FACE_DEG = 10.0
#: m: a gaze point on the floor farther than this from the eyes is none (looking toward the horizon)
GAZE_RANGE = 3.0
HAPPY = EXPRESSIONS.index("happy")
NEUTRAL = EXPRESSIONS.index("neutral")

_HANDS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


@dataclass(frozen=True, eq=False)
class Cues:
    """The learner's cues at one moment (see the module docstring); compared by identity (it
    holds an array)."""

    expression: int
    smiling: bool
    gaze_on_face: bool
    gaze_point: np.ndarray | None
    touching: bool
    #: degrees between the learner's line of sight and the direction to the caregiver's face
    gaze_angle_deg: float = float("nan")


def _index(env, name: str, what: str) -> int:
    names = list(env.possible_agents)
    if name not in names:
        reject_old_names(name, names)
        raise ValueError(f"learner_cues: {what}={name!r} is not an agent of this env; agents: "
                         f"{names}")
    return names.index(name)


def gaze_line(world, i: int) -> tuple[np.ndarray, np.ndarray]:
    """Agent ``i``'s line of sight: (origin between its eyes, unit direction), world frame."""
    return gaze_rays(world.data, world.agents[i].eye_cameras)


def _hand_mask(world, i: int) -> np.ndarray:
    """Per geom of the world: 1 for agent i's right hand, 2 for its left, else 0 (cached)."""
    masks = _HANDS.get(world)
    if masks is None:
        masks = _HANDS.setdefault(world, {})
    if i not in masks:
        mask = np.zeros(world.model.ngeom, np.int8)
        mask[hand_geoms(world, i, 0)] = 1
        mask[hand_geoms(world, i, 1)] = 2
        masks[i] = mask
    return masks[i]


def touching_hands(world, i: int, j: int) -> tuple[bool, bool]:
    """Whether agent ``i``'s (right, left) hand touches agent ``j``'s body (a contact)."""
    hands = _hand_mask(world, i)
    owner = world.geom_agent
    d = world.data
    n = d.ncon
    if not n:
        return False, False
    g1, g2 = d.contact.geom1[:n], d.contact.geom2[:n]
    side = np.concatenate([hands[g1][owner[g2] == j], hands[g2][owner[g1] == j]])
    return bool(np.any(side == 1)), bool(np.any(side == 2))


def learner_cues(env, learner: str, caregiver: str, plane_z: float = 0.0) -> Cues:
    """The cues ``learner`` shows ``caregiver`` in ``env``'s current state (see the module
    docstring). ``env``: the :class:`~mimo_social.core.env.MimoParallelEnv` (a scripted
    partner's ``env``)."""
    i, j = _index(env, learner, "learner"), _index(env, caregiver, "caregiver")
    w = env.world
    expression = int(w.expression_of(i))
    origin, direction = gaze_line(w, i)
    to_face = w.data.site_xpos[w.agents[j].head_site] - origin
    cos = float(direction @ to_face) / max(float(np.linalg.norm(to_face)), 1e-12)
    angle = float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    point = None
    if direction[2] < -1e-6:
        t = (plane_z - origin[2]) / direction[2]
        if 0.0 <= t <= GAZE_RANGE:
            point = origin + t * direction
    touching = any(touching_hands(w, i, j))
    return Cues(expression=expression, smiling=expression == HAPPY,
                gaze_on_face=angle <= GAZE_ON_FACE_DEG, gaze_point=point, touching=touching,
                gaze_angle_deg=angle)
