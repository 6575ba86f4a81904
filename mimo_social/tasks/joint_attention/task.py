"""The joint_attention task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from ...body.joint_groups import GAZE_JOINTS, held_posture
from ...body.postures import posture_joints
from ...body.sight import gaze_rays
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup, Prop
from ..common import face_to_face
from ..dyad import held_angles, tables_of, task_plan
from ...core.factory import make_aec, make_parallel, with_options

__all__ = ["parallel_env", "env", "scripted_env", "JointAttention", "JointAttentionOptions"]

DISTANCE = 0.7
EYE_SIZE = 96
TOY_SIZE = 0.035
TOYS = (("sphere", (0.9, 0.15, 0.15, 1.0)), ("box", (0.15, 0.35, 0.9, 1.0)),
        ("sphere", (0.95, 0.85, 0.1, 1.0)), ("box", (0.15, 0.7, 0.2, 1.0)))
SIDE = (0.25, 0.45)          # toys this far (m) off the line between the infants
MAX_TRIES = 500
INSTRUCTION_HOLD_S = (1.5, 3.0)   # a leader's instruction lasts this long (as GazeAtTarget's holds)
MIN_TARGET_S = 1.0           # success needs at least this much time with a target
TWO_LEARNERS = ("leader", "shared")


class GazeRays:
    """Each agent's gaze ray (from between its eyes along the eyes' mean viewing axis) and the
    toy it lands on; index tables resolved once. Every toy counts as a sphere of ``toy_radius``
    (for the cubes: their inscribed sphere plus 18 %)."""

    def __init__(self, world, toy_bodies, toy_radius: float, margin_deg: float):
        self.cams = np.array([a.eye_cameras for a in world.agents], dtype=np.intp)  # (n, 2)
        self.toys = np.asarray(toy_bodies, dtype=np.intp)
        self.radius = float(toy_radius)
        self.margin = np.deg2rad(margin_deg)

    def rays(self, data) -> tuple[np.ndarray, np.ndarray]:
        """Origins (n, 3) and unit directions (n, 3); a camera looks along its frame's -z."""
        return gaze_rays(data, self.cams)

    def angles(self, data) -> tuple[np.ndarray, np.ndarray]:
        """Angle (rad) from each agent's ray to each toy centre (n, k), and each toy's angular
        radius seen from each agent (n, k)."""
        origin, direction = self.rays(data)
        to_toy = data.xpos[self.toys][None, :, :] - origin[:, None, :]
        dist = np.linalg.norm(to_toy, axis=2)
        cos = np.einsum("nkc,nc->nk", to_toy, direction) / dist
        return np.arccos(np.clip(cos, -1.0, 1.0)), np.arcsin(np.minimum(1.0, self.radius / dist))

    def looked_at(self, data) -> tuple[np.ndarray, np.ndarray]:
        """Per agent, the toy its gaze lands on (-1: none), and the angles of :meth:`angles`."""
        angle, radius = self.angles(data)
        excess = angle - radius
        best = np.argmin(excess, axis=1)
        hit = excess[np.arange(len(best)), best] <= self.margin
        return np.where(hit, best, -1), angle



@dataclass(frozen=True)
class JointAttentionOptions(TaskOptions):
    """Distance between the infants (m), number of toys, the gaze margin around a toy (deg),
    the shaping weight, the share of steps on target for success, the scripted partner's head
    share (mean, jitter), the two-learner convention, the toys' least angular separation (deg),
    head support, and whether ``infant_1`` is a scripted partner (no eyes, no reward)."""

    task = "joint_attention"
    distance: float = DISTANCE
    n_toys: int = len(TOYS)
    margin_deg: float = 5.0
    shaping: float = 0.1
    success_share: float = 0.6
    partner_head_share: float = 0.3
    partner_head_jitter: float = 0.3
    two_learners: str = "leader"
    min_separation_deg: float = 25.0
    head_support: bool = True
    scripted_partner: bool = False

    def __post_init__(self):
        # closer, the sitting infants' feet overlap (1.1 cm at 0.68 m, 3.6 cm at 0.6)
        self._number("distance", 0.7, 1.5)
        self._int("n_toys", 2, len(TOYS))
        self._number("margin_deg", 0.0, 30.0)
        self._number("shaping", 0.0, 100.0)
        self._number("success_share", 0.05, 1.0)
        self._number("partner_head_share", 0.0, 1.0)
        self._number("partner_head_jitter", 0.0, 0.5)
        self._choice("two_learners", TWO_LEARNERS)
        self._number("min_separation_deg", 0.0, 35.0)
        self._bool("head_support")
        self._bool("scripted_partner")


