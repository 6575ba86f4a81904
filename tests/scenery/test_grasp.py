"""Toys of the play room can be grasped and lifted by an infant through its own motors.

A five-fingered infant sits in the play room (free play, one infant). Every step its action is
computed from the state: a PD loop per motor toward target angles plus MuJoCo's bias forces,
sent as spring-damper motor commands (``tau / T_max``), with the right hand's finger and thumb
flexors (mcp, pip, dip, ip) given a constant ``grip`` command. The right arm hangs beside the
body, the palm facing the body and the fingers pointing down. The fingers curl (0.3 s); the
rattle is then put, at rest, with its handle across the palm between palm and fingers (the
toy's free joint set through ``env.world``, as the handover task lays its ball in the giver's
palm); the fingers close on it (0.3 s); then the elbow flexes by 1.5 rad (1 s ramp, 0.5 s hold)
and the hand rises about 9 cm. Gripped (``grip`` 0.5), the rattle rises with the hand (about 12
cm above where it was put) and the hand's geoms still press on it; with the fingers open
(``grip`` 0) it falls out of the hand onto the mat at once and stays there.

Checked as well (not in the test): the 4 cm blocks are not held by this grasp at any grip
(0.2 to 1.0; see docs/playroom.md), and the rattle slips out at ``grip`` 0.2.
"""

from __future__ import annotations

import mujoco
import numpy as np

from mimo_social.core.kinematics import hand_geoms
from mimo_social.envs import free_play_v0

FLEXORS = ("mcp", "pip", "dip", "ip")


class Infant:
    """The sitting infant, its PD-held posture and the toy in its right hand."""

    def __init__(self, toy: str):
        self.env = env = free_play_v0.parallel_env(
            n_agents=1, scene="playroom", hands="five_fingers", posture="sitting",
            expressions=False)
        env.reset(seed=0)
        w = env.world
        self.m, self.d = w.model, w.data
        a = w.agents[0]
        self.act = env.actuation[0]
        self.names = list(a.actuated_names)
        k = a.actuated_joint_idx
        self.qadr, self.dadr = a.qpos_adr[k], a.dof_adr[k]
        self.target = self.d.qpos[self.qadr].copy()
        self.flex = np.array([n.startswith("right_") and n.split("_")[-1] in FLEXORS
                              for n in self.names])
        self.site = int(a.palm_sites[0])
        self.hand = int(self.m.site_bodyid[self.site])
        self.hand_geoms = set(hand_geoms(w, 0, 0).tolist())
        self.toy = self.m.body(f"playroom/{toy}").id
        self.toy_geoms = set(np.flatnonzero(self.m.geom_bodyid == self.toy).tolist())
        joint = self.m.body_jntadr[self.toy]
        self.toy_q, self.toy_v = self.m.jnt_qposadr[joint], self.m.jnt_dofadr[joint]

    def step(self, grip: float) -> None:
        d = self.d
        tau = (20.0 * (self.target - d.qpos[self.qadr]) - 1.0 * d.qvel[self.dadr]
               + d.qfrc_bias[self.dadr])
        u = np.clip(np.where(tau >= 0, tau / self.act.torque_pos, tau / self.act.torque_neg),
                    -1.0, 1.0)
        u[self.flex] = grip
        self.env.step({"infant_0": u.astype(np.float32)})

    def put_in_hand(self, toy: str) -> None:
        """The rattle's handle (radius 1 cm) across the palm, 2 mm off its skin, 1 cm toward
        the fingers from the palm's centre, its head beyond the hand's edge; a block (4 cm)
        likewise, its centre on the handle's line."""
        m, d = self.m, self.d
        R = d.xmat[self.hand].reshape(3, 3)
        across, fingers, normal = R[:, 0], R[:, 2], -R[:, 1]   # the right palm faces -y
        half_palm = m.geom_size[m.geom("infant_0/right_palm").id][1]
        r = 0.01 if toy == "rattle" else 0.02
        handle = d.site_xpos[self.site] + (half_palm + r + 0.002) * normal + 0.01 * fingers
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, np.stack([across, fingers, normal], 1).ravel())
        # the rattle's handle lies at x = -4.5 cm in its frame
        d.qpos[self.toy_q:self.toy_q + 3] = handle + (0.045 if toy == "rattle" else 0.0) * across
        d.qpos[self.toy_q + 3:self.toy_q + 7] = quat
        d.qvel[self.toy_v:self.toy_v + 6] = 0.0
        mujoco.mj_kinematics(m, d)

    def hand_force(self) -> float:
        """Normal force (N) of all contacts between the toy and the right hand's geoms."""
        m, d = self.m, self.d
        f, buf = 0.0, np.zeros(6)
        for n in range(d.ncon):
            g1, g2 = int(d.contact.geom1[n]), int(d.contact.geom2[n])
            if (g1 in self.toy_geoms and g2 in self.hand_geoms) or \
                    (g2 in self.toy_geoms and g1 in self.hand_geoms):
                mujoco.mj_contactForce(m, d, n, buf)
                f += abs(buf[0])
        return f


def grasp_and_lift(grip: float, toy: str = "rattle") -> dict:
    inf = Infant(toy)
    for _ in range(30):                       # curl the fingers into a hook
        inf.step(min(grip, 0.15))
    inf.put_in_hand(toy)
    toy0 = inf.d.xpos[inf.toy][2]
    for _ in range(30):                       # close them on the handle
        inf.step(grip)
    palm0 = inf.d.site_xpos[inf.site][2]
    elbow = inf.names.index("right_elbow")
    start = inf.target[elbow]
    for t in range(150):                      # flex the elbow by 1.5 rad: the hand rises
        inf.target[elbow] = start - 1.5 * min(1.0, t / 100)
        inf.step(grip)
    return {"toy_rise": inf.d.xpos[inf.toy][2] - toy0,
            "palm_rise": inf.d.site_xpos[inf.site][2] - palm0,
            "force": inf.hand_force(), "toy_z": inf.d.xpos[inf.toy][2]}


def test_an_infant_grasps_the_rattle_and_lifts_it_with_its_motors():
    held = grasp_and_lift(0.5)
    assert held["palm_rise"] > 0.06, held
    assert held["toy_rise"] > 0.05, held          # measured: 12 cm
    assert held["toy_rise"] > 0.8 * held["palm_rise"], held   # it rose with the hand
    assert held["force"] > 0.5, held              # the hand still presses on it (several N)


def test_with_open_fingers_the_rattle_falls_out_of_the_hand():
    dropped = grasp_and_lift(0.0)
    assert dropped["palm_rise"] > 0.06, dropped
    assert dropped["toy_rise"] < -0.03, dropped   # it fell onto the mat (5 cm down)
    assert dropped["toy_z"] < 0.08, dropped      # measured: its origin 5.1 cm above the mat
    assert dropped["force"] == 0.0, dropped
