"""The scene the face-to-face paradigms share (contingency, vocal turn taking): a learner that
stands, hip fixed, every joint held but (``gaze_free``) its head and eyes, face to face with a
caregiver (an adult kneeling, or an infant standing) whose joints are all held, head and eyes on
the learner's face.

:class:`FacingPair` is a mixin for such a :class:`~mimo_social.core.task.Task`: its options need
``distance`` (m, between two 18-month-olds; :mod:`.dyad` places other bodies) and ``gaze_free``.
"""

from __future__ import annotations

from ..body.joint_groups import GAZE_JOINTS, held_posture
from ..core.world import AgentSetup
from .common import face_to_face
from .dyad import held_angles, tables_of, task_plan

__all__ = ["FacingPair"]

#: the standing pair's knees, a little bent (degrees)
KNEES = {"right_knee": -5, "left_knee": -5}


class FacingPair:
    """Setup, held joints and head support of the learner (agent 0) and its caregiver."""

    def pair_defaults(self, i: int, settings) -> dict:
        """Agent i's posture and body: the learner stands; the caregiver is the adult body
        (kneeling) unless ``settings`` say ``body="infant"`` (standing)."""
        if i == 0:
            return {"posture": "standing"}
        body = settings.get("body", "adult")
        return {"body": body, "posture": "kneeling" if body == "adult" else "standing"}

    def free_joints(self, i: int) -> tuple[str, ...]:
        """Agent i's motor joints: the learner's head and eyes with ``gaze_free``, else none."""
        return GAZE_JOINTS if i == 0 and self.options.gaze_free else ()

    def held_joints(self, i, config):
        """Agent i's held joints (rad): all but its free ones, standing knees a little bent, or
        its own posture's angles (the kneeling adult)."""
        angles = held_angles(config, "standing", KNEES)
        return held_posture(tables_of(config), keep=self.free_joints(i), angles=angles)

    def setup(self, i, config):
        plan = task_plan(self, "standing", self.options.distance, self.held_joints, (0, 1))
        pos, facing = face_to_face(i, plan.distance)
        free = self.free_joints(i)
        aimed = {k: v for k, v in plan.gaze[i].items() if k not in free}
        frozen = {**self.held_joints(i, config), **aimed}
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=free)

    def bind(self, env):
        """The learner's head and eye dofs (``gaze_free``: gravity on them is cancelled)."""
        a = env.world.agents[0]
        self._head_dofs = a.dof_adr[a.actuated_joint_idx]

    def before_physics(self, env):
        if len(self._head_dofs):     # head support: a zero action holds the head up
            d = env.world.data
            d.qfrc_applied[self._head_dofs] = d.qfrc_bias[self._head_dofs]
