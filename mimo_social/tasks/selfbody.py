"""Self-body touch (paper Sec. VI-A): a cross-legged infant touches a named part of its own body.

| | |
|---|---|
| agents | 1 (`infant_0`), mitten hands, spring-damper motors |
| body | hip fixed, sitting cross-legged (legs crossed in front, shins towards the midline), trunk bent forward; everything but the right arm held (trunk, head, eyes, legs, left arm: they cannot move, but their skin feels) |
| scene | the floor only; the hip is fixed where the body's lowest point touches it |
| reset | the right arm starts held out to the side, touching nothing; a target part is drawn uniformly from `targets` (task option `target` fixes it) |
| physics | one physics step (5 ms) per control step (`frame_skip=1`), as published |
| action | the right-arm motors: 8 in [-1, 1] (shoulder 3, elbow, wrist 3, fingers) |
| observation | `proprioception` (48), `touch` (1400: the whole skin; by default at a quarter of the published point density and the normal force only, 1 float a point; `touch=True` gives the published density and 3 floats a point), `target` (15: one-hot over `targets`) |
| reward | `+500` when the right hand (hand or fingers) touches the target part; else `-distance(contact, target part's centre of mass)` (m, the contact nearest the target) when the right hand touches another part of the body; else `-1` |
| success | the right hand or fingers touch the target part (`is_success`) |
| termination | when the target is touched; truncation at 500 steps |
| infos | `target` (part name), `is_success`, `touched` (parts the right hand touches), `distance` (m; None when the hand touches no part) |
| privileged cues | `target`: the named part as a one-hot code (the instruction; no sense carries it) |
| baselines | PPO, seed 0, 100k steps (4.8 min): mean return -87.7 +- 150 on 50 episodes (6 % success) against a random policy's -414.5 +- 219 (8 %) and zero controls' -176 (5 %) on the same episodes (`mimo-social train --task selfbody --algo ppo --steps 100000 --seed 0 --out runs/selfbody_ppo --eval-every 10000 --eval-episodes 10`, then `mimo-social eval runs/selfbody_ppo --episodes 50 --seed 10000`) |
| sources | the MIMo paper (Mattern et al.), Sec. VI-A: the self-body knowledge demo |
| version history | v0: first version, with the paper's other one-agent demos (stand up, catch) |

`targets` by default (15 for the mitten body): hip, lower and upper trunk, head, the left arm's
four parts, the right leg's four parts and the left thigh, shin and foot. Not the right arm's
own parts, the eyes, nor the left toes, which no right-arm posture reaches in this pose (none of
20,000 random ones). The trunk is bent forward as far as it goes and the left hand rests on the
lap so that the rest is within reach.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from gymnasium import spaces

from ..body.joint_groups import held_posture, right_arm_joints
from ..body.tables import load_body, subtree
from ..core.kinematics import hand_geoms, reach_sites
from ..core.task import Task, TaskOptions
from ..core.world import AgentSetup
from .common import CROSS_LEGGED_DEG, skin_parts

# the right arm at the start: raised to the side, elbow bent a little, touching nothing
ARM_START_DEG = {"right_shoulder_abduction": 45.0, "right_shoulder_horizontal": 20.0,
                 "right_elbow": -30.0}
EXCLUDED_SUFFIXES = ("_eye",)
# out of the right hand's reach in this pose (none of 20,000 random right-arm postures touches it)
UNREACHABLE = ("left_toes",)


def default_targets(tables) -> tuple[str, ...]:
    """Every body part with geoms except the right arm's own parts and the eyes."""
    arm = set(subtree(tables, "right_upper_arm"))
    return tuple(b for b in skin_parts(tables) if b not in arm and b not in UNREACHABLE
                 and not b.endswith(EXCLUDED_SUFFIXES))


@dataclass(frozen=True)
class SelfBodyOptions(TaskOptions):
    """The target parts (None: :func:`default_targets`), one fixed target (None: drawn each
    episode), the reward on touching it and the reward of a step that touches nothing."""

    task = "selfbody"
    targets: tuple[str, ...] | None = None
    target: str | None = None
    success_reward: float = 500.0
    miss_reward: float = -1.0

    def __post_init__(self):
        self._names("targets", "body part names")
        self._name("target", "a body part name from targets")
        self._number("success_reward")
        self._number("miss_reward")


