"""Mirror: two infants face to face; the follower copies the face its partner shows.

| | |
|---|---|
| agents | 2: `infant_0` (the learner) and `infant_1` (the partner: scripted, e.g. `ExpressionShow`, or a second learner) |
| body | standing, hip fixed in the world, every joint held; head and eyes held at rest, looking straight ahead: the partner's face (at the same height, `distance` away) is in the middle of both eye images without any aiming. With `assisted_gaze` the head and eyes are free joints that the task points at the partner's face every control step (the first version) |
| scene | the two infants `distance` (0.3 m) apart, face to face: the partner's face fills about a third of each 64x64 eye image (see docs/social/mirror_views.png) |
| reset | both faces neutral; two learners with `roles="leader"` (default): one of them, drawn at random (seeded), is the episode's leader; nothing else random in the task (a scripted partner draws its faces and how long it shows them) |
| action | `Dict(motors=Box(0,), expression=Discrete(7))`: the expression is the action (no motor is free; the empty motor Box flattens to nothing in `FlattenParallel` / `make_sb3_single`, which leave 7 expression logits). The leader's expression action is ignored: its face is set by the task (below) |
| observation | `eye_left`, `eye_right` (64x64x3 RGB; the only way the partner's face reaches the learner), `proprioception` (its own joints: none are free by default, so 0 floats; 36 with `assisted_gaze`: the head and eye angles, constant since neither face moves); never the partner's expression |
| two learners | `roles="leader"` (default): per episode one agent is the leader, whose face the task's script sets (each face held for a time drawn from `leader_hold_s` (1-2 s), the next one drawn among the other six); only the other agent, the follower, is rewarded. No fixed face can earn more than chance (1/7 of the steps): copying is the only way to the reward. With a shared policy each agent is the follower in about half the episodes (the leader's reward is 0 whatever it does, so its steps carry no gradient in expectation). `roles="free"`: both faces are the agents' own actions and both are rewarded on every match: any shared convention ("always neutral", or any fixed face) earns the full reward without looking; for studying how a convention forms, not mimicry |
| reward | the follower: +1 on a step where its expression equals its partner's, else 0; the leader 0. With `scripted_partner` (set by `scripted_env`) `infant_0` is the follower and `infant_1` has no eyes; with `roles="free"` both are rewarded on a match |
| success | per episode: `is_success` becomes True on the step at which the matched steps reach `success_fraction` (0.8) of the episode's `max_steps` (500: 400 steps), i.e. the step from which the episode can no longer fail; the last step's value is the episode's verdict. A reactive copier misses one step per change of the partner's face (about 4 an episode: 99 % matched); chance (1/7 of the steps) never comes near 80 % (random and zero: 0 %) |
| termination | none; truncation at 500 steps (5 s) |
| infos | `match` (the faces are equal this step), `matched_steps` (so far this episode), `is_success`, `is_leader` (this agent's face is set by the task this episode) |
| options | `distance` (0.3 m, 0.22 to 2.0), `scripted_partner` (False), `assisted_gaze` (False), `roles` (`"leader"`, or `"free"`), `leader_hold_s` ((1.0, 2.0) s), `success_fraction` (0.8, 0.01 to 1) |
| privileged cues | none by default: the partner's face reaches the learner only through its eyes, which look straight ahead at it (the posture). `assisted_gaze` (False): the task points head and eyes at the partner's face; it would leak no expression (the face does not move, so the angles are the same every step and every episode), kept as an option for other `distance` / posture settings. The reward reads both expressions from the world (the reward is no observation) |
| baselines | 20 episodes of 500 steps, seeds 1000-1019, scripted `ExpressionShow` partner, the learner's eyes rendered (`docs/social/mirror.md` gives the script): random policy (uniform expression) 0 / 20 successes, return 70.2 +- 9.5; zero action (always neutral, the two-learner convention) 0 / 20, 93.0 +- 93.6; always happy 0 / 20, 70.5 +- 105.9; scripted `MirrorController` (copies the partner's face read from the world) 20 / 20, 496.5 +- 0.7, success secured at step 402.8 on average. PPO, scripted partner (`--normalize-obs`, gamma 0, 32x32 eyes, 2 seeds, 30k env steps, 3.7 and 9 min on the loaded machine): 100 % evaluation success from the first evaluation (5k env steps, 30 s) on, both seeds; on 20 fresh episodes (seeds 1000-1019) 20 / 20 for both, return 496.5 +- 0.7, success secured at step 403: the scripted mirror's level (`mimo-social compare --task mirror --mode scripted --algos ppo --seeds 2 --steps 30000 --out runs/mirror15 --eval-every 5000 --eval-episodes 10 --normalize-obs --algo-kwargs '{"gamma": 0.0}' --env-kwargs '{"per_agent": [{"vision": {"width": 32, "height": 32}}, {}]}'`, then `mimo-social baselines mirror --episodes 20 --seed 1000 --run runs/mirror15/ppo_seed0 runs/mirror15/ppo_seed1`). Without input normalisation PPO stayed at chance (first version, three variants, 70k-120k steps) |
| sources | not in the MIMo paper: a social task of this package; rationale (facial mimicry, the correspondence problem) and figures: `docs/social/mirror.md` |
| version history | v0: first version, with joint attention and the scripted partners `ExpressionShow` and `GazeAtTarget`; v0, issue 15: success per episode (`success_fraction` of the steps matched; it was the step's match, which random met on 14 % of the steps), head and eyes held looking straight ahead (the task's aiming is the `assisted_gaze` option), two learners as leader (face set by the task) and follower by default (`roles`; the old symmetric reward, where "always neutral" earns everything, is `roles="free"`); v0, issue 18: partners of other bodies (`tasks/dyad.py`, docs/bodies.md): placed by their measured reach, each in its own posture, held heads and eyes on the partner's face (a kneeling adult 0.37 m away); two 18-month-olds unchanged |

The learner's action and the partner's face shown on the same step are compared; the eye images
of a step show the faces as the previous step left them, so a copy lags the model by one step
(10 ms): the best reactive policy loses one step per change of the partner's face.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..body.joint_groups import GAZE_JOINTS, held_posture
from ..core.kinematics import Gaze
from ..core.task import Plot, Task, TaskOptions
from ..core.world import AgentSetup
from ..expressions.faces import EXPRESSIONS
from .common import face_to_face
from .dyad import held_angles, tables_of, task_plan

DISTANCE = 0.3
EYE_SIZE = 64
ROLES = ("leader", "free")
N_FACES = len(EXPRESSIONS)


@dataclass(frozen=True)
class MirrorOptions(TaskOptions):
    """Distance between the faces (m, from 0.22: closer and the faces touch), whether
    ``infant_1`` is a scripted partner (no eyes, no reward), whether the task aims head and eyes
    at the partner's face (``assisted_gaze``), the two learners' roles (``"leader"``: one agent's
    face is set by the task each episode, only the other is rewarded; ``"free"``: both act and
    both are rewarded on a match), the leader's hold times (s) and the fraction of the
    episode's steps that must match for success."""

    task = "mirror"
    privileged: ClassVar[tuple[str, ...]] = ("assisted_gaze",)
    distance: float = DISTANCE
    scripted_partner: bool = False
    assisted_gaze: bool = False
    roles: str = "leader"
    leader_hold_s: tuple = (1.0, 2.0)
    success_fraction: float = 0.8

    def __post_init__(self):
        self._number("distance", 0.22, 2.0)
        self._bool("scripted_partner")
        self._bool("assisted_gaze")
        self._choice("roles", ROLES)
        self._numbers("leader_hold_s", 2, 0.01, 60.0, rising=True,
                      allowed="(min, max) seconds, 0.01 <= min <= max <= 60")
        self._number("success_fraction", 0.01, 1.0)


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

    def _held(self, i, config):
        """Agent i's held joints (rad): all (but head and eyes with ``assisted_gaze``), standing
        knees a little bent, or its own posture's angles."""
        gaze = GAZE_JOINTS if self.options.assisted_gaze else ()
        angles = held_angles(config, "standing", {"right_knee": -5, "left_knee": -5})
        return held_posture(tables_of(config), keep=gaze, angles=angles)

    def setup(self, i, config):
        # two 18-month-olds stand `distance` apart; other bodies (a kneeling adult) at the
        # distance scaled with their reach, looking at each other's face (tasks/dyad.py)
        plan = task_plan(self, "standing", self.options.distance, self._held,
                         () if self.options.assisted_gaze else (0, 1))
        pos, facing = face_to_face(i, plan.distance)
        gaze = GAZE_JOINTS if self.options.assisted_gaze else ()
        frozen = {**self._held(i, config), **plan.gaze[i]}
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=(), gaze_joints=gaze)

    @property
    def leading(self) -> bool:
        """Whether one of two learners leads (its face set by the task) this env."""
        return self.options.roles == "leader" and not self.options.scripted_partner

    def reset(self, env, rng):
        if not hasattr(self, "_faces"):
            w = env.world
            self._gaze = [Gaze(w, i) for i in range(2)] if self.options.assisted_gaze else []
            self._faces = [int(w.agents[i].head_site) for i in range(2)]
        self._rng = rng
        self._leader = int(rng.integers(2)) if self.leading else -1
        if self._leader >= 0:
            self._weights = np.zeros(2)
            self._weights[1 - self._leader] = 1.0
        elif self.options.scripted_partner:
            self._weights = np.array([1.0, 0.0])
        else:
            self._weights = np.ones(2)
        self._shown = None        # the leader's face (the task's script) and its steps left
        self._left = 0
        self._need = max(1, math.ceil(self.options.success_fraction * env.max_steps - 1e-9))
        self._match = False
        self._matched = 0
        self._aim(env)

    def _aim(self, env):
        if self._gaze:
            m, d = env.world.model, env.world.data
            for i in range(2):
                self._gaze[i](m, d, "site", self._faces[1 - i])

    def _lead(self, env):
        """The leader's face: held for a time drawn from ``leader_hold_s``, then another one."""
        if self._left <= 0:
            faces = np.arange(N_FACES)
            if self._shown is not None:
                faces = faces[faces != self._shown]
            self._shown = int(self._rng.choice(faces))
            lo, hi = self.options.leader_hold_s
            self._left = max(1, int(round(self._rng.uniform(lo, hi) / env.dt)))
        self._left -= 1
        env.world.set_expression(self._leader, self._shown)

    def before_physics(self, env):
        if self._leader >= 0:
            self._lead(env)
        self._aim(env)

    def rewards(self, env):
        w = env.world
        self._match = w.expression_of(0) == w.expression_of(1)
        self._matched += int(self._match)
        return self._weights * float(self._match)

    def plots(self):
        """Reward, matched expression (the two faces the same) and the matched steps as a share
        of those success needs."""
        return [Plot.reward(),
                Plot("match", "0/1", lambda env: self._match, per_agent=False),
                Plot("matched_share", "of success", lambda env: self._matched / self._need,
                     per_agent=False)]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"match": "number", "matched_steps": "number", "is_success": "number",
                "is_leader": "number"}

    def terminations(self, env):
        success = self._matched >= self._need
        infos = [{"match": self._match, "matched_steps": self._matched, "is_success": success,
                  "is_leader": i == self._leader} for i in range(2)]
        return np.zeros(2, bool), infos
