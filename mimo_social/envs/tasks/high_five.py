"""High five: two standing infants, face to face, bring their right hands together.

| | |
|---|---|
| agents | 2 (`infant_0`, `infant_1`), 0.45 m apart, facing each other |
| body | hip fixed in the world; trunk, legs, left arm held; head and eyes fixate the partner's right hand (set by the task each control step) |
| action | the right-arm motors (mitten hands: 8, shoulder 3, elbow, wrist 3, fingers; five fingers: 29), plus the expression when expressions are on |
| observation | `proprioception` (head and eye angles tell where the partner's hand is), `vestibular` |
| reward (both) | `-distance(right palms)` per step, `+touch_bonus` (100) on the step the right hands touch |
| termination | both, when the right hands touch (if `end_on_touch`); truncation at `max_steps` (500) |
"""

from __future__ import annotations

import numpy as np

from ...body.tables import load_body
from ..world import AgentSetup
from .base import (GAZE_JOINTS, ContactProbe, Gaze, Task, hand_geoms, held_posture,
                   right_arm_joints)

DISTANCE = 0.45


class HighFive(Task):
    name = "high_five"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 500

    def option_defaults(self) -> dict:
        return {"touch_bonus": 100.0, "end_on_touch": True, "distance": DISTANCE}

    def agent_defaults(self, i):
        return {"posture": "standing"}

    def setup(self, i, config):
        dist = float(self.options["distance"])
        pos = (0.0, 0.0) if i == 0 else (dist, 0.0)
        facing = (dist, 0.0) if i == 0 else (0.0, 0.0)
        tables = load_body(config.hands)
        arm = right_arm_joints(tables)
        frozen = held_posture(tables, keep=arm + GAZE_JOINTS,
                              angles={"right_knee": -5, "left_knee": -5})
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=arm,
                          gaze_joints=GAZE_JOINTS)

    def _hand_geoms(self, env, i):
        return hand_geoms(env.world, i)

    def reset(self, env, rng):
        if not hasattr(self, "_gaze"):
            self._gaze = [Gaze(env.world, i) for i in range(2)]
            self._palms = [env.world.agents[i].palm_sites[0] for i in range(2)]
            self._hands_meet = ContactProbe(env.world.model.ngeom, self._hand_geoms(env, 0),
                                            self._hand_geoms(env, 1))
        self._touching = False
        self.before_physics(env)

    def before_physics(self, env):
        m, d = env.world.model, env.world.data
        for i in range(2):
            self._gaze[i](m, d, "site", self._palms[1 - i])

    def rewards(self, env):
        d = env.world.data
        a0, a1 = env.world.agents
        dist = np.linalg.norm(d.site_xpos[a0.palm_sites[0]] - d.site_xpos[a1.palm_sites[0]])
        self._touching = self._hands_meet(d)
        r = -dist + (self.options["touch_bonus"] if self._touching else 0.0)
        self._distance = dist
        return np.array([r, r])

    def terminations(self, env):
        done = self._touching and self.options["end_on_touch"]
        info = {"hands_touching": self._touching, "hand_distance": float(self._distance)}
        return np.array([done, done]), [dict(info), dict(info)]
