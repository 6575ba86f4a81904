"""Reach (paper Sec. VI-A): a standing infant reaches for a ball with its right hand.

| | |
|---|---|
| agents | 1 (`infant_0`), mitten hands, spring-damper motors (five-fingered hands and muscles also work) |
| body | standing, hip fixed; everything but the right arm held at its rest angles; the head and eyes fixate the ball (their angles set every control step) |
| scene | gravity off (as published); a ball (r = 2.5 cm) held in place: a body without joints, put where the reset draws it |
| reset | the right arm (fingers included) starts in one of 10 postures (a fixed set drawn once from a seeded generator, each joint in the middle 40 % of its range); the ball's centre is drawn uniformly in the published box in front of the right shoulder (forward 20 to 30 cm, left -15 to +15 cm, up -1 to +9 cm) and kept only when it is at least `min_distance` = 25 cm from the shoulder, the fingertips reach 5 mm into it (damped least squares over shoulder, elbow and wrist, fingers straight, 3 mm tolerance) and it is 2 cm or more from every part of the body; measured: 25.0 to 30.0 cm from the shoulder over seeds 0-99 |
| physics | two physics steps of 5 ms per control step (`frame_skip=2`): control step 10 ms, as published; an episode is at most 10 s |
| action | the right-arm motors in [-1, 1]: 8 (mitten hands: shoulder 3, elbow, wrist 3, fingers) or 29 (five fingers: + 22 finger joints instead of 1); muscles: 2 per joint in [0, 1] |
| observation | `proprioception` only (84 floats with mitten hands; the head and eye angles tell where the ball is) |
| reward | `+100` (`success_reward`) on the step the right hand touches the ball; otherwise -distance(right fingertips, ball centre) in m |
| success | a geom of the right hand (palm, palm heel, fingers; all finger segments of the five-fingered hand) touches the ball (`is_success`); no other part counts |
| termination | on success; truncation at 1000 steps |
| infos | `is_success`, `distance` (m, right fingertips to the ball's centre) |
| privileged cues | the task points the head and eyes at the ball every step: the ball's position reaches the learner as its own head and eye angles (proprioception), not through a sense of its own |
| differences from the paper | (1) success is a touch of the right hand, as the paper's text says ("until MIMo successfully touches the ball"), not the published code's "the ball moved more than 1 cm": that rule paid any push (measured before this change, git 3f7ffa1: a random policy succeeded in 23 of 30 episodes, 7 of them by moving the ball without a hand contact). (2) The ball is held in place (the published one floats free in zero gravity, "hovering"): a pushed ball cannot drift away and back into the hand. (3) Of the published box only the part at least 25 cm from the shoulder and within the fingertips' reach is used: the box reaches 35 cm, beyond the fingertips (the farthest reachable centre measured is 30 cm); below 23.8 cm the forearm can touch the ball (its outer surface comes at most 21.3 cm from the shoulder, measured over 30000 random arm postures, plus the ball's 2.5 cm), and there the random arm sweeps: random success over seeds 0-99 is 17 % with `min_distance` = 0 against 8 % at 25 cm. (4) "The fingers' position" in the reward is the right fingertips site (the published code takes the mitten's finger body origin, at the knuckles; the five-fingered hand has no single finger body). (5) The reward is +100 on success (the paper's equation; the published code pays 100 - distance). (6) The finger joint is actuated (the published scene welds the mitten's fingers to the hand, its motor idle). (7) The 10 start postures are drawn over the middle 40 % of each joint's range, as the text says ("10 random positions"; the published code takes 10 random single physics steps from one rest pose) |
| baselines | seeds 0-99, 1000 steps at most (`python tests/tasks/test_reach.py 100`; random: `action_space.sample()` seeded 1000 + seed): scripted `ReachController` (`mimo_social.partners.controllers.reach`) 100 % success, return 96.1 +- 1.4, 49 steps to the ball; random 8 %, return -238.7 +- 89.3; zero action 0 %, return -320.4 +- 24.2; a forearm push (the arm driven to put the forearm's middle on the ball) 69 % success (the hand gets there first; the forearm never touched the ball), return 47.0 +- 72.2. Five-fingered hands, seeds 0-29: controller 100 %, random 7 % (2 of 30), zero 0 %; muscles, seeds 0-29: controller 100 %, random 0 %, zero 0 %. `mimo-social baselines reach --episodes 30 --seed 1000 --run <6 runs>` (seeds 1000-1029; docs/baselines.md): scripted 100 %, 96 +- 2, 51 steps; random 7 %, -248; zero 0 %, -317; PPO (SB3 defaults, 300k steps, 3 seeds) 100 / 87 / 93 %, return 95 / 70 / 79, 47 / 39 / 86 steps to the ball; SAC (20k steps, 3 seeds, the budget this machine affords: ~50 steps/s) 0 / 0 / 0 %, -290 / -297 / -271 |
| sources | the MIMo paper (Mattern et al.), Sec. VI-A: the reaching demo; the published task's settings (`mimo-figures.md`, MIMoReach-v0: ball box, gravity 0, 10 ms control step, 1000 steps) |
| version history | v0: first version, with the first env; later in v0: the published success criterion (ball moved > 1 cm) and no start touching the body; v0, issue 14: success is a touch of the right hand on a ball held in place at arm's length (25 to 30 cm from the shoulder, option `min_distance`; option `moved_threshold` removed) |
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ..body.joint_groups import GAZE_JOINTS, held_posture, right_arm_joints
from ..body.tables import load_body
from ..core.kinematics import Gaze, hand_geoms, reach_sites
from ..core.task import Plot, Task, TaskOptions
from ..core.world import AgentSetup, Prop
from .common import ContactProbe

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

    def reset(self, env, rng):
        w = env.world
        m, d = w.model, w.data
        if not hasattr(self, "_postures"):
            self._prepare(env)
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
