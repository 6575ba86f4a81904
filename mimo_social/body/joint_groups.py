"""Named groups of joints (head and eyes, the right arm) and held postures, from the body tables.

The one place for joint-name groups: tasks, partners and tools import them from here.
:func:`~mimo_social.body.tables.arm_joints` gives an arm's joints of any hand version.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from .tables import arm_joints

__all__ = ["HEAD_GAZE_JOINTS", "EYE_GAZE_JOINTS", "GAZE_JOINTS", "RIGHT_ARM_JOINTS",
           "RIGHT_SHOULDER_ELBOW", "RIGHT_WRIST", "right_arm_joints", "both_arms_joints", "held_posture"]

HEAD_GAZE_JOINTS = ("head_swivel", "head_tilt", "head_tilt_side")
EYE_GAZE_JOINTS = ("right_eye_horizontal", "right_eye_vertical", "right_eye_torsional",
                   "left_eye_horizontal", "left_eye_vertical", "left_eye_torsional")
GAZE_JOINTS = HEAD_GAZE_JOINTS + EYE_GAZE_JOINTS
#: the right arm of the mitten body (shoulder 3, elbow, wrist 3, the mitten's finger joint)
RIGHT_ARM_JOINTS = ("right_shoulder_horizontal", "right_shoulder_abduction",
                    "right_shoulder_rotation", "right_elbow", "right_wrist_rotation",
                    "right_wrist_flexion", "right_wrist_ulnar", "right_fingers")
RIGHT_SHOULDER_ELBOW = RIGHT_ARM_JOINTS[:4]
RIGHT_WRIST = RIGHT_ARM_JOINTS[4:7]


def right_arm_joints(tables) -> tuple[str, ...]:
    """The right arm's joints of this body version: :data:`RIGHT_ARM_JOINTS` (8) for the mitten
    hands, shoulder 3 + elbow + wrist 3 + 22 finger joints for the five-fingered hands."""
    return arm_joints(tables, "right")


def both_arms_joints(tables) -> tuple[str, ...]:
    """The right arm's joints, then the left arm's."""
    return arm_joints(tables, "right") + arm_joints(tables, "left")


def held_posture(tables, keep: tuple[str, ...], angles: Mapping[str, float] | None = None) -> dict:
    """Freeze every joint except ``keep``, at the given angles (deg) or its spring reference;
    returns joint name -> angle (rad, within the joint's range)."""
    angles = angles or {}
    out = {}
    for j in tables.joints:
        if j.name in keep or j.coupled_to:
            continue
        lo, hi = j.range_deg
        out[j.name] = float(np.deg2rad(np.clip(angles.get(j.name, j.springref_deg), lo, hi)))
    return out