class JointAttention(Task):
    name = "joint_attention"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 500
    Options = JointAttentionOptions

    def __init__(self, n_agents: int, options=None, /, **values):
        super().__init__(n_agents, options, **values)
        self.toy_bodies: np.ndarray | None = None   # body ids of the toys, set at the first reset
        o = self.options
        #: the range of head shares the scripted partner draws from per gaze shift (read by
        #: GazeAtTarget when it is not given its own)
        self.partner_head_share = (max(0.0, o.partner_head_share - o.partner_head_jitter),
                                   min(1.0, o.partner_head_share + o.partner_head_jitter))
        # two learners in "leader" mode: a leader (with an instruction) and a follower
        self._instructed = not o.scripted_partner and o.two_learners == "leader"
        self.leader = 1          # the scripted partner leads; with two learners, drawn per episode
        self.instruction = -1    # the toy the leader is told to look at ("leader" mode)

    def agent_defaults(self, i, settings):
        scripted = i == 1 and self.options.scripted_partner
        return {"posture": "sitting", "expressions": False, "vestibular": False,
                "vision": False if scripted else {"width": EYE_SIZE, "height": EYE_SIZE}}

    def held_joints(self, i, config):
        """Agent i's held joints (rad): all but head and eyes, sitting, or in its own posture
        (an adult kneeling)."""
        angles = held_angles(config, "sitting", posture_joints("sitting", config.body))
        return held_posture(tables_of(config), keep=GAZE_JOINTS, angles=angles)

    def setup(self, i, config):
        # two sitting 18-month-olds are `distance` apart; other bodies (a kneeling adult) at
        # the distance scaled with their reach (tasks/dyad.py: 1.31 m for the kneeling adult,
        # where four toys still lie 25 degrees apart seen from both heads)
        plan = task_plan(self, "sitting", self.options.distance, self.held_joints, ())
        self.pair_distance = plan.distance
        pos, facing = face_to_face(i, plan.distance)
        frozen = self.held_joints(i, config)
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=GAZE_JOINTS)

    def props(self):
        out = []
        for k in range(self.options.n_toys):
            shape, rgba = TOYS[k]
            size = (TOY_SIZE,) if shape == "sphere" else (TOY_SIZE * 0.85,) * 3
            out.append(Prop(f"toy_{k}", shape, size, (0.35, 1.0 + 0.2 * k, TOY_SIZE), 0.05, rgba))
        return out

    def task_spaces(self, env, i):
        if self._instructed:
            return {"instruction": spaces.Box(0.0, 1.0, (self.options.n_toys,), np.float32)}
        return {}

    def observe(self, env, i):
        if not self._instructed:
            return {}
        out = np.zeros(self.options.n_toys, np.float32)
        if i == self.leader and self.instruction >= 0:
            out[self.instruction] = 1.0
        return {"instruction": out}

    # -- running -------------------------------------------------------------------------------
    def bind(self, env):
        """Index tables of this world (once per world: :meth:`Task.bind`)."""
        w = env.world
        d = w.data
        n = self.options.n_toys
        self.toy_bodies = np.array([w.prop_bodies[f"toy_{k}"] for k in range(n)], np.intp)
        self._toy_qpos = [w.prop_qpos[f"toy_{k}"] for k in range(n)]
        self._rays = GazeRays(w, self.toy_bodies, TOY_SIZE, self.options.margin_deg)
        self._heads = np.array([d.site_xpos[a.head_site] for a in w.agents])
        self._weights = np.array([1.0, 0.0 if self.options.scripted_partner else 1.0])
        self._head_dofs = np.concatenate([a.dof_adr[a.actuated_joint_idx] for a in w.agents])
        self._dt = float(env.dt)

    def reset(self, env, rng):
        w = env.world
        d = w.data
        for k, xy in enumerate(self._place_toys(rng)):
            q = self._toy_qpos[k]
            yaw = rng.uniform(-np.pi, np.pi)
            d.qpos[q:q + 7] = (xy[0], xy[1], TOY_SIZE if TOYS[k][0] == "sphere"
                               else 0.85 * TOY_SIZE, np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))
        self._rng = rng
        if self._instructed:
            self.leader = int(rng.integers(2))
            self.instruction = int(rng.integers(self.options.n_toys))
            self._instruction_left = self._instruction_steps()
        else:
            self.leader, self.instruction = 1, -1
        self._looked = np.full(2, -1)
        self._targets = np.full(2, -1)
        self._angle = None
        self._on = np.zeros(2, np.int64)        # steps on target, per agent
        self._with = np.zeros(2, np.int64)      # steps with a target, per agent

    def _instruction_steps(self) -> int:
        return max(1, int(round(self._rng.uniform(*INSTRUCTION_HOLD_S) / self._dt)))

    def _place_toys(self, rng) -> list[np.ndarray]:
        """Toy positions (x, y): beside the pair (left and right alternate, so both sides hold
        toys), each at least ``min_separation_deg`` from the others seen from either head."""
        dist = getattr(self, "pair_distance", self.options.distance)
        sep = np.deg2rad(self.options.min_separation_deg)
        n = self.options.n_toys
        for _ in range(MAX_TRIES):   # whole layouts: an early toy may leave no room for a later
            first_side = rng.choice([-1.0, 1.0])
            placed: list[np.ndarray] = []
            for k in range(n):
                side = first_side * (1 if k % 2 == 0 else -1)
                for _ in range(20):
                    xy = np.array([rng.uniform(0.1, dist - 0.1), side * rng.uniform(*SIDE)])
                    if all(self._separated(xy, other, sep) for other in placed):
                        placed.append(xy)
                        break
                else:
                    break
            if len(placed) == n:
                return placed
        raise RuntimeError(f"joint_attention: could not place {n} toys {np.rad2deg(sep):.0f} "
                           "degrees apart; lower min_separation_deg")

    def _separated(self, a, b, sep) -> bool:
        for head in self._heads:
            u = np.append(a, TOY_SIZE) - head
            v = np.append(b, TOY_SIZE) - head
            cos = u @ v / (np.linalg.norm(u) * np.linalg.norm(v))
            if np.arccos(np.clip(cos, -1.0, 1.0)) < sep:
                return False
        return True

    def before_physics(self, env):
        """Head support: the head and eye joints' generalised gravity (and Coriolis) force of
        the last physics step is applied to them, as neck tone would, so a zero action holds
        the head where it is (springs and damping still pull it toward rest). In "leader"
        mode the leader's instruction moves on to another toy when its time is up."""
        if self.options.head_support:
            d = env.world.data
            d.qfrc_applied[self._head_dofs] = d.qfrc_bias[self._head_dofs]
        if self._instructed:
            self._instruction_left -= 1
            if self._instruction_left <= 0:
                others = [k for k in range(self.options.n_toys) if k != self.instruction]
                self.instruction = int(self._rng.choice(others))
                self._instruction_left = self._instruction_steps()

    def rewards(self, env):
        looked, angle = self._rays.looked_at(env.world.data)
        self._looked, self._angle = looked, angle
        # each agent's target: the toy the other looks at (the follower; both in "shared"
        # mode); the leader's instruction ("leader" mode)
        targets = looked[::-1].copy()
        if self._instructed:
            targets[self.leader] = self.instruction
        self._targets = targets
        has = targets >= 0
        on = has & (looked == targets)
        self._with += has
        self._on += on
        self._shared = on
        err = angle[np.arange(2), np.maximum(targets, 0)]
        r = on.astype(float) - self.options.shaping * np.where(has, err, 0.0)
        return self._weights * r

    def plots(self):
        """Reward, each agent's gaze error to its target toy (none while it has no target), on
        target, and the toy each looks at (-1: none)."""
        def error(env):
            t = self._targets
            if self._angle is None:
                return (float("nan"),) * 2
            err = np.rad2deg(self._angle[np.arange(2), np.maximum(t, 0)])
            return np.where(t >= 0, err, np.nan)
        return [Plot.reward(), Plot("gaze_error", "deg", error),
                Plot("on_target", "0/1", lambda env: self._shared),
                Plot("looked_at", "toy, -1 none", lambda env: self._looked)]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"looked_at": "number", "target": "number", "gaze_error_deg": "number",
                "shared": "number", "on_target_fraction": "number", "leader": "number",
                "is_success": "number"}

    def terminations(self, env):
        infos = []
        enough = self._with * self._dt >= MIN_TARGET_S - 1e-9
        frac = self._on / np.maximum(self._with, 1)
        success = enough & (frac >= self.options.success_share)
        for i in range(2):
            t = int(self._targets[i])
            err = float(np.rad2deg(self._angle[i, t])) if t >= 0 else -1.0
            infos.append({"looked_at": int(self._looked[i]), "target": t,
                          "gaze_error_deg": err, "shared": bool(self._shared[i]),
                          "on_target_fraction": float(frac[i]),
                          "leader": i == self.leader, "is_success": bool(success[i])})
        return np.zeros(2, bool), infos


# -- the env factories (``mimo_social.envs.joint_attention_v0`` re-exports them) ----------

def parallel_env(**kwargs):
    return make_parallel(JointAttention, **kwargs)


def env(**kwargs):
    return make_aec(JointAttention, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ...partners import ScriptedPartners
    from ...partners.gaze import GazeAtTarget
    options = with_options(JointAttention, kwargs.pop("task_options", None), scripted_partner=True)
    penv = parallel_env(task_options=options, **kwargs)
    # the partner: the second agent (caregiver_0 when it is the adult)
    return ScriptedPartners(penv, {penv.possible_agents[1]: partner or GazeAtTarget()})
