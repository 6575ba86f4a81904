"""High five: two standing infants, face to face, bring their right hands together and feel it.

agents:
    2 (`infant_0`, `infant_1`; an adult partner is `caregiver_0`), `distance` (0.35 m) apart hip to
    hip, facing each other
body:
    standing, hip fixed in the world; trunk, legs, left arm held; head and eyes held at rest,
    looking straight ahead at the partner (no gaze joint in the model). With `assisted_gaze` (the
    first version) head and eyes are joints the task points at the partner's right hand every
    control step
scene:
    the floor only: each infant's target is the partner's hand
reset:
    each right arm starts in its own random posture: every joint at its standing-pose angle plus
    U(-1/2, 1/2) x `start_spread` (0.3) x its range, resampled until the hands touch nothing (seeded
    by `reset(seed=...)`)
action:
    the right-arm motors (mitten hands: 8, shoulder 3, elbow, wrist 3, fingers; five fingers: 29),
    plus the expression (`Discrete(7)`) while expressions are on (default)
observation:
    `proprioception` (48 for the mitten body: the right arm's joints and motors; 84 with
    `assisted_gaze`, whose head and eye angles tell where the partner's hand is), `vestibular` (6),
    `touch`: the skin of the right hand only by default (hand and fingers, a tenth of the published
    point density, normal force only: 232 floats for the mitten hand); `touch=True` or a mapping
    gives more skin. Nothing of the partner before its hand touches the skin: the learner finds the
    meeting point by the shaped reward
reward (both):
    with `shaping` (default): `-distance(right palms)` (m) per step (the reward reads the world; it
    is no observation); `+touch_bonus` (100) on a step of success
success (`is_success`):
    `success="palms"` (default, issue 30): the palms meet, palm side to palm side, and stay
    together `hold_time` (0.1 s: 10 control steps in a row): each step the two right hands are in
    contact, both right-hand skins feel the other agent, and one contact between the hands has its
    normal, from each hand into the other, within 60 deg of that hand's palm normal (the palm and
    the finger pads count; the back of the hand, its edges and the fingertips' ends do not); a
    step without it starts the count again. `success="touch"` (the first versions' rule): any
    contact of the two right hands that both skins feel, one step, any side of the hand. Neither
    counts the partner's forearm, body or left hand on one's hand (the partner's right hand feels
    nothing), nor crossed arms (each right hand on the other's arm). Why: under the first rule
    random bang-bang actions (each motor at a bound, the side drawn every step or held 5 or 20
    steps) met the partner's hand in 5 / 30, 20 / 30 and 20 / 30 episodes (the first versions'
    partner) and 15, 25 and 27 / 30 (the default partner): brief slaps (1 step, up to 13 held),
    at 0.4-5 m/s (the scripted hand: 0.03-0.6 m/s), with any part, the palms mostly facing the
    same way (the back of one hand on the other); palm side to palm side those flails never lasted
    5 steps
termination:
    both, on success (if `end_on_touch`, default); truncation at `max_steps` (500 steps, 5 s)
infos:
    `is_success`, `hands_touching` (the same, kept for older code), `hand_feels_partner` (this
    agent's right-hand skin senses the other agent, on any of its parts), `hand_distance` (m),
    `palm_contact` (the palms meet this step, palm side to palm side), `palm_contact_time` (s:
    how long they have, in a row), and the skin's `touch` (who touches which part)
options:
    `touch_bonus` (100.0), `end_on_touch` (True), `distance` (0.35 m, 0.25 to 0.4 with
    `success="palms"`, to 0.6 with `"touch"`: farther apart the palms do not meet, the scripted high
    five 10 / 10 at 0.25-0.4 m, 3 / 10 at 0.45 m, 0 / 10 at 0.5 m), `start_spread` (0.3, 0 to 1;
    0: the same start every episode), `assisted_gaze` (False), `shaping` (True), `success`
    (`"palms"`; `"touch"`: the first versions' rule), `hold_time` (0.1 s, 0 to 1: how long the
    palms stay together; 0: one step)
scripted partner:
    `high_five_v0.scripted_env()`: `infant_1` is a `HandOffer` that holds its right hand out, palm
    up, fingers open, at the midline between the infants (`HandOffer(grip=False, release=None,
    reach_to=OFFER_AT)`, `OFFER_AT` = 0.195 m forward, 0.105 m left, 0.06 m down from the learner's
    right shoulder, scaled with its arm; `palm="forward"` for a palm facing the learner; the first
    versions' partner, `HandOffer(grip=False, release=None)`, holds it 15 cm to the learner's left,
    where a palm facing down reaches it with the finger pads only). The learner's scripted
    solution: `HighFiveController` (`mimo_social.tasks.high_five.controller`): reads the partner's
    palm from the world every 50 ms; holds its hand ready in front of its shoulder until that palm
    is still, then brings its palm over it, facing it, 4 cm off, then in along its normal, its
    finger pads on the partner's palm (its fingertips on the partner's fingers where that is out of
    reach), pressing 2 cm; IK on a scratch copy, PD + gravity compensation through its own motors
    (`palm="forward"`: the first versions' controller). A flailing policy, for baselines:
    `BangBang(hold)`
privileged cues:
    `assisted_gaze` (False): the task points head and eyes at the partner's right hand every control
    step, so the hand's position reaches the learner as its own head and eye angles
    (proprioception): off by default, since it leaks the partner's state. With it off the learner's
    observations do not change when only the partner's hand posture changes, until the hands touch
    (tested). The contact reaches the learner only through its skin
baselines:
    issue 30, 30 episodes, seeds 1000-1029, `scripted_env()` (the default partner, palm up at the
    midline), success = palms held 0.1 s: random (uniform actions) 0 / 30, return -131.5 +- 12.1;
    zero action 0 / 30, -131.2 +- 5.0; scripted `HighFiveController` 30 / 30, 78.7 +- 2.6, 117 steps
    to the high five (`mimo-social baselines high_five --episodes 30 --seed 1000`); random bang-bang
    (`BangBang`, every step / held 5 / held 20 steps) 0 / 30, -132.8 +- 10.1; 1 / 30, -119.0 +-
    37.7; 1 / 30, -117.5 +- 23.9; hacks: `ArmSweep` (sweeps the arm across the front, blind) 0 / 30,
    -96.9 +- 1.1; a hand held still at the midpoint between the infants (a `HandOffer` as the
    learner) 0 / 30, -36.2 +- 1.3 (the script: `docs/social/high_five.md`). Partner palm forward
    (`HandOffer(grip=False, release=None, palm="forward", reach_to=OFFER_AT)`): random 0 / 30,
    -135.9 +- 11.9; zero 0 / 30, -134.0 +- 5.0; scripted 30 / 30, 76.6 +- 3.2, 125 steps; bang-bang
    0 / 30 each (-136.0, -129.9, -123.9); `ArmSweep` 11 / 30, -39.5 +- 80.0; midpoint 0 / 30, -38.9
    +- 1.4. The first versions' partner (`HandOffer(grip=False, release=None)`): scripted 30 / 30,
    72.7 +- 2.8, 139 steps; random, zero, `ArmSweep`, midpoint 0 / 30; bang-bang 0, 0, 1 / 30. With
    `success="touch"` and the default partner: scripted 30 / 30, random 5 / 30, bang-bang 15, 25, 27
    / 30. Under the palm rule, the shipped recipe (`mimo-social recipe high_five --seeds 0,1`: a
    behaviour-cloning warm start from 100 scripted episodes, then PPO with its learning rate
    decaying to 0 over 600k steps, partner scripted; issue 30): seeds 0 and 1, 30 episodes (seeds
    1000-1029), 100 % / 100 % and 97 % / 93 % (mean action / sampled), return 91.6 and 86.9, 18-24
    min a seed (docs/baselines.md); PPO without the warm start: 20 % at 100k steps (seed 0).
    Issue 15, the first versions' rule and partner, 20 episodes, seeds 1000-1019: random 1 /
    20, -139.9 +- 46.6; zero 0 / 20; scripted 20 / 20, 90.0 +- 2.6, 38 steps; `ArmSweep` 20 / 20,
    64.9 +- 0.9; PPO (the first rule; SB3 defaults, 2 seeds each; deterministic
    evaluation, 10 episodes every 10k env steps): scripted partner, 60k env steps (7-9 min): seed 0
    80 % at 20k, 90 % at 61k; seed 1 0 % until 30k, 80 % at 61k; on 20 fresh episodes (seeds
    1000-1019) 20 / 20 (return 94.0 +- 0.8, 23 steps) and 19 / 20 (85.5 +- 38.5, 20 steps): the
    scripted level (`mimo-social compare --task high_five --mode scripted --algos ppo --seeds 2
    --steps 60000 --out runs/high_five15_scripted --eval-every 10000 --eval-episodes 10`, then
    `mimo-social baselines high_five --episodes 20 --seed 1000 --run
    runs/high_five15_scripted/ppo_seed0 runs/high_five15_scripted/ppo_seed1`). Shared-parameter PPO,
    two learners, 50k env steps (5-10 min): seed 0 100 % at 51k, seed 1 100 % from 30k; 20 fresh
    episodes: 100 % for both infants, return 93.4 +- 1.0 (23 steps) and 90.1 +- 4.1 (78 steps)
    (`mimo-social compare --task high_five --mode shared --algos ppo --seeds 2 --steps 50000 --out
    runs/high_five15_shared --eval-every 10000 --eval-episodes 10`, then `mimo-social eval
    runs/high_five15_shared/ppo_seed0 --episodes 20 --seed 1000`): the two learners agree on a
    meeting point without the cue; the first version with it reached 100 % from 60k env steps (seed
    0)
sources:
    not in the MIMo paper: a social task of this package; rationale (touch games, contingency) and
    figures: `docs/social/high_five.md`
version history:
    v0: first version, with the first env (the infants 0.45 m apart); later in v0: success sensed by
    both right-hand skins, 0.35 m apart, the `HandOffer` scripted partner, seeded random start
    postures (`start_spread`); v0, issue 15: the task no longer aims head and eyes at the partner's
    hand (that is the `assisted_gaze` option, default off: head and eyes held looking ahead,
    proprioception 84 -> 48), `shaping` option (default on), the scripted learner
    `HighFiveController` and the hack `ArmSweep`; v0, issue 18: partners of other bodies
    (`tasks/dyad.py`, docs/bodies.md "As a partner in the social tasks"): placed by their measured
    reach, each in its own posture, held heads and eyes on the partner's face; an adult partner
    (`per_agent=[{}, {"body": "adult", "posture": "kneeling"}]`) kneels leaning 15 deg and its
    `HandOffer` holds its palm where the infant reaches; two 18-month-olds unchanged; v0, issue 30:
    success is the palms meeting palm side to palm side for `hold_time` (0.1 s), random bang-bang
    no longer succeeds (the first rule: `success="touch"`); `distance` up to 0.4 m with it; the
    default partner holds its palm at the midline (`OFFER_AT`; the adult and other bodies too);
    `HighFiveController` meets palm to palm (`palm="partner"`, default; ready, over, in); infos
    `palm_contact`, `palm_contact_time`; the flailing policy `BangBang`

Success is read from the same skin that the agents observe (:mod:`mimo_social.senses.touch`), so
what ends the episode is what both infants perceive. The skin must cover the right hand
(`touch=False`, or an `exclude` that names a right-hand part, raises an error).

``parallel_env(n_agents=..., task_options={...}, physics={...}, per_agent=[...], **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv`; ``env(...)`` the AEC version;
``scripted_env(partner=None, **kwargs)`` a one-learner env (``infant_0`` learns) whose partner
``infant_1`` is driven by a scripted :class:`~mimo_social.partners.Partner` (by default one that
offers its right hand: :func:`default_partner`).

Every agent has the touch sense on its right hand by default (the skin that senses the high five);
``touch=True`` gives the whole skin, ``touch=hand_touch(density=...)`` the right hand at another
density.
"""

from .task import (parallel_env, env, scripted_env, default_partner, HighFive, hand_touch,
                   HighFiveOptions)
from .controller import ArmSweep, BangBang, HighFiveController

__all__ = ["parallel_env", "env", "scripted_env", "default_partner", "HighFive", "hand_touch",
           "ArmSweep", "BangBang", "HighFiveController", "HighFiveOptions"]
