"""Initial postures as data: joint angles (degrees) and the root's tilt.

Arms hang 12 degrees abducted so the hands clear the hips. Joints not named keep their spring
reference angle (the relaxed pose). ``pitch_deg`` tilts the whole body about its own left-right axis
before it is placed on the floor (lying on the back is a pitch of -90 degrees: the face looks up).
The world lowers every posture onto the floor.

:data:`POSTURES` holds every body's postures; :data:`BODY_POSTURES` what one body (the adult)
does otherwise, merged over them by :func:`posture_joints` and :func:`posture_pitch` (read a
posture through these two for a body that may be the adult).

Kneeling ("tall kneeling" on tucked toes, for face-to-face play at infant height): the trunk
upright, the thighs 20 degrees forward of it, the knees bent 120 degrees so that the knees and
the toe tips touch the floor together, the centre of mass between them (the ankle angle that
puts the toes level with the knees is the body's own: -18 degrees for the infant, -35 for the
adult). Shins flat on the floor would need the feet plantar flexed about 90 degrees, beyond both
bodies' ankle ranges (infant 63, adult 50 degrees).
"""

POSTURES = {
    "standing": {
        "pitch_deg": 0.0,
        "joints": {"right_shoulder_abduction": 12.0, "left_shoulder_abduction": 12.0,
                   "right_knee": -5.0, "left_knee": -5.0, "right_hip_flexion": -3.0,
                   "left_hip_flexion": -3.0, "right_ankle_flexion": 0.0,
                   "left_ankle_flexion": 0.0},
    },
    "sitting": {
        "pitch_deg": 0.0,
        "joints": {"right_shoulder_abduction": 12.0, "left_shoulder_abduction": 12.0,
                   "right_hip_flexion": -90.0, "left_hip_flexion": -90.0,
                   "right_hip_abduction": -15.0, "left_hip_abduction": -15.0,
                   "right_knee": -10.0, "left_knee": -10.0,
                   "right_ankle_flexion": 0.0, "left_ankle_flexion": 0.0,
                   "lower_trunk_bend": 5.0},
    },
    "kneeling": {
        "pitch_deg": 0.0,
        "joints": {"right_shoulder_abduction": 12.0, "left_shoulder_abduction": 12.0,
                   "right_hip_flexion": -20.0, "left_hip_flexion": -20.0,
                   "right_knee": -120.0, "left_knee": -120.0,
                   "right_ankle_flexion": -18.0, "left_ankle_flexion": -18.0},
    },
    "lying": {
        "pitch_deg": -90.0,
        "joints": {"right_shoulder_abduction": 12.0, "left_shoulder_abduction": 12.0,
                   "right_knee": -10.0, "left_knee": -10.0},
    },
}

#: body -> posture -> what replaces the shared posture's values: ``joints`` (merged over the
#: shared angles) and ``pitch_deg``. The adult stands leaning 3 degrees forward with the ankles
#: dorsiflexed 5 degrees (soles flat; the centre of mass over the middle of the feet rather than
#: over the heels, where a held adult tips over backwards); sits with straight legs and the hands
#: on the thighs (with the infant's angles its long arms prop it on its fingers and it rocks back
#: from its heels onto its thighs); and kneels with the ankles at -35.
BODY_POSTURES = {
    "adult": {
        "standing": {"pitch_deg": 3.0,
                     "joints": {"right_ankle_flexion": 5.0, "left_ankle_flexion": 5.0}},
        "sitting": {"joints": {"right_shoulder_abduction": 30.0, "left_shoulder_abduction": 30.0,
                               "right_elbow": -70.0, "left_elbow": -70.0,
                               "right_knee": 0.0, "left_knee": 0.0}},
        "kneeling": {"joints": {"right_ankle_flexion": -35.0, "left_ankle_flexion": -35.0}},
    },
}


def posture_joints(posture: str, body: str = "infant") -> dict:
    """Joint name -> angle (degrees) of ``posture`` for ``body`` ("infant" or "adult")."""
    own = BODY_POSTURES.get(body, {}).get(posture, {})
    return {**POSTURES[posture]["joints"], **own.get("joints", {})}


def posture_pitch(posture: str, body: str = "infant") -> float:
    """The root's pitch (degrees) of ``posture`` for ``body``."""
    own = BODY_POSTURES.get(body, {}).get(posture, {})
    return float(own.get("pitch_deg", POSTURES[posture]["pitch_deg"]))
