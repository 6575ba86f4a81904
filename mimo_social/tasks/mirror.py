"""Mirror: two infants face to face; the learner copies the face its partner shows.

| | |
|---|---|
| agents | 2: `infant_0` (the learner) and `infant_1` (the partner: scripted, e.g. `ExpressionShow`, or a second learner) |
| body | standing, hip fixed in the world, every joint held except head and eyes; the task points each head and both eyes at the partner's face every control step (as in reach) |
| scene | the two infants `distance` (0.3 m) apart, face to face: the partner's face fills about a third of each 64x64 eye image (see docs/social/mirror_views.png) |
| observation | `eye_left`, `eye_right` (64x64 RGB; the only way the partner's face reaches the learner), `proprioception` (its own joints: the head and eye angles); never the partner's expression |
| action | `Dict(motors=Box(0,), expression=Discrete(7))`: the expression is the action (no motor is free; the empty motor Box flattens to nothing in `FlattenParallel` / `make_sb3_single`, which leave 7 expression logits) |
| reward | +1 on a step where the agent's expression equals its partner's, else 0; with `scripted_partner` (set by `scripted_env`) only `infant_0` is rewarded and `infant_1` has no eyes |
| success | `is_success` = `match`: the two expressions are equal on this step |
| termination | none; truncation at 500 steps (5 s) |

The learner's action and the partner's shown on the same step are compared; the eye images of
a step show the faces as the previous step left them, so a copy lags the model by one step (10
ms): the best reactive policy loses one step per change of the partner's face.

Why: infants imitate facial gestures and, in the second year, match and use others' emotional
expressions (facial mimicry, emotional contagion and social referencing: looking at a
caregiver's face to read how to react). Matching a seen face with one's own unseen face is the
classic "correspondence problem" of imitation: the learner sees the partner's face but never its
own, so it must learn which of its own expressions corresponds to which image.
"""

from __future__ import annotations

import numpy as np

from ..body.tables import load_body
from ..core.world import AgentSetup
from ..core.task import GAZE_JOINTS, Gaze, Task, face_to_face, held_posture

DISTANCE = 0.3
EYE_SIZE = 64


class Mirror(Task):
    name = "mirror"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 500

    def option_defaults(self) -> dict:
        return {"distance": DISTANCE, "scripted_partner": False}

    def __init__(self, n_agents: int, **options):
        super().__init__(n_agents, **options)
        d = self.options["distance"]
        if isinstance(d, bool) or not isinstance(d, (int, float)) or not 0.22 <= d <= 2.0:
            raise ValueError(f"mirror: distance={d!r}; allowed: a number of metres from 0.22 "
                             "(closer and the faces touch) to 2.0")
        if not isinstance(self.options["scripted_partner"], bool):
            raise ValueError(f"mirror: scripted_partner={self.options['scripted_partner']!r}; "
                             "allowed: True or False")

    def agent_defaults(self, i):
        scripted = i == 1 and self.options["scripted_partner"]
        return {"posture": "standing", "expressions": True, "vestibular": False,
                "vision": False if scripted else {"width": EYE_SIZE, "height": EYE_SIZE}}

    def setup(self, i, config):
        dist = float(self.options["distance"])
        pos, facing = face_to_face(i, dist)
        tables = load_body(config.hands)
        frozen = held_posture(tables, keep=GAZE_JOINTS,
                              angles={"right_knee": -5, "left_knee": -5})
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=(), gaze_joints=GAZE_JOINTS)

    def reset(self, env, rng):
        if not hasattr(self, "_gaze"):
            w = env.world
            self._gaze = [Gaze(w, i) for i in range(2)]
            self._faces = [int(w.agents[i].head_site) for i in range(2)]
            self._weights = np.array([1.0, 0.0 if self.options["scripted_partner"] else 1.0])
        self._match = False
        self.before_physics(env)

    def before_physics(self, env):
        m, d = env.world.model, env.world.data
        for i in range(2):
            self._gaze[i](m, d, "site", self._faces[1 - i])

    def rewards(self, env):
        w = env.world
        self._match = w.expression_of(0) == w.expression_of(1)
        return self._weights * float(self._match)

    def terminations(self, env):
        info = {"match": self._match, "is_success": self._match}
        return np.zeros(2, bool), [dict(info), dict(info)]
