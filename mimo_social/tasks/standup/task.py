"""The standup task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ...body.joint_groups import held_posture
from ...body.tables import load_body
from ...core.kinematics import reach_sites
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup, Prop
from ..common import settle
from ...core.factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "Standup", "StandupOptions"]

TRUNK = ("lower_trunk_lean", "lower_trunk_twist", "lower_trunk_bend")
ARM = ("shoulder_horizontal", "shoulder_abduction", "shoulder_rotation", "elbow",
       "wrist_rotation", "wrist_flexion", "wrist_ulnar")
LEG = ("hip_flexion", "hip_abduction", "hip_rotation", "knee", "ankle_flexion")
STANDUP_JOINTS = TRUNK + tuple(f"{s}_{j}" for s in ("right", "left") for j in ARM) \
    + tuple(f"{s}_{j}" for s in ("right", "left") for j in LEG)

RAIL_HEIGHT = 0.45      # m, the rail's axis above the floor (paper: 45 cm)
RAIL_X = 0.20           # m in front of the hip
RAIL_RADIUS = 0.015     # half thickness of the (square) rail
RAIL_HALF_WIDTH = 0.32  # m, half the rail's length
GRIP_Y = 0.10           # m, each hand this far from the infant's midline
ARM_GUESS_DEG = (90.0, 120.0, 0.0, -20.0)  # shoulder 3, elbow: the arms raised forward
# the start pose: a low squat, hips and knees bent as far as they go with the feet flat (with this
# body's thigh and shank lengths the soles reach the floor next to the buttocks only when the
# feet are 27 cm in front of the hip, beyond the rail, from where no standing up is possible)
HIP_FLEXION_DEG = -113.0
KNEE_DEG = -145.0
COST_WEIGHT = 0.01       # the control cost's weight (paper)
HEAD_REFERENCE = 0.2     # m, subtracted from the head's height (paper: "from an initial height of 20 cm")
SUCCESS_GAIN = 0.20      # m, success: the head this far above its settled start height ...
SUCCESS_HOLD = 1.0       # s, ... for this long without a break
WELD_SOLREF = (0.01, 1.0)  # hands and feet: time constant 2 physics steps, critically damped


def lowest_point(model, data, geoms: np.ndarray) -> float:
    """Lowest world z of a set of geoms, from their bounding spheres' centres and the geoms'
    own half extents along world z (exact for spheres and axis-aligned shapes, close for others)."""
    z = data.geom_xpos[geoms, 2]
    R = data.geom_xmat[geoms].reshape(-1, 3, 3)
    size = model.geom_size[geoms]
    t = model.geom_type[geoms]
    rz = R[:, 2, :]
    G = mujoco.mjtGeom
    low = z - model.geom_rbound[geoms]
    box = t == G.mjGEOM_BOX
    low[box] = z[box] - np.sum(np.abs(rz[box]) * size[box], axis=1)
    cap = t == G.mjGEOM_CAPSULE
    low[cap] = z[cap] - np.abs(rz[cap, 2]) * size[cap, 1] - size[cap, 0]
    cyl = t == G.mjGEOM_CYLINDER
    low[cyl] = z[cyl] - np.abs(rz[cyl, 2]) * size[cyl, 1] \
        - size[cyl, 0] * np.sqrt(np.clip(1 - rz[cyl, 2] ** 2, 0, 1))
    sph = t == G.mjGEOM_SPHERE
    low[sph] = z[sph] - size[sph, 0]
    return float(low.min())


@dataclass(frozen=True)
class StandupOptions(TaskOptions):
    """Rail height (m), control cost weight, the head's reference height (m; None: its height
    after settling), the start perturbation (rad) and the settling steps."""

    task = "standup"
    rail_height: float = RAIL_HEIGHT
    cost_weight: float = COST_WEIGHT
    head_reference: float | None = HEAD_REFERENCE
    success_gain: float = SUCCESS_GAIN
    success_hold: float = SUCCESS_HOLD
    perturbation: float = 0.01
    settle_steps: int = 100

    def __post_init__(self):
        self._number("rail_height", 0.2, 1.0)
        self._number("cost_weight", 0.0)
        if self.head_reference is not None:
            self._number("head_reference", 0.0, 2.0)
        self._number("success_gain", 0.0, 1.0)
        self._number("success_hold", 0.0, 60.0)
        self._number("perturbation", 0.0, 0.5)
        self._int("settle_steps", 0, 10_000)


class Standup(Task):
    name = "standup"
    n_agents_range = (1, 1)
    default_n_agents = 1
    default_max_steps = 500

    Options = StandupOptions

    def agent_defaults(self, i, settings):
        return {"posture": "sitting", "vestibular": True, "expressions": False}

    def setup(self, i, config):
        tables = load_body(config.hands)
        known = {j.name for j in tables.joints}
        actuated = tuple(j for j in STANDUP_JOINTS if j in known)
        frozen = held_posture(tables, keep=actuated)
        return AgentSetup(config, position=(0.0, 0.0), facing=(1.0, 0.0), frozen=frozen,
                          base="free", actuated=actuated)

    def props(self):
        h = self.options.rail_height
        wood = (0.72, 0.52, 0.32, 1.0)
        post = h / 2 + RAIL_RADIUS / 2
        me = self.agent_name(0) if self.configs else "infant_0"
        return [
            Prop("crib_rail", "box", (RAIL_RADIUS, RAIL_HALF_WIDTH, RAIL_RADIUS), (RAIL_X, 0.0, h),
                 1.0, wood, fixed=True, welds=(f"{me}/right_hand", f"{me}/left_hand")),
            Prop("crib_post_right", "box", (RAIL_RADIUS, RAIL_RADIUS, post),
                 (RAIL_X, -RAIL_HALF_WIDTH - RAIL_RADIUS, post), 1.0, wood, fixed=True),
            Prop("crib_post_left", "box", (RAIL_RADIUS, RAIL_RADIUS, post),
                 (RAIL_X, RAIL_HALF_WIDTH + RAIL_RADIUS, post), 1.0, wood, fixed=True),
            # under the floor, out of sight: the feet are welded to it (i.e. to the floor)
            Prop("crib_base", "box", (0.3, 0.3, 0.01), (0.1, 0.0, -0.02), 1.0, wood, fixed=True,
                 welds=(f"{me}/right_foot", f"{me}/left_foot")),
        ]

    # -- the start pose (computed once per world) -----------------------------------------------
    def _start_pose(self, env) -> np.ndarray:
        w = env.world
        m, d = w.model, w.data
        a = w.agents[0]
        idx = {n: k for k, n in enumerate(a.joint_names)}
        q0 = w.initial_qpos
        d.qpos[:] = q0

        def setj(name, deg):
            k = idx[name]
            d.qpos[a.qpos_adr[k]] = np.clip(np.deg2rad(deg), *a.joint_range[k])

        for s in ("right", "left"):
            setj(f"{s}_hip_flexion", HIP_FLEXION_DEG)
            setj(f"{s}_knee", KNEE_DEG)
            # foot flat: hip (about +y) - knee - ankle (both about -y) = 0
            setj(f"{s}_ankle_flexion", HIP_FLEXION_DEG - KNEE_DEG)
        mujoco.mj_kinematics(m, d)
        # the body rests on the floor
        drop = lowest_point(m, d, a.geom_ids)
        d.qpos[a.free_qpos + 2] -= drop - 0.002
        mujoco.mj_kinematics(m, d)
        # hands to the rail: shoulder and elbow by damped least squares
        h = self.options.rail_height
        for side, k_site, y in (("right", 0, -GRIP_Y), ("left", 1, GRIP_Y)):
            names = [f"{side}_{j}" for j in ARM[:4]]
            for n, deg in zip(names, ARM_GUESS_DEG):  # arms forward, from where IK starts
                setj(n, deg)
            ks = [idx[n] for n in names]
            target = (RAIL_X - 0.01, y, h)
            reach_sites(m, d, a.qpos_adr[ks], a.dof_adr[ks], a.joint_range[ks, 0],
                        a.joint_range[ks, 1], a.palm_sites[k_site], target)
        return d.qpos.copy()

    # -- running --------------------------------------------------------------------------------
    def bind(self, env):
        """Index tables of this world (once per world: :meth:`Task.bind`)."""
        w = env.world
        m = w.model
        a = w.agents[0]
        self._start = self._start_pose(env)
        self._rail = m.geom("crib_rail").id
        self._act_qpos = a.qpos_adr[a.actuated_joint_idx]
        self._head = a.head_site

    def reset(self, env, rng):
        w = env.world
        m, d = w.model, w.data
        self._model_settings(env)
        d.qpos[:] = self._start
        d.qvel[:] = 0.0
        mujoco.mj_kinematics(m, d)
        w.hold_welds()
        eps = self.options.perturbation
        d.qpos[self._act_qpos] += rng.uniform(-eps, eps, len(self._act_qpos))
        d.ctrl[:] = 0.0
        settle(env, self.options.settle_steps)
        self._start_height = float(d.site_xpos[self._head, 2])
        ref = self.options.head_reference
        self._ref = self._start_height if ref is None else float(ref)
        self._height = self._start_height
        self._cost = 0.0
        self._above = 0   # steps in a row with the head success_gain above its start
        self._hold_steps = max(1, round(self.options.success_hold / env.dt))

    @property
    def start_height(self) -> float:
        """The head's height (m) after this episode's settling."""
        return self._start_height

    @property
    def reference(self) -> float:
        """The height (m) the reward subtracts from the head's: the option, or the start's."""
        return self._ref

    def _model_settings(self, env):
        """The model values the task sets at reset (a pickled env carries them: its MjData
        travels with its model)."""
        m = env.world.model
        # the rail only shows where the hands hold on (they are welded to it): it takes no
        # contacts, so the gripping hands never fight it
        m.geom_contype[self._rail] = m.geom_conaffinity[self._rail] = 0
        m.eq_solref[env.world.welds[:, 0]] = WELD_SOLREF  # stiffer than MuJoCo's default 0.02 s

    def rewards(self, env):
        d = env.world.data
        self._height = float(d.site_xpos[self._head, 2])
        u = env.controls[0]
        self._cost = self.options.cost_weight * float(np.dot(u, u))
        return np.array([self._height - self._ref - self._cost])

    def plots(self):
        """Reward, the head's height, its gain over the start and success (held above)."""
        return [Plot.reward(),
                Plot("head_height", "m", lambda env: (self._height,)),
                Plot("head_gain", "m", lambda env: (self._height - self._start_height,)),
                Plot("success", "0/1", lambda env: (self._above >= self._hold_steps,))]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"head_height": "number", "head_gain": "number", "is_success": "number",
                "control_cost": "number"}

    def terminations(self, env):
        gain = self._height - self._start_height
        self._above = self._above + 1 if gain >= self.options.success_gain else 0
        return np.zeros(1, bool), [{"head_height": self._height, "head_gain": gain,
                                    "is_success": self._above >= self._hold_steps,
                                    "control_cost": self._cost}]


# -- the env factories (``mimo_social.envs.standup_v0`` re-exports them) ------------------

def parallel_env(**kwargs):
    return make_parallel(Standup, **kwargs)


def env(**kwargs):
    return make_aec(Standup, **kwargs)
