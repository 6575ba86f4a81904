"""High five: two standing infants, face to face, bring their right hands together and feel it.

agents:
    2 (`infant_0`, `infant_1`), `distance` (0.35 m) apart hip to hip, facing each other
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
    both right hands feel the partner: each agent's right-hand skin (hand or fingers) senses a force
    whose source is the other agent, and the two right hands are in contact with each other. The
    partner's forearm, body or left hand on one's hand does not count (the partner's right hand
    feels nothing), nor do crossed arms (each right hand on the other's arm)
termination:
    both, on success (if `end_on_touch`, default); truncation at `max_steps` (500 steps, 5 s)
infos:
    `is_success`, `hands_touching` (the same, kept for older code), `hand_feels_partner` (this
    agent's right-hand skin senses the other agent, on any of its parts), `hand_distance` (m), and
    the skin's `touch` (who touches which part)
options:
    `touch_bonus` (100.0), `end_on_touch` (True), `distance` (0.35 m, 0.25 to 0.6), `start_spread`
    (0.3, 0 to 1; 0: the same start every episode), `assisted_gaze` (False), `shaping` (True)
scripted partner:
    `high_five_v0.scripted_env()`: `infant_1` is a `HandOffer` (holds its right hand out, fingers
    open: `HandOffer(grip=False, release=None)`, palm up; `palm="forward"` for a palm facing the
    learner). The learner's scripted solution: `HighFiveController`
    (`mimo_social.tasks.high_five.controller`): reads the partner's palm from the world every 50 ms,
    solves the arm posture that puts its palm there, facing forward (its fingertips where the palm
    cannot reach), PD + gravity compensation through its own motors
privileged cues:
    `assisted_gaze` (False): the task points head and eyes at the partner's right hand every control
    step, so the hand's position reaches the learner as its own head and eye angles
    (proprioception): off by default, since it leaks the partner's state. With it off the learner's
    observations do not change when only the partner's hand posture changes, until the hands touch
    (tested). The contact reaches the learner only through its skin
baselines:
    20 episodes, seeds 1000-1019, `scripted_env()` (partner `HandOffer`, palm up;
    `docs/social/high_five.md` gives the script): random (uniform actions) 1 / 20 successes, return
    -139.9 +- 46.6; zero action 0 / 20, -136.5 +- 5.0; scripted `HighFiveController` 20 / 20, 90.0
    +- 2.6, 38.2 steps to the high five; hacks: `ArmSweep` (sweeps the arm across the front, blind)
    20 / 20 but less return, 64.9 +- 0.9 (120 steps), a hand held still at the midpoint between the
    infants (a `HandOffer` as the learner) 0 / 20, -63.5 +- 1.0. Partner palm forward
    (`HandOffer(grip=False, release=None, palm="forward")`): random 0 / 20, -158.4 +- 11.2; zero 0 /
    20, -143.2 +- 5.1; scripted 20 / 20, 88.6 +- 4.2, 48.8 steps; `ArmSweep` 0 / 20, -127.5 +- 0.9;
    midpoint 0 / 20, -74.8 +- 0.9. PPO (SB3 defaults, 2 seeds each; deterministic evaluation, 10
    episodes every 10k env steps): scripted partner, 60k env steps (7-9 min): seed 0 80 % at 20k, 90
    % at 61k; seed 1 0 % until 30k, 80 % at 61k; on 20 fresh episodes (seeds 1000-1019) 20 / 20
    (return 94.0 +- 0.8, 23 steps) and 19 / 20 (85.5 +- 38.5, 20 steps): the scripted level
    (`mimo-social compare --task high_five --mode scripted --algos ppo --seeds 2 --steps 60000 --out
    runs/high_five15_scripted --eval-every 10000 --eval-episodes 10`, then `mimo-social baselines
    high_five --episodes 20 --seed 1000 --run runs/high_five15_scripted/ppo_seed0
    runs/high_five15_scripted/ppo_seed1`). Shared-parameter PPO, two learners, 50k env steps (5-10
    min): seed 0 100 % at 51k, seed 1 100 % from 30k; 20 fresh episodes: 100 % for both infants,
    return 93.4 +- 1.0 (23 steps) and 90.1 +- 4.1 (78 steps) (`mimo-social compare --task high_five
    --mode shared --algos ppo --seeds 2 --steps 50000 --out runs/high_five15_shared --eval-every
    10000 --eval-episodes 10`, then `mimo-social eval runs/high_five15_shared/ppo_seed0 --episodes
    20 --seed 1000`): the two learners agree on a meeting point without the cue; the first version
    with it reached 100 % from 60k env steps (seed 0)
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
    `HandOffer` holds its palm where the infant reaches; two 18-month-olds unchanged

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
from .controller import ArmSweep, HighFiveController

__all__ = ["parallel_env", "env", "scripted_env", "default_partner", "HighFive", "hand_touch",
           "ArmSweep", "HighFiveController", "HighFiveOptions"]
