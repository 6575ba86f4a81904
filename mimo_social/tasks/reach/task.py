"""The reach task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ...body.joint_groups import GAZE_JOINTS, held_posture, right_arm_joints
from ...body.tables import load_body
from ...core.kinematics import Gaze, hand_geoms, reach_sites
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup, Prop
from ..common import ContactProbe
from ...core.factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "Reach", "ReachOptions"]

BALL_RADIUS = 0.025
N_START_POSTURES = 10
CLEARANCE = 0.02  # m between the ball and the body at the start
MAX_PLACEMENT_TRIES = 200
#: the published box of ball centres, from the right shoulder: (forward, left, up), m
BALL_BOX = ((0.2, 0.3), (-0.15, 0.15), (-0.01, 0.09))
#: the fingertips must reach this deep into the ball (m) for a position to count as in reach
REACH_DEPTH = 0.005
REACH_TOLERANCE = 0.003  # m left by the inverse kinematics for "in reach"


@dataclass(frozen=True)
class ReachOptions(TaskOptions):
    """Reward on reaching the ball; the nearest the ball's centre may be to the right
    shoulder (m)."""

    task = "reach"
    success_reward: float = 100.0
    min_distance: float = 0.25

    def __post_init__(self):
        self._number("success_reward")
        self._number("min_distance", 0.0, 0.28)


class Reach(Task):
    name = "reach"
    n_agents_range = (1, 1)
    default_n_agents = 1
    default_max_steps = 1000
    physics_overrides = {"gravity": (0.0, 0.0, 0.0)}

    Options = ReachOptions

    def agent_defaults(self, i, settings):
        return {"posture": "standing", "vestibular": False, "expressions": False}

    def setup(self, i, config):
        tables = load_body(config.hands)
        arm = right_arm_joints(tables)
        frozen = held_posture(tables, keep=arm + GAZE_JOINTS)
        return AgentSetup(config, position=(0.0, 0.0), facing=(1.0, 0.0), frozen=frozen,
                          base="fixed", actuated=arm, gaze_joints=GAZE_JOINTS)

    def props(self):
        return [Prop("ball", "sphere", (BALL_RADIUS,), (0.3, -0.05, 0.7), 0.05,
                     (0.9, 0.2, 0.2, 1), fixed=True)]

    def _prepare(self, env):
        w = env.world
        m = w.model
        a = w.agents[0]
        k = np.array([a.joint_names.index(n) for n in right_arm_joints(w.tables[0])])
        self._arm_qpos = a.qpos_adr[k]
        lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
        fixed = np.random.default_rng(12345)  # the same 10 postures in every run
        self._postures = lo + (hi - lo) * (0.3 + 0.4 * fixed.random((N_START_POSTURES, len(k))))
        self._ik_qpos, self._ik_dof = a.qpos_adr[k[:7]], a.dof_adr[k[:7]]  # shoulder to wrist
        self._ik_lo, self._ik_hi = lo[:7], hi[:7]
        self._straight = (a.qpos_adr[k[7:]], np.clip(0.0, lo[7:], hi[7:]))  # fingers straight
        self._hand = hand_geoms(w, 0)
        self._touch_ball = ContactProbe(m.ngeom, self._hand, [m.geom("ball").id])
        self._gaze = Gaze(w, 0)
        self._ball_body = w.prop_bodies["ball"]
        self._ball_geom = m.geom("ball").id
        self._body_geoms = a.geom_ids
        self._tip = int(a.fingertip_sites[0])
        self._shoulder_body = int(m.jnt_bodyid[m.jnt_qposadr.tolist().index(
            a.qpos_adr[a.joint_names.index("right_shoulder_horizontal")])])

    def bind(self, env):
        """Index tables of this world (once per world: :meth:`Task.bind`)."""
        self._prepare(env)

    def reset(self, env, rng):
        w = env.world
        m, d = w.model, w.data
        d.qpos[self._arm_qpos] = self._postures[rng.integers(N_START_POSTURES)]
        mujoco.mj_kinematics(m, d)
        shoulder = d.xpos[self._shoulder_body].copy()
        for _ in range(MAX_PLACEMENT_TRIES):
            ball = shoulder + np.array([rng.uniform(*r) for r in BALL_BOX])
            if np.linalg.norm(ball - shoulder) < self.options.min_distance:
                continue
            self._place(m, d, ball)
            if self._clearance(m, d) >= CLEARANCE and self._in_reach(m, d, shoulder, ball):
                break
        else:
            raise RuntimeError(f"reach: no ball position in reach and clear of the body in "
                               f"{MAX_PLACEMENT_TRIES} tries (min_distance="
                               f"{self.options.min_distance})")
        self.ball_position = ball.copy()
        self._touched = False
        self.before_physics(env)

    def _place(self, m, d, ball) -> None:
        m.body_pos[self._ball_body] = ball
        mujoco.mj_kinematics(m, d)

    def place_ball(self, env, position) -> None:
        """Hold the ball at a world position for the rest of the episode (for tests and
        demonstrations; kinematics updated, the head and eyes turned to it)."""
        self.ball_position = np.array(position, dtype=float)
        self._place(env.world.model, env.world.data, self.ball_position)
        self.before_physics(env)

    def _in_reach(self, m, d, shoulder, ball) -> bool:
        """Whether the fingertips can reach REACH_DEPTH into the ball along the line from the
        shoulder (damped least squares from the middle of the joint ranges, on a scratch copy)."""
        s = mujoco.MjData(m)
        s.qpos[:] = d.qpos
        s.qpos[self._ik_qpos] = 0.5 * (self._ik_lo + self._ik_hi)
        s.qpos[self._straight[0]] = self._straight[1]
        u = (ball - shoulder) / np.linalg.norm(ball - shoulder)
        goal = ball - (BALL_RADIUS - REACH_DEPTH) * u
        left = reach_sites(m, s, self._ik_qpos, self._ik_dof, self._ik_lo, self._ik_hi,
                           self._tip, goal, iters=100)
        return left < REACH_TOLERANCE

    def _clearance(self, m, d) -> float:
        """Smallest distance (m) between the ball and any of the infant's geoms."""
        return min(mujoco.mj_geomDistance(m, d, self._ball_geom, int(g), CLEARANCE, None)
                   for g in self._body_geoms)

    def before_physics(self, env):
        w = env.world
        self._gaze(w.model, w.data, "body", self._ball_body)

    def rewards(self, env):
        w = env.world
        d = w.data
        self._touched = self._touch_ball(d)
        self._dist = float(np.linalg.norm(d.site_xpos[self._tip] - d.xpos[self._ball_body]))
        return np.array([self.options.success_reward if self._touched else -self._dist])

    def plots(self):
        """Reward, the fingertip's distance to the ball and success (the ball touched)."""
        return [Plot.reward(),
                Plot("distance", "m", lambda env: (self._dist,)),
                Plot("success", "0/1", lambda env: (self._touched,))]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"is_success": "number", "distance": "number"}

    def terminations(self, env):
        return (np.array([self._touched]),
                [{"is_success": self._touched, "distance": self._dist}])


# -- the env factories (``mimo_social.envs.reach_v0`` re-exports them) --------------------

def parallel_env(**kwargs):
    return make_parallel(Reach, **kwargs)


def env(**kwargs):
    return make_aec(Reach, **kwargs)
