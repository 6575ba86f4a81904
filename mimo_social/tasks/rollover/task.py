"""The rollover task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ...body.joint_groups import held_posture
from ...body.tables import load_body
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup
from ...util.checks import ConfigError
from ..common import settle
from ...core.factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "RollOver", "RollOverOptions", "ROLL_JOINTS", "STARTS",
           "turn_angle"]

TRUNK = ("lower_trunk_lean", "lower_trunk_twist", "lower_trunk_bend")
HEAD = ("head_swivel", "head_tilt", "head_tilt_side")
ARM = ("shoulder_horizontal", "shoulder_abduction", "shoulder_rotation", "elbow",
       "wrist_rotation", "wrist_flexion", "wrist_ulnar")
LEG = ("hip_flexion", "hip_abduction", "hip_rotation", "knee", "ankle_flexion")
#: the motors of the task (30): trunk, head, each arm, each leg; eyes, fingers, toes and the
#: ankles' inversion and rotation are held
ROLL_JOINTS = TRUNK + HEAD + tuple(f"{s}_{j}" for s in ("right", "left") for j in ARM) \
    + tuple(f"{s}_{j}" for s in ("right", "left") for j in LEG)
#: the start postures: on the back (roll to the belly) and on the belly (roll to the back)
STARTS = ("supine", "prone")
AGE_MONTHS = 6.0          # infants roll over at about 4 to 6 months (the table's sources)
SUCCESS_ANGLE = 135.0     # deg: the chest turned this far from its start ...
SUCCESS_HOLD = 1.0        # s: ... for this long without a break
COST_WEIGHT = 0.001       # the control cost's weight
OVER_BONUS = 1.0          # reward per step while the chest is turned success_angle or more
PERTURBATION = 0.05       # rad, U(-p, p) on every motor joint at reset
SETTLE_STEPS = 100        # physics steps with zero controls before the first observation
LIFT = 0.002              # m of air under the lowest geom before settling


def turn_angle(model, data, body: int, start: str) -> float:
    """How far (deg, 0 to 180) the chest has turned from its ``start`` posture: the angle between
    the chest's forward axis (the x axis of ``body``, the upper trunk) and the world's up (from
    the back) or down (from the belly)."""
    up = float(data.xmat[body, 6])   # world z of the body's x axis
    if start == "prone":
        up = -up
    return float(np.degrees(np.arccos(np.clip(up, -1.0, 1.0))))


@dataclass(frozen=True)
class RollOverOptions(TaskOptions):
    """The start (``supine``: roll onto the belly; ``prone``: onto the back), success (the chest
    turned ``success_angle`` degrees for ``success_hold`` s), the reward per step while turned that
    far (``over_bonus``), the control cost's weight, the start noise (rad), the start yaw's range
    (deg, either way) and the settling steps."""

    task = "rollover"
    start: str = "supine"
    success_angle: float = SUCCESS_ANGLE
    success_hold: float = SUCCESS_HOLD
    over_bonus: float = OVER_BONUS
    cost_weight: float = COST_WEIGHT
    perturbation: float = PERTURBATION
    yaw_range: float = 180.0
    settle_steps: int = SETTLE_STEPS

    def __post_init__(self):
        self._choice("start", STARTS)
        self._number("success_angle", 90.0, 180.0)
        self._number("success_hold", 0.0, 60.0)
        self._number("over_bonus", 0.0)
        self._number("cost_weight", 0.0)
        self._number("perturbation", 0.0, 0.5)
        self._number("yaw_range", 0.0, 180.0)
        self._int("settle_steps", 0, 10_000)


class RollOver(Task):
    name = "rollover"
    n_agents_range = (1, 1)
    default_n_agents = 1
    default_max_steps = 600

    Options = RollOverOptions

    def agent_defaults(self, i, settings):
        return {"posture": "lying", "age_months": AGE_MONTHS, "vestibular": True,
                "expressions": False}

    def setup(self, i, config):
        if config.posture != "lying":
            raise ConfigError(f"rollover: agent {self.agent_name(i)}: posture={config.posture!r} "
                              "not allowed; allowed: 'lying' (the task turns the lying body onto "
                              "its back or belly: task option start)")
        tables = load_body(config.hands, age_months=config.age_months, body=config.body)
        known = {j.name for j in tables.joints}
        actuated = tuple(j for j in ROLL_JOINTS if j in known)
        frozen = held_posture(tables, keep=actuated)
        return AgentSetup(config, position=(0.0, 0.0), facing=(1.0, 0.0), frozen=frozen,
                          base="free", actuated=actuated)

    # -- running --------------------------------------------------------------------------------
    def bind(self, env):
        """Index tables of this world (once per world: :meth:`Task.bind`)."""
        w = env.world
        m = w.model
        a = w.agents[0]
        self.chest_body = m.body(f"{a.name}/upper_body").id
        self._act_qpos = a.qpos_adr[a.actuated_joint_idx]
        self._free = a.free_qpos
        self._geoms = np.array([g for g in a.geom_ids
                                if m.geom_contype[g] or m.geom_conaffinity[g]], np.intp)
        d = mujoco.MjData(m)   # the world's initial pose: the lying body placed on the floor
        d.qpos[:] = w.initial_qpos
        mujoco.mj_kinematics(m, d)
        self._floor_z = lowest_point(m, d, self._geoms)

    def reset(self, env, rng):
        w = env.world
        m, d = w.model, w.data
        o = self.options
        d.qvel[:] = 0.0
        q = d.qpos[self._free + 3:self._free + 7].copy()   # the lying posture's root (on the back)
        if o.start == "prone":   # half a turn about the body's long axis (its z axis)
            q = _quat_mul(q, np.array([0.0, 0.0, 0.0, 1.0]))
        yaw = np.radians(rng.uniform(-o.yaw_range, o.yaw_range))
        q = _quat_mul(np.array([np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)]), q)
        d.qpos[self._free + 3:self._free + 7] = q / np.linalg.norm(q)
        eps = o.perturbation
        d.qpos[self._act_qpos] += rng.uniform(-eps, eps, len(self._act_qpos))
        mujoco.mj_kinematics(m, d)
        d.qpos[self._free + 2] += self._floor_z + LIFT - lowest_point(m, d, self._geoms)
        d.ctrl[:] = 0.0
        settle(env, o.settle_steps)
        self.turn_angle = turn_angle(m, d, self.chest_body, o.start)
        self._cost = 0.0
        self._turned = 0   # control steps in a row with the chest turned success_angle or more
        self._hold_steps = max(1, round(o.success_hold / env.dt))

    def rewards(self, env):
        d = env.world.data
        self.turn_angle = turn_angle(env.world.model, d, self.chest_body, self.options.start)
        u = env.controls[0]
        o = self.options
        self._cost = o.cost_weight * float(np.dot(u, u))
        over = o.over_bonus if self.turn_angle >= o.success_angle else 0.0
        return np.array([self.turn_angle / 180.0 + over - self._cost])

    def plots(self):
        """Reward, the chest's turn from its start and success (turned and held)."""
        return [Plot.reward(),
                Plot("turn_angle", "deg", lambda env: (self.turn_angle,)),
                Plot("success", "0/1", lambda env: (self._turned >= self._hold_steps,))]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"turn_angle": "number", "is_success": "number", "control_cost": "number"}

    def terminations(self, env):
        self._turned = self._turned + 1 if self.turn_angle >= self.options.success_angle else 0
        return np.zeros(1, bool), [{"turn_angle": self.turn_angle,
                                    "is_success": self._turned >= self._hold_steps,
                                    "control_cost": self._cost}]


