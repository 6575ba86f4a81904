"""Catch (paper Sec. VI-A): a ball falls onto the infant's open right hand; grasp it and hold it.

agents:
    1 (`infant_0`), five-fingered hands, muscle actuation
body:
    standing, hip fixed; the right arm held stretched forward at the published angles (shoulder
    97.4, 45.8, -91.7 deg, elbow -22.9 deg: 1.7, 0.8, -1.6, -0.4 rad), palm up; the thumb held at
    its rest angles (to the side); everything else held except the right wrist and fingers; head and
    eyes fixate the ball (set each control step)
scene:
    a ball: radius U(0.5, 2.5) cm, mass U(0.05, 0.5) kg, dropped from 9 cm (+-8 cm) above the palm
    surface, +-1 cm sideways (drawn each episode)
reset:
    the wrist turned palm up (rotation -80 deg); 50 physics steps without gravity and without the
    ball settle the hand (the rotation ends near -73 deg, the palm's normal 6 deg off vertical);
    then the muscles are set to hold the hand there against gravity (activations and controls: the
    agonists' static activations, 0 to 2.5 % here, see
    :func:`~mimo_social.partners.base.torque_controls`; the learner's first action then keeps or
    changes them); then the ball is placed, at rest
action:
    40 muscle controls in [0, 1]: a negative and a positive muscle for each of the right wrist's 3
    axes and the 17 finger joints other than the thumb's (with `actuation="spring_damper"`: 20
    motors in [-1, 1])
observation:
    `proprioception` (196, the muscles' activations included), `touch` (1702: the right arm's and
    hand's skin only, at the published spacing; the normal force only, 1 float a point), `ball_size`
    (1: radius, m)
reward:
    `-100` (`failure_reward`) when the ball falls more than 10 cm below the palm centre or goes more
    than 0.5 m from it; on success `+100 + 1 x` the steps left (this one included; `success_reward`,
    `contact_reward`, `pay_remaining`); otherwise `1 - c_w(a)`: `contact_reward` (1) while any part
    of the infant touches the ball, 0 when none does, minus the weighted muscle cost (paper eq. for
    muscles; `cost_weight` 1)
success:
    the right hand has touched the ball for 1 s (100 steps) without a break (`is_success`)
termination:
    on success (held 1 s) or failure (dropped); truncation at 800 steps; `env.dt` 0.01 s (2 physics
    steps of 5 ms)
infos:
    `is_success`, `dropped`, `parts_touching` (the paper's N_c: the infant's body parts touching the
    ball), `held_steps`, `ball_radius`, `ball_mass`
privileged cues:
    the task points the head and eyes at the ball every control step (its position reaches the
    learner as its own head and eye angles); `ball_size` gives the ball's radius directly
differences from the paper:
    (1) the paper's text pays `N_c`, the number of primitives touching the ball, each step; the
    published code pays +1 a step in contact: we pay +1 (the code), because `N_c` made holding
    without finishing the optimum (summed `N_c` of the controller holding the ball a whole episode
    without the success: 3,675, against 447 + 100 for its catches; seeds 0-19). (2) the paper pays
    +100 on success; we add what the best continuation could still collect (1 a step left), so
    succeeding beats every non-catching continuation by 100 minus the muscle cost (at most 0.025 a
    step) -- without it, holding the ball all episode without finishing (782, below) beats a catch
    (202); `pay_remaining=False` gives the paper's +100, under which holding pays more than
    catching (782 +- 8 against 202 +- 4, seeds 0-19: a learner would learn to hold): choosing it
    raises a `UserWarning` that says so (`task.PAPER_REWARD_WARNING`). (3) the paper does not say
    how the episode
    starts; at zero activation the wrist sags (39 deg in 0.6 s, `wrist_after` in the tests) and the
    ball rolls off before a finger can close, so the episode starts with the muscles holding the
    hand (the reset row). (4) the published code's starting wrist angle is not recorded: we turn the
    wrist until the palm faces up
baselines:
    seeds 0-19, the policies of `tests/tasks/test_catch.py` (`pytest tests/tasks/test_catch.py -m
    'slow or not slow'`, ~15 s): the scripted
    :class:`~mimo_social.tasks.catch.controller.CatchController` (a cupped palm held by PD through
    the muscles, fingers closing on touch) succeeds in 20 of 20, return 882 +- 8 (seeds 0-99: 99 of
    100); with actuation="spring_damper" the controller catches 7 of 10 (seeds 0-9); uniform random
    controls each step 0 of 20, return -82 (0 of 100); smooth random actions (`core.random_actions`,
    seeds 2000-2019) 1 of 20, -30; zero action 0 of 20, -92 (0 of 100); keeping the start controls 0
    of 20, -86 (0 of 100: they hold the empty hand within 2.4 deg for 0.5 s, but are too soft for a
    falling ball); holding the ball all episode without the success (the controller with `hold_time`
    9 s) 782 +- 8; the controller under the paper's +100 alone (`pay_remaining=False`) 202 +- 4
    (seeds 0-19, measured again in issue 30 with `tests/tasks/test_catch.py`'s `run`: 20 of 20
    caught; the hold 0 of 20).
    `mimo-social baselines catch --episodes 30 --seed 1000 --run <6 runs>` (seeds 1000-1029;
    docs/baselines.md): scripted 97 % (29/30), 849 +- 168, 125 steps to success; random 0 %, -83;
    zero 0 %, -92; PPO (SB3 defaults, 100k steps, 3 seeds) 13 / 0 / 0 %, return 71 / -49 / -42; SAC
    (10k steps, 3 seeds) 0 / 0 / 3 %, -64 / -86 / -39
sources:
    the MIMo paper (Mattern et al.), Sec. VI-A: the catching demo; the published task's settings
    (`mimo-figures.md`, MIMoCatch-v0)
version history:
    v0: first version, with the paper's other one-agent demos (stand up, self-body touch); v0, issue
    14: reward +1 a step in contact (not `N_c`), success pays the steps left, the episode starts
    with the muscles holding the hand, scripted controller; v0, issue 30: `pay_remaining=False`
    warns that holding pays more than catching

`c_w(a) = sum(a_i^2 fmax_i) / (N sum fmax_i)` is at most `1/N` = 0.025 here; the published code
scaled it by 40 (`task_options={"cost_weight": 40}`). Succeeding is the return optimum while
`cost_weight x 0.025 x 800 < success_reward`, i.e. `cost_weight` < 5.

``parallel_env(task_options={...}, physics={...}, max_steps=..., render_mode=...,
**agent_settings)`` returns a :class:`~mimo_social.core.env.MimoParallelEnv` with the one agent
``infant_0``; ``env(...)`` the AEC version. The Gymnasium id is ``mimo_social/Catch-v0``.
"""

from .task import (parallel_env, env, Catch, CatchOptions)
from .controller import CatchController, palm_cup_angles

__all__ = ["parallel_env", "env", "Catch", "CatchController", "palm_cup_angles", "CatchOptions"]