class SelfBody(Task):
    name = "selfbody"
    n_agents_range = (1, 1)
    default_n_agents = 1
    default_max_steps = 500
    physics_overrides = {"frame_skip": 1}

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
        parts = {g.body for g in tables.geoms}
        unknown = [t for t in targets if t not in parts]
        if unknown or not targets:
            raise ValueError(f"selfbody: targets {unknown or list(targets)} not allowed; body parts "
                             f"of the {config.hands} body: {sorted(parts)}")
        fixed = self.options.target
        if fixed is not None and fixed not in targets:
            raise ValueError(f"selfbody: target={fixed!r} not allowed; one of {list(targets)}")
        self.targets = targets
        return AgentSetup(config, position=(0.0, 0.0), facing=(1.0, 0.0), frozen=frozen,
                          base="fixed", actuated=arm)

    def task_spaces(self, env, i):
        return {"target": spaces.Box(0.0, 1.0, (len(self.targets),), np.float32)}

    def _bind(self, env):
        w = env.world
        m = w.model
        a = w.agents[0]
        self._world = w
        hand = hand_geoms(w, 0, 0)
        self._is_hand = np.zeros(m.ngeom, bool)
        self._is_hand[hand] = True
        # every geom of this infant outside the right hand -> its body id; others -> -1
        self._part_body = np.full(m.ngeom, -1, dtype=np.intp)
        own = a.geom_ids[~self._is_hand[a.geom_ids]]
        self._part_body[own] = m.geom_bodyid[own]
        self._target_bodies = np.array([m.body(f"{a.name}/{t}").id for t in self.targets],
                                       dtype=np.intp)
        idx = {n: k for k, n in enumerate(a.joint_names)}
        ks = [idx[n] for n in ARM_START_DEG if n in idx]
        self._arm_qpos = a.qpos_adr[ks]
        self._arm_start = np.clip(np.deg2rad([ARM_START_DEG[a.joint_names[k]] for k in ks]),
                                  a.joint_range[ks, 0], a.joint_range[ks, 1])
        self._names = {int(b): m.body(int(b)).name[len(a.name) + 1:]
                       for b in np.unique(self._part_body[own])}

    def reset(self, env, rng):
        if getattr(self, "_world", None) is not env.world:
            self._bind(env)
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
        """The current episode's target part."""
        return self.targets[self._target]

    def _contacts(self, d):
        """Bodies the right hand touches, and the contact positions."""
        n = d.ncon
        if n == 0:
            return np.empty(0, np.intp), np.empty((0, 3))
        c = d.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        h1, h2 = self._is_hand[g1], self._is_hand[g2]
        other = np.where(h1, g2, g1)
        body = self._part_body[other]
        keep = (h1 ^ h2) & (body >= 0) & (c.dist[:n] <= 0.0)
        return body[keep], c.pos[:n][keep]

    def rewards(self, env):
        d = env.world.data
        bodies, pos = self._contacts(d)
        target = self._target_bodies[self._target]
        self._touched = sorted({self._names[int(b)] for b in bodies})
        self._success = bool(np.any(bodies == target))
        if self._success:
            self._distance = 0.0
            return np.array([self.options.success_reward])
        if len(bodies):
            self._distance = float(np.min(np.linalg.norm(pos - d.xipos[target], axis=1)))
            return np.array([-self._distance])
        self._distance = None
        return np.array([self.options.miss_reward])

    def terminations(self, env):
        return (np.array([self._success]),
                [{"target": self.target, "is_success": self._success,
                  "touched": list(self._touched), "distance": self._distance}])

    # -- for tests and demos ----------------------------------------------------------------------
    def place_hand_on(self, env, part: str, iters: int = 200) -> float:
        """Move the right arm (joint angles, no physics) until the palm centre lies on ``part``'s
        surface nearest to it; returns the remaining distance (m) between the hand and the part
        (negative: penetrating). Used by tests; a policy has to learn this."""
        w = env.world
        m, d = w.model, w.data
        a = w.agents[0]
        k = a.actuated_joint_idx
        body = m.body(f"{a.name}/{part}").id
        geoms = np.flatnonzero(m.geom_bodyid == body)
        target = d.xipos[body].copy()
        reach_sites(m, d, a.qpos_adr[k], a.dof_adr[k], a.joint_range[k, 0], a.joint_range[k, 1],
                    a.palm_sites[0], target, iters)
        mujoco.mj_forward(m, d)
        hand = np.flatnonzero(self._is_hand)
        fromto = np.zeros(6)
        return float(min(mujoco.mj_geomDistance(m, d, int(h), int(g), 0.05, fromto)
                         for h in hand for g in geoms))
