"""The mirror task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ...body.joint_groups import GAZE_JOINTS, held_posture
from ...core.kinematics import Gaze
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup
from ...expressions.faces import EXPRESSIONS
from ..common import face_to_face
from ..dyad import held_angles, tables_of, task_plan
from ...core.factory import make_aec, make_parallel, with_options

__all__ = ["parallel_env", "env", "scripted_env", "Mirror", "MirrorOptions"]

DISTANCE = 0.3
EYE_SIZE = 64
ROLES = ("leader", "free")
N_FACES = len(EXPRESSIONS)


@dataclass(frozen=True)
class MirrorOptions(TaskOptions):
    """Distance between the faces (m, from 0.25: closer and the toes overlap), whether
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
        self._number("distance", 0.25, 2.0)   # closer, the toes overlap (1.9 cm at 0.22)
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

    def held_joints(self, i, config):
        """Agent i's held joints (rad): all (but head and eyes with ``assisted_gaze``), standing
        knees a little bent, or its own posture's angles."""
        gaze = GAZE_JOINTS if self.options.assisted_gaze else ()
        angles = held_angles(config, "standing", {"right_knee": -5, "left_knee": -5})
        return held_posture(tables_of(config), keep=gaze, angles=angles)

    def setup(self, i, config):
        # two 18-month-olds stand `distance` apart; other bodies (a kneeling adult) at the
        # distance scaled with their reach, looking at each other's face (tasks/dyad.py)
        plan = task_plan(self, "standing", self.options.distance, self.held_joints,
                         () if self.options.assisted_gaze else (0, 1))
        pos, facing = face_to_face(i, plan.distance)
        gaze = GAZE_JOINTS if self.options.assisted_gaze else ()
        frozen = {**self.held_joints(i, config), **plan.gaze[i]}
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=(), gaze_joints=gaze)

    @property
    def leading(self) -> bool:
        """Whether one of two learners leads (its face set by the task) this env."""
        return self.options.roles == "leader" and not self.options.scripted_partner

    def bind(self, env):
        """Index tables of this world (once per world: :meth:`Task.bind`)."""
        w = env.world
        self._gaze = [Gaze(w, i) for i in range(2)] if self.options.assisted_gaze else []
        self._faces = [int(w.agents[i].head_site) for i in range(2)]

    def reset(self, env, rng):
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


# -- the env factories (``mimo_social.envs.mirror_v0`` re-exports them) -------------------

def parallel_env(**kwargs):
    return make_parallel(Mirror, **kwargs)


def env(**kwargs):
    return make_aec(Mirror, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ...partners import ScriptedPartners
    from ...partners.expression import ExpressionShow
    options = with_options(Mirror, kwargs.pop("task_options", None), scripted_partner=True)
    penv = parallel_env(task_options=options, **kwargs)
    # the partner: the second agent (caregiver_0 when it is the adult)
    return ScriptedPartners(penv, {penv.possible_agents[1]: partner or ExpressionShow()})
