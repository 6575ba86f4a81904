"""Pictures for people that need a whole scene: the skin of a hand holding a ball (paper Fig. 5b).

``mimo-social figure skin-hand-ball OUT.png`` draws it (:mod:`mimo_social.cli.figure`).
"""

from __future__ import annotations

import mujoco
import numpy as np

from .body.postures import POSTURES
from .body.tables import load_body
from .core.env import MimoParallelEnv
from .body.joint_groups import held_posture
from .core.world import AgentSetup, Prop
from .senses.touch import save_skin_png
from .tasks.free_play import FreePlay

__all__ = ["HOLD_BALL_ARM", "hand_ball_scene", "save_hand_ball_png", "FIGURES"]


# the right arm held forward, palm up, the hand tilted 12 degrees towards the fingertips
# (degrees; found by minimising the palm's deviation from that pose over the arm's joints)
HOLD_BALL_ARM = {"right_shoulder_horizontal": 95.7, "right_shoulder_abduction": 24.3,
                 "right_shoulder_rotation": -89.7, "right_elbow": -84.2,
                 "right_wrist_rotation": -76.9, "right_wrist_flexion": 34.7,
                 "right_wrist_ulnar": 12.3}


def hand_ball_scene(steps: int = 100, touch: dict | bool = True, ball_radius: float = 0.025,
                    grip: float = -0.1, along: float = 0.015):
    """A sitting infant holding a ball in its upturned right hand, the mitten closing over it.

    Every joint but the mitten fingers is held (the arm forward, palm up: :data:`HOLD_BALL_ARM`);
    the infant sits on the floor as one rigid body (so MuJoCo's parent-child contact filter
    keeps the fingers from colliding with the palm). After the infant has settled, the ball
    (``ball_radius``, 0.1 kg) is laid on the palm, ``along`` m from its centre towards the
    fingers, and the mitten closes on it with action ``grip`` for ``steps`` control steps (the
    ball then rests in the cup of palm, fingers and wrist). Returns the env.
    """
    class HoldBall(FreePlay):
        def setup(self, i, config):
            angles = dict(POSTURES["sitting"]["joints"])
            angles.update(HOLD_BALL_ARM)
            frozen = held_posture(load_body(config.hands), keep=("right_fingers",), angles=angles)
            return AgentSetup(config, position=(0.0, 0.0), facing=(1.0, 0.0), frozen=frozen,
                              actuated=("right_fingers",))

        def props(self):
            return [Prop("ball", "sphere", (ball_radius,), (0.5, 0.5, ball_radius), 0.1,
                         (0.9, 0.25, 0.2, 1.0))]

    env = MimoParallelEnv(HoldBall(1), touch=touch, posture="sitting", expressions=False,
                          proprioception=False)
    env.reset(seed=0)
    w = env.world
    m, d = w.model, w.data
    a = w.agents[0]
    name = env.agents[0]
    rest = {name: np.zeros(1, np.float32)}
    for _ in range(50):                                 # let the sitting infant settle
        env.step(rest)
    hand = m.site_bodyid[a.palm_sites[0]]
    palm_normal = -d.xmat[hand].reshape(3, 3)[:, 1]   # the palm side of the right mitten
    q = w.prop_qpos["ball"]
    along_hand = d.xmat[hand].reshape(3, 3)[:, 2]
    d.qpos[q:q + 3] = (d.site_xpos[a.palm_sites[0]] + (0.0105 + ball_radius) * palm_normal
                       + along * along_hand)
    d.qpos[q + 3:q + 7] = (1.0, 0.0, 0.0, 0.0)
    mujoco.mj_forward(m, d)
    hold = {name: np.array([grip], np.float32)}
    for _ in range(steps):
        env.step(hold)
    return env


def save_hand_ball_png(path, steps: int = 100) -> str:
    """The paper's Fig. 5b: the skin of a hand holding a ball, coloured by force, as a PNG."""
    env = hand_ball_scene(steps)
    parts = ["right_lower_arm", "right_hand", "right_fingers"]
    view = getattr(env, "unwrapped", env).system("touch").view(0)
    total = sum(view[k]["normal_force"].sum() for k in parts)
    w = env.world
    ball = w.data.xpos[w.prop_bodies["ball"]]
    radius = float(w.model.geom_size[w.model.geom("ball").id, 0])
    side = w.data.xmat[w.model.site_bodyid[w.agents[0].palm_sites[0]]].reshape(3, 3)[:, 0]
    out = save_skin_png(env, 0, path, parts=parts, spheres=[(ball, radius)], elev=35.0,
                        azim=float(np.degrees(np.arctan2(side[1], side[0]))) + 35.0,
                        title=f"right hand holding a ball (0.1 kg): {total:.2f} N normal force "
                              "sensed")
    env.close()
    return out


#: the figures ``mimo-social figure NAME OUT.png`` draws: name -> (function(path), what it shows)
FIGURES = {
    "skin-hand-ball": (save_hand_ball_png, "the skin of a hand holding a ball, coloured by force "
                                           "(paper Fig. 5b)"),
}
