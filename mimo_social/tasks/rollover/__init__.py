"""Roll over: an infant on the floor rolls from its back to its belly, or the other way round.

agents:
    1 (`infant_0`), mitten hands, spring-damper motors; the body of a 6-month-old (`age_months=6`,
    the task's default: infants roll both ways by about 6 months, see sources; `age_months=...`
    sets another age: every figure here is for 6 months, and the controller's docstring gives a
    few at 4 and 8 months and with five-fingered hands)
body:
    free base on the bare floor; eyes, fingers, toes and the ankles' inversion and rotation held at
    their rest angles
scene:
    the bare floor, nothing else
reset:
    lying on the back (option `start="supine"`, the default) or on the belly (`start="prone"`: the
    lying posture turned half a turn about the body's long axis), turned about the vertical by a
    yaw drawn from U(-180, 180) degrees (option `yaw_range`); every motor joint gets U(-0.05, 0.05)
    rad (option `perturbation`); the body is lowered until its lowest part is 2 mm above the floor,
    then 100 physics steps with zero controls settle it (option `settle_steps`) before the first
    observation. Measured over seeds 0-99: the chest settles within 5 degrees of facing straight up
    (from the back) and within 9 of facing straight down (from the belly); no two seeds start alike
physics:
    two physics steps of 5 ms per control step (`frame_skip=2`, control step 10 ms); an episode is
    600 steps, 6 s
action:
    30 motors in [-1, 1]: trunk 3 (lean, twist, bend), head 3 (swivel, tilt, side tilt), each arm 7
    (shoulder 3, elbow, wrist 3), each leg 5 (hip 3, knee, ankle flexion)
observation:
    `proprioception` (208: joint angles, velocities, torques, limit sensors, motor state),
    `vestibular` (6: head gyro, accelerometer); touch on with `touch=True`
reward:
    `turn / 180 + [turn >= 135] - 0.001 * sum(u_i^2)` per step: `turn` is how far (degrees, 0 to
    180) the chest has turned from its start, the angle between the chest's forward axis (the upper
    trunk's x axis) and the world's up (from the back) or down (from the belly); 1 more for every
    step with the chest turned 135 degrees or more (option `over_bonus`: 1; the angle is
    `success_angle`); minus the control cost over the 30 motors (option `cost_weight`: 0.001)
success:
    `is_success`: the chest turned 135 degrees or more (option `success_angle`) for the last 1 s
    without a break (option `success_hold`): on the belly (or back), not on the side, and staying
    there
return optimum:
    the reward grows with the turn at every step and almost doubles once the chest is past 135
    degrees, so the sooner the infant is over and the longer it stays there, the higher the return:
    a policy never past 135 degrees earns less than 0.75 a step (450 an episode, held just short of
    the angle from the first step), lying on the side at most 0.5 (300), while the scripted
    controller earns 872 (from the back) and 773 (from the belly); rolling half way and falling
    back, or flailing, scores far less (baselines)
termination:
    none (a fixed 600 steps, then truncation); a simulation that goes unstable ends the episode
infos:
    `turn_angle` (deg), `is_success`, `control_cost`
privileged cues:
    none
baselines:
    30 seeded episodes per policy and start (seeds 1000-1029; `python tests/tasks/test_rollover.py
    30 1000`; random: uniform in [-1, 1], seeded per episode). From the back: scripted
    `RollOverController` (`mimo_social.tasks.rollover.controller`) 100 % (30/30), return 872.4 +-
    5.6, over (and held 1 s) after 271 steps, the chest at 176 degrees at the end; zero action 0 %,
    return 5.3; random 0 %, 6.8; hacks: bang-bang (every motor at +-1, signs redrawn every 0.25 s)
    0 %, return 99.9 +- 137.3; half roll (the controller until the chest has turned 60 degrees, then
    rest: it falls back) 0 %, 187.8 +- 103.7. From the belly: scripted 100 % (30/30), return 772.5
    +- 8.5, over after 326 steps, 173 degrees at the end; zero 0 %, 10.1; random 0 %, 7.3;
    bang-bang 13 % (4/30), 271.6 +- 267.3; half roll 0 %, 103.0 +- 9.9. `mimo-social baselines
    rollover --episodes 30 --seed 1000` (from the belly: add `--env-kwargs '{"task_options":
    {"start": "prone"}}'`; docs/baselines.md) gives the same scripted, zero and random figures.
    Learner (recipe `rollover`, PPO with SB3's defaults, 1M steps from the back, seeds 0 and 1,
    the same 30 episodes; `mimo-social recipe rollover --seeds 0,1`): seed 0 100 % with the mean
    action (return 952.7), 93 % sampled; seed 1 0 % / 0 % (return 149.4: stuck with the chest
    about 45 degrees over); 18-20 min a seed (docs/training/issue30/recipes/rollover_ppo_1M).
    The recipe now warm-starts PPO from the scripted roll (cloning and DAgger, the cloning kept
    up over 300k steps): its best evaluated models roll over in 100 % of the 30 episodes in both
    seeds, mean action and sampled; the final models 57 % / 90 % and 100 % / 100 %
    (docs/training/issue30/recipes/rollover)
sources:
    rolling emerges at about 3 to 6 months, from the belly to the back first (about 3-5 months)
    and from the back to the belly a month or two later (about 5-7 months): the Alberta Infant Motor
    Scale (Piper & Darrah), whose prone and supine items include rolling prone to supine and supine
    to prone (its age norms re-checked by Darrah et al. 2014, Dev. Med. Child Neurol.
    56(9):877-881, doi 10.1111/dmcn.12452); a pediatric neurological examination's 3-month prone
    item ("rolling front to back usually occurs at 3 to 5 months of age"; a video at kaltura.com,
    entry 0_795q4f4q); parents' guides (front to back at 4 to 6 months, back to front at 5 to 7).
    6 months is the youngest age at which both directions are usual, hence the default body. The
    task is named after the published MIMo v3 suite's `MIMoRollOver-v0`; nothing was taken from
    it: every constant here is this task's own and every figure is measured here
version history:
    v0, issue 32: first version, both starts (`mimo_social/RollOver-v0`: from the back,
    `mimo_social/RollOverProne-v0`: from the belly), scripted controller

``parallel_env(task_options={...}, physics={...}, max_steps=..., render_mode=...,
**agent_settings)`` returns a :class:`~mimo_social.core.env.MimoParallelEnv` with the one agent
``infant_0``; ``env(...)`` the AEC version. The Gymnasium ids are ``mimo_social/RollOver-v0``
(from the back) and ``mimo_social/RollOverProne-v0`` (from the belly: ``task_options={"start":
"prone"}``).
"""

from .task import (parallel_env, env, RollOver, RollOverOptions, ROLL_JOINTS, STARTS, turn_angle)
from .controller import PRONE_PLAN, SUPINE_PLAN, RollOverController

__all__ = ["parallel_env", "env", "RollOver", "RollOverController", "RollOverOptions",
           "ROLL_JOINTS", "STARTS", "PRONE_PLAN", "SUPINE_PLAN", "turn_angle"]
