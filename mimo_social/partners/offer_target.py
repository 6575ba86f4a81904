"""Where an offering agent holds its palm when the other agent's body differs from its own.

An adult, or an infant whose arm differs from the other's by over :data:`SIZE_TOLERANCE`,
offers where the other reaches (:func:`adapts`): the point :data:`REACH_TO` from the other's
right shoulder, scaled with the other's arm (:func:`arm_length`), as a target of its own right
shoulder (:func:`reach_target`), for :func:`~mimo_social.partners.hand_offer.offer_posture`.
Used by :class:`~mimo_social.partners.hand_offer.HandOffer` and the handover's giver.
"""

from __future__ import annotations

import numpy as np

__all__ = ["REACH_TO", "REACH_LIMIT", "REF_ARM", "SIZE_TOLERANCE", "reach_target", "is_adult",
           "arm_length", "nearest_other", "adapts"]

#: where an adult offers its palm centre by default: (forward, left, up) m from the other
#: agent's right shoulder, in that agent's heading frame: where the high five's scripted partner
#: (an 18-month-old, 0.35 m away) held its palm for the other 18-month-old before issue 30 moved
#: the high five's default offer to the midline (measured then on
#: ``high_five_v0.scripted_env()``: HandOffer.target_position minus infant_0's shoulder)
REACH_TO = (0.205, 0.152, -0.099)


#: where an offering agent holds its palm when the point asked is out of its reach (farther than
#: its arm, shoulder to palm centre): this fraction of its arm from the shoulder (the high five's
#: 18-month-old partner holds its palm 0.896 of its arm from its shoulder)
REACH_LIMIT = 0.9
#: a partner whose arm differs from the other's by more than this fraction offers where the
#: other reaches (:func:`adapts`)
SIZE_TOLERANCE = 0.05
#: m: the 18-month-old's right arm, shoulder to palm centre along the segments (arm_length)
REF_ARM = 0.2157


def arm_length(world, i: int) -> float:
    """Agent ``i``'s right arm in the world, m: shoulder to elbow, elbow to wrist, wrist to
    palm centre (the segments' origins and the palm site), whatever its posture."""
    m, d = world.model, world.data
    a = world.agents[i]
    pts = [d.xpos[m.body(f"{a.name}/right_{s}").id] for s in ("upper_arm", "lower_arm", "hand")]
    pts.append(d.site_xpos[a.palm_sites[0]])
    return float(sum(np.linalg.norm(q - p) for p, q in zip(pts, pts[1:])))


def is_adult(world, i: int) -> bool:
    """Whether agent ``i`` of ``world`` has the adult caregiver's body."""
    return getattr(world.tables[i], "body", "infant") == "adult"


def nearest_other(world, i: int) -> int:
    """The index of the agent nearest to agent ``i`` (hip to hip)."""
    d = world.data
    me = world.agents[i]
    others = [j for j in range(len(world.agents)) if j != i]
    if not others:
        raise ValueError(f"HandOffer: {me.name} has no other agent to offer to")
    return min(others, key=lambda k: np.linalg.norm(d.xpos[world.agents[k].root_body]
                                                     - d.xpos[me.root_body]))


def adapts(world, i: int) -> bool:
    """Whether agent ``i`` offers where the other reaches (:func:`reach_target`): an adult, or
    any body whose arm differs from the nearest other agent's by more than
    :data:`SIZE_TOLERANCE` (two infants of different sizes meet where the other reaches, within
    their own reach)."""
    if is_adult(world, i):
        return True
    ratio = arm_length(world, i) / arm_length(world, nearest_other(world, i))
    return abs(ratio - 1.0) > SIZE_TOLERANCE


def reach_target(world, i: int, point) -> tuple[float, float, float]:
    """``point`` (forward, left, up: m from the right shoulder of the agent nearest to agent
    ``i``, in that agent's heading frame, for an 18-month-old's arm; times that agent's
    :func:`arm_length` over :data:`REF_ARM`) as a target of agent ``i``'s own right shoulder
    (forward, left, up in ``i``'s heading frame), for :func:`offer_posture`. A point beyond
    agent ``i``'s arm is brought to :data:`REACH_LIMIT` of it: raised, if below, else pulled
    toward the shoulder."""
    m, d = world.model, world.data
    me = world.agents[i]
    j = nearest_other(world, i)

    def frame(a):
        R = d.xmat[a.root_body].reshape(3, 3)
        h = np.arctan2(R[1, 0], R[0, 0])
        c, s = np.cos(h), np.sin(h)
        sh = d.xpos[m.body(f"{a.name}/right_upper_arm").id].copy()
        return sh, np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    sh_j, R_j = frame(world.agents[j])
    sh_i, R_i = frame(me)
    goal = sh_j + R_j @ np.asarray(point, float) * arm_length(world, j) / REF_ARM
    local = R_i.T @ (goal - sh_i)
    arm = arm_length(world, i)
    reach = REACH_LIMIT * arm
    if np.linalg.norm(local) > arm:
        # out of its reach: below it, as low as it comfortably reaches above that point; else
        # (or if even that is too far) on the line to its shoulder, within reach
        across = float(np.linalg.norm(local[:2]))
        if local[2] < 0.0 and across < reach:
            local[2] = -np.sqrt(reach ** 2 - across ** 2)
        else:
            local = local * reach / np.linalg.norm(local)
    return tuple(float(x) for x in local)
