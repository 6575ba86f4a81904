"""The selfbody task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from gymnasium import spaces

from ...body.joint_groups import held_posture, right_arm_joints
from ...body.tables import load_body, subtree
from ...core.kinematics import hand_geoms, reach_sites
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup
from ...util.checks import ConfigError
from ..common import CROSS_LEGGED_DEG
from ...core.factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "SelfBody", "SelfBodyOptions"]

# the right arm at the start: raised to the side, elbow bent a little, touching nothing
ARM_START_DEG = {"right_shoulder_abduction": 45.0, "right_shoulder_horizontal": 20.0,
                 "right_elbow": -30.0}
EXCLUDED_SUFFIXES = ("_eye",)
# primitives the scripted controller does not reach in this pose (see the module docstring)
UNREACHABLE: tuple[str, ...] = ()
SUCCESS_REWARD = 500.0
MISS_REWARD = -1.0
MAX_STEPS = 500
FRAME_SKIP = 1


def default_targets(tables) -> tuple[str, ...]:
    """Every primitive (geom) of the body except the right arm's own (upper arm, forearm, hand,
    fingers), the eyes and :data:`UNREACHABLE`, in table order."""
    arm = set(subtree(tables, "right_upper_arm"))
    return tuple(g.name for g in tables.geoms if g.body not in arm
                 and not g.body.endswith(EXCLUDED_SUFFIXES) and g.name not in UNREACHABLE)


@dataclass(frozen=True)
class SelfBodyOptions(TaskOptions):
    """The target primitives (geom names; None: :func:`default_targets`), one fixed target
    (None: drawn each episode), the reward on touching it, the reward of a step that touches
    nothing, and the cost of touching another primitive on top of its distance to the target."""

    task = "selfbody"
    targets: tuple[str, ...] | None = None
    target: str | None = None
    success_reward: float = SUCCESS_REWARD
    miss_reward: float = MISS_REWARD
    other_touch_cost: float = 0.0

    def __post_init__(self):
        self._names("targets", "primitive (geom) names")
        self._name("target", "a primitive (geom) name from targets")
        self._number("success_reward")
        self._number("miss_reward")
        self._number("other_touch_cost")


class SelfBody(Task):
    name = "selfbody"
    n_agents_range = (1, 1)
    default_n_agents = 1
    default_max_steps = MAX_STEPS
    physics_overrides = {"frame_skip": FRAME_SKIP}

    Options = SelfBodyOptions

    def agent_defaults(self, i, settings):
        return {"posture": "sitting", "vestibular": False, "expressions": False,
                "touch": {"density": 0.25, "normal_only": True}}

    def setup(self, i, config):
        tables = load_body(config.hands)
        arm = right_arm_joints(tables)
        frozen = held_posture(tables, keep=arm, angles=CROSS_LEGGED_DEG)
        targets = self.options.targets
        targets = tuple(targets) if targets is not None else default_targets(tables)
        prims = {g.name: g.body for g in tables.geoms}
        unknown = [t for t in targets if t not in prims]
        if unknown or not targets:
            raise ConfigError(f"selfbody: targets {unknown or list(targets)} not allowed; "
                             f"primitives (geoms) of the {config.hands} body: {list(prims)}")
        fixed = self.options.target
        if fixed is not None and fixed not in targets:
            raise ConfigError(f"selfbody: target={fixed!r} not allowed; one of {list(targets)}")
        self.targets = targets
        self.target_parts = tuple(prims[t] for t in targets)
        return AgentSetup(config, position=(0.0, 0.0), facing=(1.0, 0.0), frozen=frozen,
                          base="fixed", actuated=arm)

    def task_spaces(self, env, i):
        return {"target": spaces.Box(0.0, 1.0, (len(self.targets),), np.float32)}

    def bind(self, env):
        w = env.world
        m = w.model
        a = w.agents[0]
        self._world = w
        hand = hand_geoms(w, 0, 0)
        self._is_hand = np.zeros(m.ngeom, bool)
        self._is_hand[hand] = True
        # every geom of this infant outside the right hand -> True
        self._is_own = np.zeros(m.ngeom, bool)
        own = a.geom_ids[~self._is_hand[a.geom_ids]]
        self._is_own[own] = True
        self._target_geoms = np.array([m.geom(f"{a.name}/{t}").id for t in self.targets],
                                      dtype=np.intp)
        self._geom_names = {int(g): m.geom(int(g)).name[len(a.name) + 1:] for g in own}
        idx = {n: k for k, n in enumerate(a.joint_names)}
        ks = [idx[n] for n in ARM_START_DEG if n in idx]
        self._arm_qpos = a.qpos_adr[ks]
        self._arm_start = np.clip(np.deg2rad([ARM_START_DEG[a.joint_names[k]] for k in ks]),
                                  a.joint_range[ks, 0], a.joint_range[ks, 1])
        self._force = np.zeros(6)

    def reset(self, env, rng):
        d = env.world.data
        d.qpos[self._arm_qpos] = self._arm_start
        fixed = self.options.target
        self._target = (self.targets.index(fixed) if fixed is not None
                        else int(rng.integers(len(self.targets))))
        self._onehot = np.zeros(len(self.targets), np.float32)
        self._onehot[self._target] = 1.0
        self._success = False
        self._touched: list[str] = []
        self._distance = None

    def observe(self, env, i):
        return {"target": self._onehot.copy()}

    @property
    def target(self) -> str:
        """The current episode's target primitive (geom name)."""
        return self.targets[self._target]

    @property
    def target_part(self) -> str:
        """The body part holding the current target primitive."""
        return self.target_parts[self._target]

    def _contacts(self, m, d):
        """Primitives of the body that the right hand presses on (a contact with a positive
        normal force), and the contact positions."""
        n = d.ncon
        if n == 0:
            return np.empty(0, np.intp), np.empty((0, 3))
        c = d.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        h1, h2 = self._is_hand[g1], self._is_hand[g2]
        other = np.where(h1, g2, g1)
        keep = np.flatnonzero((h1 ^ h2) & self._is_own[other] & (c.dist[:n] <= 0.0))
        pressed = []
        for k in keep:
            mujoco.mj_contactForce(m, d, int(k), self._force)
            if self._force[0] > 0.0:
                pressed.append(k)
        pressed = np.asarray(pressed, dtype=np.intp)
        return other[pressed], c.pos[:n][pressed]

    def rewards(self, env):
        w = env.world
        m, d = w.model, w.data
        geoms, pos = self._contacts(m, d)
        target = self._target_geoms[self._target]
        self._touched = sorted({self._geom_names[int(g)] for g in geoms})
        # the touch sense: the target's body part feels a touch by the infant itself, and the
        # contact that it feels is the right hand on the target primitive
        felt = env.system("touch").touched_by(0).get(self.target_part, {}).get("self", False)
        self._success = bool(felt and np.any(geoms == target))
        if self._success:
            self._distance = 0.0
            return np.array([self.options.success_reward])
        if len(geoms):
            self._distance = float(np.min(np.linalg.norm(pos - d.geom_xpos[target], axis=1)))
            return np.array([-(self.options.other_touch_cost + self._distance)])
        self._distance = None
        return np.array([self.options.miss_reward])

    def plots(self):
        """Reward, the right palm's distance to the target primitive's centre, the touch's
        distance to it (none without a touch: the reward's) and success."""
        nan = float("nan")

        def palm(env):
            d = env.world.data
            site = env.world.agents[0].palm_sites[0]
            return (math.dist(d.site_xpos[site], d.geom_xpos[self._target_geoms[self._target]]),)
        return [Plot.reward(), Plot("palm_to_target", "m", palm),
                Plot("touch_distance", "m",
                     lambda env: (nan if self._distance is None else self._distance,)),
                Plot("success", "0/1", lambda env: (self._success,))]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"target": tuple(self.targets),
                "target_part": tuple(dict.fromkeys(self.target_parts)), "is_success": "number",
                "touched": "count", "distance": "number"}

    def terminations(self, env):
        return (np.array([self._success]),
                [{"target": self.target, "target_part": self.target_part,
                  "is_success": self._success, "touched": list(self._touched),
                  "distance": self._distance}])

    # -- for tests and demos ----------------------------------------------------------------------
    def place_hand_on(self, env, primitive: str, iters: int = 200) -> float:
        """Move the right arm (joint angles, no physics) until the palm centre lies on the
        primitive's surface nearest to it; returns the remaining distance (m) between the hand
        and the primitive (negative: penetrating). Used by tests; a policy has to learn this."""
        w = env.world
        m, d = w.model, w.data
        a = w.agents[0]
        k = a.actuated_joint_idx
        geom = m.geom(f"{a.name}/{primitive}").id
        target = d.geom_xpos[geom].copy()
        reach_sites(m, d, a.qpos_adr[k], a.dof_adr[k], a.joint_range[k, 0], a.joint_range[k, 1],
                    a.palm_sites[0], target, iters)
        mujoco.mj_forward(m, d)
        hand = np.flatnonzero(self._is_hand)
        fromto = np.zeros(6)
        return float(min(mujoco.mj_geomDistance(m, d, int(h), geom, 0.05, fromto)
                         for h in hand))


# -- the env factories (``mimo_social.envs.selfbody_v0`` re-exports them) -----------------

def parallel_env(**kwargs):
    return make_parallel(SelfBody, **kwargs)


def env(**kwargs):
    return make_aec(SelfBody, **kwargs)
