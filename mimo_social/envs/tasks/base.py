"""What a task is: scene additions, placement, held joints, reset randomisation, rewards, ends.

A task never touches MuJoCo names at run time: it reads the world's integer index tables.
One-agent tasks (reach ...) are tasks like any other; the Gymnasium adapter wraps the same env.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping

import mujoco
import numpy as np
from gymnasium import spaces

from ..config import AgentConfig
from ..world import AgentSetup, Prop

if TYPE_CHECKING:  # pragma: no cover
    from ..parallel import MimoParallelEnv

HEAD_GAZE_JOINTS = ("head_swivel", "head_tilt", "head_tilt_side")
EYE_GAZE_JOINTS = ("right_eye_horizontal", "right_eye_vertical", "right_eye_torsional",
                   "left_eye_horizontal", "left_eye_vertical", "left_eye_torsional")
GAZE_JOINTS = HEAD_GAZE_JOINTS + EYE_GAZE_JOINTS
RIGHT_ARM_JOINTS = ("right_shoulder_horizontal", "right_shoulder_abduction",
                    "right_shoulder_rotation", "right_elbow", "right_wrist_rotation",
                    "right_wrist_flexion", "right_wrist_ulnar", "right_fingers")


class Task:
    """Base task: N infants on the floor, reward 0, never terminates (truncated at max_steps)."""

    name = "task"
    n_agents_range = (1, 8)
    default_n_agents = 2
    default_max_steps = 1000
    physics_overrides: Mapping[str, Any] = {}

    def __init__(self, n_agents: int, **options):
        lo, hi = self.n_agents_range
        if not isinstance(n_agents, (int, np.integer)) or not lo <= n_agents <= hi:
            raise ValueError(f"{self.name}: n_agents={n_agents!r}; allowed: {lo} to {hi}")
        unknown = sorted(set(options) - set(self.option_defaults()))
        if unknown:
            raise ValueError(f"{self.name}: unknown task option(s) {unknown}; "
                             f"allowed: {sorted(self.option_defaults())}")
        self.n_agents = int(n_agents)
        self.options = {**self.option_defaults(), **options}

    # -- building ------------------------------------------------------------------------------
    def option_defaults(self) -> dict:
        return {}

    def agent_defaults(self, i: int) -> dict:
        """Default agent settings this task wants (users may override them)."""
        return {}

    def setup(self, i: int, config: AgentConfig) -> AgentSetup:
        pos, facing = self.placement(i)
        return AgentSetup(config, position=config.position or pos,
                          facing=config.facing or facing)

    def placement(self, i: int) -> tuple[tuple[float, float], tuple[float, float]]:
        """Agents on a circle around the origin, each facing the centre."""
        if self.n_agents == 1:
            return (0.0, 0.0), (1.0, 0.0)
        radius = max(0.3, 0.12 * self.n_agents)
        angle = np.pi + 2 * np.pi * i / self.n_agents
        pos = (radius * np.cos(angle), radius * np.sin(angle))
        return (float(pos[0]), float(pos[1])), (0.0, 0.0)

    def props(self) -> list[Prop]:
        return []

    def task_spaces(self, env: "MimoParallelEnv", i: int) -> dict[str, spaces.Space]:
        """Extra observation keys of this task for agent i."""
        return {}

    # -- running -------------------------------------------------------------------------------
    def reset(self, env: "MimoParallelEnv", rng: np.random.Generator) -> None:
        """Randomise the initial state (the world has been reset to its initial pose)."""

    def before_physics(self, env: "MimoParallelEnv") -> None:
        """Called once per control step after the actions were applied."""

    def observe(self, env: "MimoParallelEnv", i: int) -> dict[str, np.ndarray]:
        return {}

    def rewards(self, env: "MimoParallelEnv") -> np.ndarray:
        return np.zeros(self.n_agents)

    def terminations(self, env: "MimoParallelEnv") -> tuple[np.ndarray, list[dict]]:
        """Per agent: terminated?, and task infos."""
        return np.zeros(self.n_agents, bool), [{} for _ in range(self.n_agents)]


# -- helpers shared by tasks -------------------------------------------------------------------
def held_posture(tables, keep: tuple[str, ...], angles: Mapping[str, float] | None = None) -> dict:
    """Freeze every joint except ``keep``, at the given angles (deg) or its spring reference."""
    angles = angles or {}
    out = {}
    for j in tables.joints:
        if j.name in keep or j.coupled_to:
            continue
        lo, hi = j.range_deg
        out[j.name] = float(np.deg2rad(np.clip(angles.get(j.name, j.springref_deg), lo, hi)))
    return out


def geoms_in_contact(model, data, geoms_a: np.ndarray, geoms_b: np.ndarray) -> bool:
    """True when any active contact joins a geom of set a with a geom of set b."""
    n = data.ncon
    if n == 0:
        return False
    g1 = data.contact.geom1[:n]
    g2 = data.contact.geom2[:n]
    real = data.contact.dist[:n] <= 0.0
    ina1, ina2 = np.isin(g1, geoms_a), np.isin(g2, geoms_a)
    inb1, inb2 = np.isin(g1, geoms_b), np.isin(g2, geoms_b)
    return bool(np.any(real & ((ina1 & inb2) | (ina2 & inb1))))


def point_gaze(env: "MimoParallelEnv", i: int, target: np.ndarray) -> None:
    """Turn agent i's head and eyes to fixate ``target`` (world point): sets the joint angles.

    The head turns (swivel, then tilt) to face the target from the neck; each eye then turns
    (horizontal, then vertical) to look at it from its own centre, so the joint angles of head
    and eyes together tell where the target is, as in the paper's reach and catch tasks.
    """
    m, d = env.world.model, env.world.data
    a = env.world.agents[i]
    idx = a.gaze_idx
    if not len(idx):
        return
    names = [a.joint_names[k] for k in idx]
    adr = {n: a.qpos_adr[k] for n, k in zip(names, idx)}
    d.qpos[[adr[n] for n in names]] = 0.0
    d.qvel[[a.dof_adr[k] for k in idx]] = 0.0
    mujoco.mj_kinematics(m, d)
    head_body = m.site_bodyid[a.head_site]
    if "head_swivel" in adr:
        R = d.xmat[head_body].reshape(3, 3)
        v = R.T @ (target - d.xpos[head_body])
        _set(d, a, adr, "head_swivel", np.arctan2(v[1], v[0]))
        _set(d, a, adr, "head_tilt", -np.arctan2(v[2], np.hypot(v[0], v[1])))
        mujoco.mj_kinematics(m, d)
    R = d.xmat[head_body].reshape(3, 3)
    for side, cam in zip(("right", "left"), a.eye_cameras):
        h = f"{side}_eye_horizontal"
        if h not in adr:
            continue
        v = R.T @ (target - d.xpos[m.cam_bodyid[cam]])
        az = np.arctan2(v[1], v[0])
        _set(d, a, adr, h, az if side == "left" else -az)
        _set(d, a, adr, f"{side}_eye_vertical", np.arctan2(v[2], np.hypot(v[0], v[1])))
    mujoco.mj_kinematics(m, d)


def _set(d, a, adr, name, angle):
    if name in adr:
        k = a.joint_names.index(name)
        lo, hi = a.joint_range[k]
        d.qpos[adr[name]] = np.clip(angle, lo, hi)
