"""Initial postures as data: joint angles (degrees) and the root's tilt.

Arms hang 12 degrees abducted so the hands clear the hips. Joints not named keep their spring reference angle (the relaxed pose). ``pitch_deg`` tilts the
whole body about its own left-right axis before it is placed on the floor (lying on the back is a
pitch of -90 degrees: the face looks up). The world lowers every posture onto the floor.
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
    "lying": {
        "pitch_deg": -90.0,
        "joints": {"right_shoulder_abduction": 12.0, "left_shoulder_abduction": 12.0,
                   "right_knee": -10.0, "left_knee": -10.0},
    },
}
