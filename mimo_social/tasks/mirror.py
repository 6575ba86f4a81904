"""Mirror: two infants face to face; the learner copies the face its partner shows.

| | |
|---|---|
| agents | 2: `infant_0` (the learner) and `infant_1` (the partner: scripted, e.g. `ExpressionShow`, or a second learner) |
| body | standing, hip fixed in the world, every joint held except head and eyes; the task points each head and both eyes at the partner's face every control step (as in reach) |
| scene | the two infants `distance` (0.3 m) apart, face to face: the partner's face fills about a third of each 64x64 eye image (see docs/social/mirror_views.png) |
| reset | both faces neutral, heads and eyes on the partner's face; nothing random in the task (a scripted partner draws its faces and how long it shows them) |
| action | `Dict(motors=Box(0,), expression=Discrete(7))`: the expression is the action (no motor is free; the empty motor Box flattens to nothing in `FlattenParallel` / `make_sb3_single`, which leave 7 expression logits) |
| observation | `eye_left`, `eye_right` (64x64x3 RGB; the only way the partner's face reaches the learner), `proprioception` (36: its own joints, the head and eye angles); never the partner's expression |
| reward | +1 on a step where the agent's expression equals its partner's, else 0; with `scripted_partner` (set by `scripted_env`) only `infant_0` is rewarded and `infant_1` has no eyes |
| success | `is_success` = `match`: the two expressions are equal on this step |
| termination | none; truncation at 500 steps (5 s) |
| privileged cues | the task points the head and eyes at the partner's face (the learner need not find it); the partner's expression only through the eyes |
| baselines | random policy (uniform expression, 20 episodes of 500 steps, scripted partner; no command in the package): return 70.4 +- 6.5, success rate 0.141 +- 0.013 (chance: 1/7 = 0.143). PPO with `--normalize-obs`, scripted `ExpressionShow` partner, gamma 0, 32x32 eyes, 2 seeds, 60k env steps (5.7 min): 99.2 % of steps matched (return 496 of 500) at the first evaluation, 10k steps (50 s), for both seeds; on 20 fresh episodes 496.2 +- 0.4 and 496.1 +- 0.4; the 4 missed steps an episode are the one-step lag after each of the partner's changes (`mimo-social train --task mirror --mode scripted --algo ppo --steps 60000 --seed 0 --out runs/mirror_s0 --normalize-obs --algo-kwargs '{"gamma": 0.0}' --env-kwargs '{"per_agent": [{"vision": {"width": 32, "height": 32}}, {}]}'`). Without input normalisation PPO stayed at chance (three variants, 70k-120k steps) |
| sources | not in the MIMo paper: a social task of this package; rationale (facial mimicry, the correspondence problem) and figures: `docs/social/mirror.md` |
| version history | v0: first version, with joint attention and the scripted partners `ExpressionShow` and `GazeAtTarget` |

The learner's action and the partner's shown on the same step are compared; the eye images of
a step show the faces as the previous step left them, so a copy lags the model by one step (10
ms): the best reactive policy loses one step per change of the partner's face.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..body.joint_groups import GAZE_JOINTS, held_posture
from ..body.tables import load_body
from ..core.kinematics import Gaze
from ..core.task import Task, TaskOptions
from ..core.world import AgentSetup
from .common import face_to_face

DISTANCE = 0.3
EYE_SIZE = 64


@dataclass(frozen=True)
class MirrorOptions(TaskOptions):
    """Distance between the faces (m, from 0.22: closer and the faces touch) and whether
    ``infant_1`` is a scripted partner (no eyes, no reward)."""

    task = "mirror"
    distance: float = DISTANCE
    scripted_partner: bool = False

    def __post_init__(self):
        self._number("distance", 0.22, 2.0)
        self._bool("scripted_partner")


class Mirror(Task):
    name = "mirror"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 500
    Options = MirrorOptions

    def agent_defaults(self, i, settings):
        scripted = i == 1 and self.options.scripted_partner
        return {"posture": "standing", "expressions": True, "vestibular": False,
                "vision": False if scripted else {"width": EYE_SIZE, "height": EYE_SIZE}}

    def setup(self, i, config):
        dist = self.options.distance
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
            self._weights = np.array([1.0, 0.0 if self.options.scripted_partner else 1.0])
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
