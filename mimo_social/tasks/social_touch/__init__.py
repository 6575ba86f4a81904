"""Social touch: a sitting infant touches a named part of its partner's body, who feels it.

agents:
    2: the toucher `infant_0` and the touched infant `infant_1` (an adult is `caregiver_0`), sitting
    cross-legged face to face, `distance` (0.37 m; 0.35 to 0.40) apart hip to hip: sitting infants
    at play, arms' length and a lean apart; exactly two (a third raises an error)
body:
    hips fixed on the floor, legs crossed, knees bent to -145 deg (the crossed feet of the two stay
    apart); the toucher: everything but the right arm and the eyes held, the trunk bent forward
    towards the partner as far as it goes (lower trunk 30.5 deg, the upper trunk coupled: 61 deg),
    the head tilted back (-60 deg) to face the partner, the left arm hanging at its side; the
    touched infant: everything but both arms and the eyes held, leaning back a little (6 deg); the
    heads stay 11 cm apart (9 cm at 0.35 m, 14 cm at 0.40 m)
scene:
    the floor only: the target is a part of the partner's body
reset:
    each episode starts from its own seeded draw (`reset(seed=...)`, the env's generator): the
    distance, `distance` + U(-1, 1) x `distance_spread` (0.02 m), within 0.35-0.40 m (other bodies
    shifted by as much: the touched infant's hip is moved along the line between the two); the
    toucher's right arm (its motors' joints: 8 with mitten hands) at its start posture (out to its
    side, elbow a little bent) plus U(-1/2, 1/2) x `start_spread` (0.2) x each joint's range; the
    touched infant's arms (16 joints with mitten hands; its hands resting on its legs) plus U(-1/2,
    1/2) x `partner_spread` (0.1) x each range; drawn again (up to 50 times) until the toucher's arm
    touches nothing and the two infants do not touch. 100 seeds give 100 distinct starts (tested;
    the first versions had one start posture, 6 distinct episodes over 60 seeds); all spreads 0: the
    first versions' start. The target part is drawn uniformly from `targets` (task option `target`
    fixes it); the same seed, the same start
action:
    `infant_0`: the right arm's motors (mitten hands: 8, shoulder 3, elbow, wrist 3, fingers; five
    fingers: 29) in [-1, 1]; `infant_1`: both arms' motors (16; 58), zero in the scripted env
    (`Still` partner); expressions off by default (`expressions=True` adds them)
observation:
    both: `proprioception` (toucher 72, touched infant 120), `touch` (normal force only, 1 float a
    point): the toucher's skin covers its right arm (upper arm to fingertips, a tenth of the
    published point density: 242 floats), the touched infant's its whole body (a quarter of the
    density: 1400); the toucher also gets `target`, one-hot over `targets` (6 by default): the
    instruction, not the target's location. With `assisted_gaze` off (default) nothing else depends
    on the target: changing `target` with everything else fixed changes only that one-hot (tested)
reward (both):
    shaping (`shaping`, default on): `-distance(toucher's right fingertips, target part's centre of
    mass)` (m) per step; `+success_reward` (100) on success; a wrong first touch (`end_on_touch`):
    the rest of the episode's shaping charged at once (`-distance x steps left`), so ending early
    saves nothing. The best return: touch the target first, as early as possible
success (`is_success`):
    decided by the FIRST contact between the toucher's right arm (upper arm to fingertips) and the
    partner: a success when it includes the toucher's hand on the target part (a hand target
    includes its fingers), not with the back of the hand (the contact normal within 120 deg of the
    palm's normal: palm, finger pads, fingertips and edges count); any other first contact (another
    part, the forearm, the back of the hand) is a wrong touch and the attempt is over without the
    bonus; parts touched in the same 10 ms step as the target (a hand resting on a thigh) do not
    spoil it; `is_success` stays true for the rest of the episode
termination:
    both, when the first contact decides the attempt (success or wrong touch; `end_on_touch`,
    default); truncation at `max_steps` (500 steps, 5 s)
infos (both):
    `target_part`, `is_success`, `wrong_touch`, `first_touch` (the partner's parts touched at the
    deciding contact; None before), `touched_parts` (the partner's parts the toucher's right arm
    touches this step), `target_felt` (the touched infant's skin feels the toucher's hand on the
    target), `fingertip_distance` (m), and each agent's own skin record `touch`
options:
    `targets` (None: :data:`DEFAULT_TARGETS`, 6 parts, those of them in the partner's body; only
    parts of :data:`REACHABLE`, the 6 and the left thigh: others raise an error), `target` (None),
    `success_reward` (100.0), `end_on_touch` (True), `distance` (0.37 m, 0.35 to 0.40), `shaping`
    (True), `assisted_gaze` (False), `start_spread` (0.2, 0 to 1: the toucher's arm at the start,
    a fraction of each joint's range), `partner_spread` (0.1, 0 to 1: the touched infant's arms),
    `distance_spread` (0.02 m, 0 to 0.05: the episode's distance either way of `distance`, within
    0.35-0.40 m); all three 0: the first versions' fixed start
privileged cues:
    `target` one-hot (always: the instruction, the task's "name" of the part; it does not say where
    the part is); `assisted_gaze` (default False): the task aims the toucher's eyes at the target
    part every step (its eye angles then tell where the target is) and the touched infant's at the
    toucher's right palm; off, each looks at the other's face (eye angles set once per reset, the
    same for every target); the touch itself only through the skins
baselines:
    issue 30 (random starts), scripted env, `Still` partner, 30 episodes, seeds 1000-1029:
    `SocialTouchController` (`mimo_social.tasks.social_touch.controller`) 29 / 30, return 77.9 +-
    39.3, 121 steps to success; random 1 / 30, -94.2 +- 32.4; zero 0 / 30, -190.7 +- 33.8
    (`mimo-social baselines social_touch --episodes 30 --seed 1000`); seeds 0-99: scripted 99 / 100,
    83.7 +- 16.5, 114 steps; random (uniform) 4 / 100, -91.4 +- 40.3; zero 0 / 100, -192.4 +- 34.9;
    hacks (seeds 1000-1029): `NearestPartToucher` (the listed part nearest its hand, whatever the
    target) 5 / 30, -54.5 +- 66.3; `ArmSweep` (the arm swung across in front of the partner) 0 / 30,
    -100.3 +- 31.0 (the script: `docs/social/social_touch.md`). Issue 15 (the fixed start), seeds
    1000-1019: scripted 20 / 20, 82.6 +- 7.1, 132 steps; random 0 / 20, -98.7 +- 26.0; zero 0 / 20,
    -194.8 +- 28.0; `NearestPartToucher` 3 / 20, -65.7 +- 67.9; `ArmSweep` 0 / 20, -105.4 +- 34.6;
    PPO (2 seeds, 400k env steps, 24 min, the fixed start; not yet measured with the random starts):
    0 / 20, -74.3 +- 7.6 and 2 / 20, -71.5 +- 58.6: above random in return, barely in success, far
    from the scripted level (`mimo-social compare --task social_touch --mode scripted --algos ppo
    --seeds 2 --steps 400000 --out runs/social_touch15 --eval-every 25000 --eval-episodes 10 --jobs
    2`, then `mimo-social baselines social_touch --episodes 20 --seed 1000 --run
    runs/social_touch15/ppo_seed0 runs/social_touch15/ppo_seed1`; details
    `docs/social/social_touch.md`). With the random starts, the shipped recipe (issue 30: a
    warm start from the scripted toucher with DAgger, the critic fitted and the cloning kept up,
    then PPO, 600k steps; `mimo-social recipe social_touch --seeds 0,1 --jobs 2 --out
    runs/recipes/social_touch`), seeds 1000-1029: 15 / 30 and 17 / 30 (mean action), 14 / 30 and
    18 / 30 (sampled); the blind toucher's clone of the scripted one reaches 20-34 % on its own
    episodes (docs/baselines.md, "Recipes")
sources:
    not in the MIMo paper: a social task of this package, the social version of self-body touch
    (paper Sec. VI-A); rationale (touch, body-part games), distances and figures:
    `docs/social/social_touch.md`
version history:
    v0: first version, with the skin-sensed high five; v0, issue 15: success = the first touch is
    the hand (not its back) on the target, a wrong first touch ends the attempt without the bonus
    (and is charged the rest of the shaping); 0.37 m apart (0.35-0.40; was 0.28), the toucher
    leaning in as far as its trunk bends; targets only parts reachable over that range, checked by
    IK (the head and the mitten's fingers dropped, a hand includes its fingers, the left thigh only
    on request); the task-aimed gaze is the `assisted_gaze` option, off by default (each looks at
    the other's face); `shaping` option; the scripted toucher `SocialTouchController` and two hack
    policies; v0, issue 18: partners of other bodies (`tasks/dyad.py`, docs/bodies.md): the floor
    between the two kept as for two 18-month-olds, each in its own posture, the partner's head
    turned to the toucher's face; an adult partner offers the parts the toucher reaches
    (`ADULT_REACHABLE`: kneeling, its left forearm, hand and thigh); two 18-month-olds unchanged;
    v0, issue 30: start randomness: the distance (`distance_spread`, 0.02 m), the toucher's arm
    posture (`start_spread`, 0.2) and the touched infant's arms (`partner_spread`, 0.1), seeded,
    touching nothing (the first versions: one start posture, only the target drawn)

Targets by default are the partner's parts within reach of the toucher's right hand over the whole
distance range: upper and lower trunk, the partner's left arm (upper arm, lower arm, hand with its
fingers: it is on the toucher's right) and left shin. For each, and for the left thigh, a posture of
the right arm (found by inverse kinematics,
:func:`~mimo_social.tasks.social_touch.controller.reach_posture`) puts the hand into the part,
touching nothing else of the partner, at 0.35, 0.37 and 0.40 m (tested). The thigh is where a
dropped arm lands (random actions touch it first, palm side, in a third of the episodes): it is a
target only on request. The head is out of reach at 0.40 m; the far side and the feet are not
offered. The toucher's trunk is held bent forward: free, with zero command, it sags forward under
gravity until the heads meet.

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns a
:class:`~mimo_social.core.env.MimoParallelEnv` with the toucher ``infant_0`` and the touched infant
``infant_1`` (both learners); ``env(...)`` the AEC version; ``scripted_env(partner=None, **kwargs)``
a one-learner env in which ``infant_0`` learns to touch and ``infant_1`` is driven by a scripted
:class:`~mimo_social.partners.Partner` (default :class:`~mimo_social.partners.Still`: it sits still
and feels).

The toucher's skin covers its right arm by default, the touched infant's its whole body;
``touch=...`` (all agents) or ``per_agent=[{...}, {"touch": ...}]`` change that, as long as the
toucher's right hand and the touched infant's target parts keep their skin.
"""

from .task import (parallel_env, env, scripted_env, SocialTouch, DEFAULT_TARGETS,
                   SocialTouchOptions)
from .controller import (BACK_COS, SIDES, VARIANTS, ArmSweep, NearestPartToucher,
                         SocialTouchController, first_touch, hand_posture, reach_posture,
                         side_normal, surface_point)

__all__ = ["parallel_env", "env", "scripted_env", "SocialTouch", "DEFAULT_TARGETS", "BACK_COS",
           "SIDES", "VARIANTS", "ArmSweep", "NearestPartToucher", "SocialTouchController",
           "first_touch", "hand_posture", "reach_posture", "side_normal", "surface_point",
           "SocialTouchOptions"]
