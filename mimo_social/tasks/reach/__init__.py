"""Reach (paper Sec. VI-A): a standing infant reaches for a ball with its right hand.

agents:
    1 (`infant_0`), mitten hands, spring-damper motors (five-fingered hands and muscles also work)
body:
    standing, hip fixed; everything but the right arm held at its rest angles; the head and eyes
    fixate the ball (their angles set every control step)
scene:
    gravity off (as published); a ball (r = 2.5 cm) held in place: a body without joints, put where
    the reset draws it
reset:
    the right arm (fingers included) starts in one of 10 postures (a fixed set drawn once from a
    seeded generator, each joint in the middle 40 % of its range); the ball's centre is drawn
    uniformly in the published box in front of the right shoulder (forward 20 to 30 cm, left -15 to
    +15 cm, up -1 to +9 cm) and kept only when it is at least `min_distance` = 25 cm from the
    shoulder, the fingertips reach 5 mm into it (damped least squares over shoulder, elbow and
    wrist, fingers straight, 3 mm tolerance) and it is 2 cm or more from every part of the body;
    measured: 25.0 to 30.0 cm from the shoulder over seeds 0-99
physics:
    two physics steps of 5 ms per control step (`frame_skip=2`): control step 10 ms, as published;
    an episode is at most 10 s
action:
    the right-arm motors in [-1, 1]: 8 (mitten hands: shoulder 3, elbow, wrist 3, fingers) or 29
    (five fingers: + 22 finger joints instead of 1); muscles: 2 per joint in [0, 1]
observation:
    `proprioception` only (84 floats with mitten hands; the head and eye angles tell where the ball
    is)
reward:
    `+100` (`success_reward`) on the step the right hand touches the ball; otherwise -distance(right
    fingertips, ball centre) in m
success:
    a geom of the right hand (palm, palm heel, fingers; all finger segments of the five-fingered
    hand) touches the ball (`is_success`); no other part counts
termination:
    on success; truncation at 1000 steps
infos:
    `is_success`, `distance` (m, right fingertips to the ball's centre)
privileged cues:
    the task points the head and eyes at the ball every step: the ball's position reaches the
    learner as its own head and eye angles (proprioception), not through a sense of its own
differences from the paper:
    (1) success is a touch of the right hand, as the paper's text says ("until MIMo successfully
    touches the ball"), not the published code's "the ball moved more than 1 cm": that rule paid any
    push (measured before this change, git 3f7ffa1: a random policy succeeded in 23 of 30 episodes,
    7 of them by moving the ball without a hand contact). (2) The ball is held in place (the
    published one floats free in zero gravity, "hovering"): a pushed ball cannot drift away and back
    into the hand. (3) Of the published box only the part at least 25 cm from the shoulder and
    within the fingertips' reach is used: the box reaches 35 cm, beyond the fingertips (the farthest
    reachable centre measured is 30 cm); below 23.8 cm the forearm can touch the ball (its outer
    surface comes at most 21.3 cm from the shoulder, measured over 30000 random arm postures, plus
    the ball's 2.5 cm), and there the random arm sweeps: random success over seeds 0-99 is 17 % with
    `min_distance` = 0 against 8 % at 25 cm. (4) "The fingers' position" in the reward is the right
    fingertips site (the published code takes the mitten's finger body origin, at the knuckles; the
    five-fingered hand has no single finger body). (5) The reward is +100 on success (the paper's
    equation; the published code pays 100 - distance). (6) The finger joint is actuated (the
    published scene welds the mitten's fingers to the hand, its motor idle). (7) The 10 start
    postures are drawn over the middle 40 % of each joint's range, as the text says ("10 random
    positions"; the published code takes 10 random single physics steps from one rest pose)
baselines:
    seeds 0-99, 1000 steps at most (`python tests/tasks/test_reach.py 100`; random:
    `action_space.sample()` seeded 1000 + seed): scripted `ReachController`
    (`mimo_social.tasks.reach.controller`) 100 % success, return 96.1 +- 1.4, 49 steps to the ball;
    random 8 %, return -238.7 +- 89.3; zero action 0 %, return -320.4 +- 24.2; a forearm push (the
    arm driven to put the forearm's middle on the ball) 69 % success (the hand gets there first; the
    forearm never touched the ball), return 47.0 +- 72.2. Five-fingered hands, seeds 0-29:
    controller 100 %, random 7 % (2 of 30), zero 0 %; muscles, seeds 0-29: controller 100 %, random
    0 %, zero 0 %. `mimo-social baselines reach --episodes 30 --seed 1000 --run <6 runs>` (seeds
    1000-1029; docs/baselines.md): scripted 100 %, 96 +- 2, 51 steps; random 7 %, -248; zero 0 %,
    -317; PPO (SB3 defaults, 300k steps, 3 seeds) 100 / 87 / 93 %, return 95 / 70 / 79, 47 / 39 / 86
    steps to the ball; SAC (20k steps, 3 seeds, the budget this machine affords: ~50 steps/s) 0 / 0
    / 0 %, -290 / -297 / -271
sources:
    the MIMo paper (Mattern et al.), Sec. VI-A: the reaching demo; the published task's settings
    (`mimo-figures.md`, MIMoReach-v0: ball box, gravity 0, 10 ms control step, 1000 steps)
version history:
    v0: first version, with the first env; later in v0: the published success criterion (ball moved
    > 1 cm) and no start touching the body; v0, issue 14: success is a touch of the right hand on a
    ball held in place at arm's length (25 to 30 cm from the shoulder, option `min_distance`; option
    `moved_threshold` removed)

``parallel_env(n_agents=..., task_options={...}, physics={...}, per_agent=[...], **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv`; ``env(...)`` the AEC version.
"""

from .task import (parallel_env, env, Reach, ReachOptions)
from .controller import ReachController

__all__ = ["parallel_env", "env", "Reach", "ReachController", "ReachOptions"]
