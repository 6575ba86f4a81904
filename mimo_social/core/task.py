"""What a task is: scene additions, placement, held joints, reset randomisation, rewards, ends.

A task never touches MuJoCo names at run time: it reads the world's integer index tables.
One-agent tasks (reach ...) are tasks like any other; the Gymnasium adapter wraps the same env.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping, Sequence

import mujoco
import numpy as np
from gymnasium import spaces

from .config import AgentConfig
from .world import AgentSetup, Prop

if TYPE_CHECKING:  # pragma: no cover
    from .env import MimoParallelEnv

HEAD_GAZE_JOINTS = ("head_swivel", "head_tilt", "head_tilt_side")
EYE_GAZE_JOINTS = ("right_eye_horizontal", "right_eye_vertical", "right_eye_torsional",
                   "left_eye_horizontal", "left_eye_vertical", "left_eye_torsional")
GAZE_JOINTS = HEAD_GAZE_JOINTS + EYE_GAZE_JOINTS
RIGHT_ARM_JOINTS = ("right_shoulder_horizontal", "right_shoulder_abduction",
                    "right_shoulder_rotation", "right_elbow", "right_wrist_rotation",
                    "right_wrist_flexion", "right_wrist_ulnar", "right_fingers")


def right_arm_joints(tables) -> tuple[str, ...]:
    """The right arm's joints of this body version: :data:`RIGHT_ARM_JOINTS` (8) for the mitten
    hands, shoulder 3 + elbow + wrist 3 + 22 finger joints for the five-fingered hands."""
    from ..body.tables import arm_joints
    return arm_joints(tables, "right")


def hand_geoms(world, i: int, side: int = 0) -> np.ndarray:
    """Geoms of agent i's hand (``side`` 0: right, 1: left): the body holding the palm site and
    every body below it (the mitten's fingers, or the five fingers' segments)."""
    m = world.model
    a = world.agents[i]
    hand = int(m.site_bodyid[a.palm_sites[side]])
    inside = np.zeros(m.nbody, bool)
    inside[hand] = True
    for b in sorted(a.body_ids.tolist()):  # MuJoCo numbers a parent before its children
        if inside[m.body_parentid[b]]:
            inside[b] = True
    return a.geom_ids[inside[m.geom_bodyid[a.geom_ids]]]


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
        self.configs: Sequence[AgentConfig] = ()  # every agent's config, set by the env

    # -- building ------------------------------------------------------------------------------
    def option_defaults(self) -> dict:
        return {}

    def agent_defaults(self, i: int) -> dict:
        """Default agent settings this task wants (users may override them)."""
        return {}

    def setup(self, i: int, config: AgentConfig) -> AgentSetup:
        pos, facing = self.placement(i, self.configs)
        return AgentSetup(config, position=config.position or pos,
                          facing=config.facing or facing)

    # How far (m) an infant of scale 1 in each posture reaches forward from its hip along the
    # floor, and its half width with arms and legs; both grow with the agent's `scale`. The
    # circle is made large enough that no two infants start interpenetrating (their forward
    # parts converge toward the centre).
    POSTURE_REACH = {"standing": 0.22, "sitting": 0.45, "lying": 0.48}
    HALF_WIDTH = 0.2
    CLEARANCE = 0.14

    def placement(self, i: int, configs: Sequence[AgentConfig] = ()) -> tuple:
        """Agents on a circle around the origin, each facing the centre.

        The radius leaves room for the largest agent's reach and half width (both times its
        ``scale``)."""
        if self.n_agents == 1:
            return (0.0, 0.0), (1.0, 0.0)
        reach = max((self.POSTURE_REACH[c.posture] * c.scale for c in configs),
                    default=self.POSTURE_REACH["standing"])
        half = max((self.HALF_WIDTH * c.scale for c in configs), default=self.HALF_WIDTH)
        sin = np.sin(np.pi / self.n_agents)
        radius = max(0.3, reach + self.CLEARANCE / sin, half / sin)
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


def parts_outside(tables, roots: tuple[str, ...]) -> tuple[str, ...]:
    """Every body part with geoms that is not in the subtree of one of ``roots``: the touch
    ``exclude`` list that leaves skin on those subtrees only."""
    from ..body.tables import subtree
    keep = set()
    for r in roots:
        keep |= set(subtree(tables, r))
    out = []
    for g in tables.geoms:
        if g.body not in keep and g.body not in out:
            out.append(g.body)
    return tuple(out)


def face_to_face(i: int, distance: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """Position and point to face of agent ``i`` of a pair ``distance`` apart on the x axis."""
    pos = (0.0, 0.0) if i == 0 else (float(distance), 0.0)
    facing = (float(distance), 0.0) if i == 0 else (0.0, 0.0)
    return pos, facing


def geoms_touching(data, geom: int) -> np.ndarray:
    """The geoms in active contact (distance <= 0) with ``geom`` this step (one gather over the
    contacts, no loop)."""
    n = data.ncon
    if n == 0:
        return np.zeros(0, dtype=np.intp)
    c = data.contact
    g1, g2 = c.geom1[:n], c.geom2[:n]
    on = ((g1 == geom) | (g2 == geom)) & (c.dist[:n] <= 0.0)
    return np.where(g1 == geom, g2, g1)[on]


class ContactProbe:
    """Tells whether any active contact joins a geom of set a with a geom of set b.

    Boolean masks over all geoms are built once, so a query is two gathers over the contacts.
    """

    def __init__(self, ngeom: int, geoms_a, geoms_b):
        self.a = np.zeros(ngeom, bool)
        self.b = np.zeros(ngeom, bool)
        self.a[np.asarray(geoms_a, dtype=np.intp)] = True
        self.b[np.asarray(geoms_b, dtype=np.intp)] = True

    def __call__(self, data) -> bool:
        n = data.ncon
        if n == 0:
            return False
        c = data.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        hit = (self.a[g1] & self.b[g2]) | (self.a[g2] & self.b[g1])
        return bool(np.any(hit & (c.dist[:n] <= 0.0)))


class Gaze:
    """Turns one agent's head and eyes to fixate a world point by setting their joint angles.

    The head turns (swivel, then tilt) to face the target from the neck; each eye then turns
    (horizontal, then vertical) to look at it from its own centre, so the joint angles of head
    and eyes together tell where the target is, as in the paper's reach and catch tasks.
    Addresses are resolved once; a call costs three ``mj_kinematics``.
    """

    def __init__(self, world, i: int):
        m = world.model
        a = world.agents[i]
        self.agent = a
        names = [a.joint_names[k] for k in a.gaze_idx]
        self.qpos = a.qpos_adr[a.gaze_idx]
        self.dof = a.dof_adr[a.gaze_idx]
        self.head_body = int(m.site_bodyid[a.head_site])
        self.has_head = "head_swivel" in names

        def slot(name):
            if name not in names:
                return None
            k = a.gaze_idx[names.index(name)]
            return int(a.qpos_adr[k]), float(a.joint_range[k, 0]), float(a.joint_range[k, 1])

        self.swivel, self.tilt = slot("head_swivel"), slot("head_tilt")
        self.eyes = [(int(m.cam_bodyid[cam]), sign, slot(f"{side}_eye_horizontal"),
                      slot(f"{side}_eye_vertical"))
                     for side, sign, cam in (("right", -1.0, a.eye_cameras[0]),
                                             ("left", 1.0, a.eye_cameras[1]))]

    @staticmethod
    def _set(d, slot, angle):
        if slot is not None:
            adr, lo, hi = slot
            d.qpos[adr] = min(max(float(angle), lo), hi)

    def __call__(self, model, data, kind: str, obj: int) -> None:
        """Fixate body ``obj`` (``kind="body"``) or site ``obj`` (``kind="site"``)."""
        d = data
        if not len(self.qpos):
            return
        d.qpos[self.qpos] = 0.0
        d.qvel[self.dof] = 0.0
        mujoco.mj_kinematics(model, d)  # also brings the target's position up to date
        target = (d.xpos if kind == "body" else d.site_xpos)[obj].copy()
        hb = self.head_body
        if self.has_head:
            v = d.xmat[hb].reshape(3, 3).T @ (target - d.xpos[hb])
            self._set(d, self.swivel, np.arctan2(v[1], v[0]))
            self._set(d, self.tilt, -np.arctan2(v[2], np.hypot(v[0], v[1])))
            mujoco.mj_kinematics(model, d)
        R = d.xmat[hb].reshape(3, 3)
        for body, sign, horizontal, vertical in self.eyes:
            v = R.T @ (target - d.xpos[body])
            self._set(d, horizontal, sign * np.arctan2(v[1], v[0]))
            self._set(d, vertical, np.arctan2(v[2], np.hypot(v[0], v[1])))
        mujoco.mj_kinematics(model, d)
