"""Stand up (paper Sec. VI-A): an infant sitting in a crib pulls itself up on the crib's rail.

| | |
|---|---|
| agents | 1 (`infant_0`), mitten hands, spring-damper motors |
| body | free base (the infant can rise, lean and sag); head, eyes, fingers, toes and the ankles' inversion and rotation held |
| scene | a crib rail 0.45 m above the floor in front of the infant (two posts hold it); the infant's hands are welded to the rail and its feet to the floor (weld equalities); the rail itself takes no contacts |
| reset | a low squat (hips and knees bent as far as they go, feet flat, buttocks 8 cm above the floor), hands on the rail; every actuated joint gets U(-0.01, 0.01) rad, then 100 physics steps with zero controls settle the body before the first observation |
| physics | one physics step (5 ms) per control step (`frame_skip=1`) |
| action | 27 motors in [-1, 1]: trunk 3 (lean, twist, bend), each arm 7 (shoulder 3, elbow, wrist 3), each leg 5 (hip 3, knee, ankle flexion) |
| observation | `proprioception` (190: joint angles, velocities, torques, limit sensors, motor state), `vestibular` (6: head gyro, accelerometer) |
| reward | `z_head - z_ref - 0.01 * sum(u_i^2)`: head-centre height gain over its height after the settling steps (option `head_reference`: a height in m instead, 0.2 as published), minus the control cost |
| success | none: no success criterion (no `is_success`); the head's height gain tells progress |
| termination | none (a fixed 500 steps, then truncation); a simulation that goes unstable ends the episode |
| infos | `head_height` (m), `head_gain` (m above the reference), `control_cost` |
| privileged cues | none |
| baselines | PPO, 3 seeds, 61k steps each (1.5-3 min a run): evaluation return 7 -> 68 / 71 / 74; the head rises 17-19 cm (0.45 -> 0.62-0.64 m) and stays there: the infant pulls itself up to a bent-knee stand (`mimo-social compare --task standup --algos ppo --seeds 3 --steps 60000 --out runs/standup --jobs 2 --eval-every 6000 --eval-episodes 5 --checkpoint-every 0`). SAC, 3 seeds, 15k steps each (7-12 min a run): evaluation return +9 -> -63 / -68 / -70: large controls, head at -6 .. +5 cm (`mimo-social compare --task standup --algos sac --seeds 3 --steps 15000 --out runs/standup --jobs 2 --eval-every 1500 --eval-episodes 5 --checkpoint-every 0`) |
| sources | the MIMo paper (Mattern et al.), Sec. VI-A: the standing-up demo |
| version history | v0: first version, with the paper's other one-agent demos (self-body touch, catch) |

Differences from the published task: the hands rather than the mitten fingers are welded (the
fingers are held), each ankle's flexion is a motor (the published model lists hip 3 + knee per
leg), the reference height defaults to the settled start height ("head height gain"), and the
start is a low squat: with this body's thigh and shank lengths, soles flat on the floor next to
the buttocks would put the feet 27 cm in front of the hip, beyond the rail.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ..body.joint_groups import held_posture
from ..body.tables import load_body
from ..core.kinematics import reach_sites
from ..core.task import Task, TaskOptions
from ..core.world import AgentSetup, Prop
from .common import settle

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
    cost_weight: float = 0.01
    head_reference: float | None = None
    perturbation: float = 0.01
    settle_steps: int = 100

    def __post_init__(self):
        self._number("rail_height", 0.2, 1.0)
        self._number("cost_weight", 0.0)
        if self.head_reference is not None:
            self._number("head_reference", 0.0, 2.0)
        self._number("perturbation", 0.0, 0.5)
        self._int("settle_steps", 0, 10_000)


class Standup(Task):
    name = "standup"
    n_agents_range = (1, 1)
    default_n_agents = 1
    default_max_steps = 500
    physics_overrides = {"frame_skip": 1}

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
        return [
            Prop("crib_rail", "box", (RAIL_RADIUS, RAIL_HALF_WIDTH, RAIL_RADIUS), (RAIL_X, 0.0, h),
                 1.0, wood, fixed=True, welds=("infant_0/right_hand", "infant_0/left_hand")),
            Prop("crib_post_right", "box", (RAIL_RADIUS, RAIL_RADIUS, post),
                 (RAIL_X, -RAIL_HALF_WIDTH - RAIL_RADIUS, post), 1.0, wood, fixed=True),
            Prop("crib_post_left", "box", (RAIL_RADIUS, RAIL_RADIUS, post),
                 (RAIL_X, RAIL_HALF_WIDTH + RAIL_RADIUS, post), 1.0, wood, fixed=True),
            # under the floor, out of sight: the feet are welded to it (i.e. to the floor)
            Prop("crib_base", "box", (0.3, 0.3, 0.01), (0.1, 0.0, -0.02), 1.0, wood, fixed=True,
                 welds=("infant_0/right_foot", "infant_0/left_foot")),
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
    def reset(self, env, rng):
        w = env.world
        m, d = w.model, w.data
        a = w.agents[0]
        if getattr(self, "_start_world", None) is not w:
            self._start_world = w
            self._start = self._start_pose(env)
            self._rail = m.geom("crib_rail").id
            self._act_qpos = a.qpos_adr[a.actuated_joint_idx]
            self._head = a.head_site
        # (model settings are made at every reset: a pickled world rebuilds its model)
        # the rail only shows where the hands hold on (they are welded to it): it takes no
        # contacts, so the gripping hands never fight it
        m.geom_contype[self._rail] = m.geom_conaffinity[self._rail] = 0
        m.eq_solref[w.welds[:, 0]] = WELD_SOLREF  # stiffer than MuJoCo's default 0.02 s
        d.qpos[:] = self._start
        d.qvel[:] = 0.0
        mujoco.mj_kinematics(m, d)
        w.hold_welds()
        eps = self.options.perturbation
        d.qpos[self._act_qpos] += rng.uniform(-eps, eps, len(self._act_qpos))
        d.ctrl[:] = 0.0
        settle(env, self.options.settle_steps)
        ref = self.options.head_reference
        self._ref = float(d.site_xpos[self._head, 2]) if ref is None else float(ref)
        self._height = float(d.site_xpos[self._head, 2])
        self._cost = 0.0

    def rewards(self, env):
        d = env.world.data
        self._height = float(d.site_xpos[self._head, 2])
        u = env.controls[0]
        self._cost = self.options.cost_weight * float(np.dot(u, u))
        return np.array([self._height - self._ref - self._cost])

    def terminations(self, env):
        return np.zeros(1, bool), [{"head_height": self._height,
                                    "head_gain": self._height - self._ref,
                                    "control_cost": self._cost}]