def lowest_point(model, data, geoms: np.ndarray) -> float:
    """The lowest world z of a set of geoms: exact for spheres, capsules, boxes, ellipsoids
    and cylinders (from each geom's orientation and half sizes), the bounding sphere for others."""
    G = mujoco.mjtGeom
    kind, size = model.geom_type[geoms], model.geom_size[geoms]
    up = data.geom_xmat[geoms].reshape(-1, 3, 3)[:, 2, :]   # world z in each geom's frame
    depth = model.geom_rbound[geoms].copy()
    for k in range(len(geoms)):
        t, r, u = kind[k], size[k], up[k]
        if t == G.mjGEOM_SPHERE:
            depth[k] = r[0]
        elif t == G.mjGEOM_CAPSULE:
            depth[k] = r[0] + abs(u[2]) * r[1]
        elif t == G.mjGEOM_BOX:
            depth[k] = float(np.abs(u) @ r)
        elif t == G.mjGEOM_ELLIPSOID:
            depth[k] = float(np.sqrt(np.sum((u * r) ** 2)))
        elif t == G.mjGEOM_CYLINDER:
            depth[k] = abs(u[2]) * r[1] + r[0] * np.sqrt(max(0.0, 1.0 - u[2] ** 2))
    return float(np.min(data.geom_xpos[geoms, 2] - depth))


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.zeros(4)
    mujoco.mju_mulQuat(out, a, b)
    return out


# -- the env factories (``mimo_social.envs.rollover_v0`` re-exports them) ------------------

def parallel_env(**kwargs):
    return make_parallel(RollOver, **kwargs)


def env(**kwargs):
    return make_aec(RollOver, **kwargs)
