"""Reach (paper Sec. VI-A): a standing infant reaches for a ball with its right hand.

| | |
|---|---|
| agents | 1 (`infant_0`) |
| body | hip fixed; everything but the right arm held; head and eyes fixate the ball (set each step) |
| scene | gravity off (as in the published task); a ball (r = 2.5 cm) placed at random within reach |
| reset | the right arm starts in one of 10 postures (fixed set, drawn once from a seeded generator); the ball position is sampled in front of the right shoulder, 14-22 cm away and at least 2 cm from the body |
| action | the right-arm motors in [-1, 1]: 8 (mitten hands: shoulder 3, elbow, wrist 3, fingers) or 29 (five fingers: + 22 finger joints instead of 1) |
| observation | `proprioception` only (84 floats; the head and eye angles tell where the ball is) |
| reward | `-distance(right fingertips, ball)`, or `+100` when the target is reached |
| success | the right hand or fingers touch the ball, or the ball has moved more than 1 cm from its start (the published task's criterion: in zero gravity any touch of the arm moves it) |
| termination | on success (`is_success`); truncation at 1000 steps |
| privileged cues | the task points the head and eyes at the ball every step: the ball's position reaches the learner as its own head and eye angles (proprioception), not through a sense of its own |
| baselines | random policy (uniform actions, 100 episodes; no command in the package): the ball reached in 74 episodes, mean length 457 steps, return -17 +- 126; success alone says little here, the steps to the ball say how well a policy reaches. PPO, seed 0, 300k steps (5.4 min): evaluation success (10 episodes) 20-60 % up to 60k steps, 100 % from 75k steps (85 s) on; on 100 fresh episodes 100 % success, mean 7 steps to the ball (`mimo-social train --task reach --algo ppo --steps 300000 --seed 0 --out runs/reach_ppo_s0`, then `mimo-social eval runs/reach_ppo_s0 --episodes 100`). PPO, seeds 1 and 2, 150k steps (4.9 / 6.6 min): 100 % evaluation success from 105k / 90k steps on; on 100 fresh episodes 100 % and 100 %, mean 21 steps to the ball (`mimo-social train --task reach --algo ppo --steps 150000 --seed 1 --out runs/reach_ppo_s1`) |
| sources | the MIMo paper (Mattern et al.), Sec. VI-A: the reaching demo |
| version history | v0: first version, with the first env; later in v0: the published success criterion (ball moved > 1 cm) and no start touching the body |
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ..body.joint_groups import GAZE_JOINTS, held_posture, right_arm_joints
from ..body.tables import load_body
from ..core.kinematics import Gaze, hand_geoms
from ..core.task import Task, TaskOptions
from ..core.world import AgentSetup, Prop
from .common import ContactProbe

BALL_RADIUS = 0.025
N_START_POSTURES = 10
CLEARANCE = 0.02  # m between the ball and the body at the start
MAX_PLACEMENT_TRIES = 50


@dataclass(frozen=True)
class ReachOptions(TaskOptions):
    """Reward on reaching the ball, and how far (m) the ball must move to count as reached."""

    task = "reach"
    success_reward: float = 100.0
    moved_threshold: float = 0.01

    def __post_init__(self):
        self._number("success_reward")
        self._number("moved_threshold", 0.0, 1.0)


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
        return [Prop("ball", "sphere", (BALL_RADIUS,), (0.3, -0.05, 0.7), 0.05, (0.9, 0.2, 0.2, 1))]

    def _arm(self, env):
        a = env.world.agents[0]
        k = [a.joint_names.index(n) for n in right_arm_joints(env.world.tables[0])]
        return a, np.array(k)

    def reset(self, env, rng):
        w = env.world
        m, d = w.model, w.data
        a, k = self._arm(env)
        if not hasattr(self, "_postures"):
            lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
            span = hi - lo
            fixed = np.random.default_rng(12345)  # the same 10 postures in every run
            self._postures = lo + span * (0.3 + 0.4 * fixed.random((N_START_POSTURES, len(k))))
            m_ = env.world.model
            a_ = env.world.agents[0]
            self._hand = hand_geoms(env.world, 0)
            self._touch_ball = ContactProbe(m_.ngeom, self._hand, [m_.geom("ball").id])
            self._gaze = Gaze(env.world, 0)
            self._ball_body = env.world.prop_bodies["ball"]
            self._ball_geom = m_.geom("ball").id
            self._body_geoms = a_.geom_ids
            self._shoulder_body = m_.jnt_bodyid[m_.jnt_qposadr.tolist().index(
                a_.qpos_adr[a_.joint_names.index("right_shoulder_horizontal")])]
        d.qpos[a.qpos_adr[k]] = self._postures[rng.integers(N_START_POSTURES)]
        mujoco.mj_kinematics(m, d)
        # the ball: in front of the right shoulder, within the arm's reach, and at least
        # CLEARANCE away from the body (a ball placed inside the arm would count as reached)
        sh = d.xpos[self._shoulder_body].copy()
        q = w.prop_qpos["ball"]
        for _ in range(MAX_PLACEMENT_TRIES):
            direction = np.array([1.0, rng.uniform(-0.6, 0.2), rng.uniform(-0.5, 0.5)])
            direction /= np.linalg.norm(direction)
            ball = sh + rng.uniform(0.14, 0.22) * direction
            d.qpos[q:q + 3] = ball
            d.qpos[q + 3:q + 7] = (1, 0, 0, 0)
            mujoco.mj_kinematics(m, d)
            if self._clearance(m, d) >= CLEARANCE:
                break
        self._ball_start = ball.copy()
        self._touched = False
        self.before_physics(env)

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
        moved = np.linalg.norm(d.xpos[self._ball_body] - self._ball_start)
        self._touched = self._touch_ball(d) or moved > self.options.moved_threshold
        dist = np.linalg.norm(d.site_xpos[w.agents[0].fingertip_sites[0]]
                              - d.xpos[w.prop_bodies["ball"]])
        self._dist = dist
        return np.array([self.options.success_reward if self._touched else -dist])

    def terminations(self, env):
        return (np.array([self._touched]),
                [{"is_success": self._touched, "distance": float(self._dist)}])
