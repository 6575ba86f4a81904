"""Handover: one infant holds out a ball in its right hand, the other takes it into its own.

agents:
    2: `infant_0` the receiver, `infant_1` the giver (scripted: :func:`scripted_giver`, a
    :class:`~mimo_social.partners.HandOffer` with `release="on_hold"`, in `scripted_env`; or a
    learner); standing face to face, `distance` (0.34 m) hip to hip
body:
    five-fingered hands (`hands="five_fingers"` is required), spring-damper motors by default
    (`actuation="muscle"`, for all or per agent, works too); standing, hip fixed in the world;
    trunk, legs, left arm held; each agent's right arm (shoulder 3, elbow, wrist 3, 22 finger
    joints) actuated; head and eyes held at rest looking straight ahead (at the partner's face),
    unless `assisted_gaze`
scene:
    a ball (radius `ball_radius` 3 cm, mass `ball_mass` 30 g)
geometry:
    the offered ball's centre is 20.1 cm from the receiver's right shoulder (15.7 cm ahead, 11.5 cm
    toward the midline, 5 cm lower) and 22.1 cm from the giver's; MIMo's straight arm reaches 22.2
    cm from the shoulder to the palm centre (27.7 cm to the fingertips); the receiving hand of
    :class:`~mimo_social.tasks.handover.controller.ReceiveController` (palm up beside the giver's
    hand) lies 20.2 cm from the shoulder, reached by its inverse kinematics within 1 mm (measured at
    the default options; tests/partners/test_receive.py)
reset:
    the giver's arm is posed in its offer posture
    (:func:`~mimo_social.partners.hand_offer.offer_posture` for `offer_target` = 18 cm ahead of its
    right shoulder, 10 cm toward its midline, 8 cm lower; palm up, leaning slightly toward thumb and
    fingers), the ball laid in its palm, its four fingers curled kinematically until they touch the
    ball; then for `settle_time` (0.3 s) the giver's own motors hold the arm and the fingers grip
    gently (:class:`HandOffer`): the episode starts with a physical grasp at rest, no weld. The
    receiver's right arm starts at a random offset (+-`arm_noise` 10 deg per joint of shoulder,
    elbow, wrist) from its hanging posture
scripted giver:
    :func:`scripted_giver`: holds the ball still in its upturned palm; when the receiver holds an
    open right hand next to its own (palm centres within 8 cm, the receiver's palm facing up within
    45 deg) for 0.3 s, it tips its palm toward its little-finger side (over 0.5 s; it levels it
    again if that hand goes away); it lets go (fingers open, the hand withdraws: 1.9 cm back and 3.7
    cm down) only once the receiver's hand holds the ball: >= 2 of its segments touch it and carry
    >= half its weight (the upward contact force), for 0.2 s. A touch of the back of the hand or a
    poke by one finger does neither (tests/partners/test_hand_offer.py)
scripted receiver:
    :class:`~mimo_social.tasks.handover.controller.ReceiveController` (through its own motors,
    reading the ball's position): holds its hand out open, palm up, beside the giver's, lets the
    ball roll in and closes the fingers gently. With the scripted giver: 19 / 20 successes (seeds
    1000-1019), 20 / 20 (seeds 0-19)
action:
    per agent: the right-arm motors, 29 (spring-damper, in [-1, 1]) or 58 (muscles, in [0, 1]); plus
    the expression when `expressions=True`
observation:
    `proprioception` (174: the agent's own joints; head and eyes are held in the body, at rest; 210
    with `assisted_gaze`, whose head and eye angles the task sets), `touch` (3404: the skin of both
    arms and hands, normal force, 1 float a point); never the partner's joints or the ball's
    coordinates: before contact the receiver's observation does not change with where the ball is
    offered (tested)
reward (both):
    `shaping` (on): `shaping_scale` (10) x the decrease, this step, of the distance from the
    receiver's right palm centre to the ball (progress: it sums to 10 x (start - end distance), so
    hovering earns at most ~2 and leaving gives it back); `+success_reward` (10) on success;
    `failure_reward` (-10) when the ball drops. Holding the ball is the optimum; dropping it is
    worse than never trying (zero action: ~0)
success:
    the ball touches at least `min_parts` (2) segments of the receiver's right hand (palm, finger
    segments), no longer touches the giver's hand and is above `drop_height`, continuously for
    `hold_time` (0.3 s); `is_success` in the last step's info is the episode's outcome
termination:
    both agents, on success (`end_on_success`) or when the ball falls below `drop_height` (0.25 m:
    well below the hands, near the floor); truncation at `max_steps` (600, 6 s)
infos:
    `is_success`, `holder` (`"giver"`: the ball touches the giver's hand; `"receiver"`: the
    receiver's hand in >= `min_parts` segments and not the giver's; `"none"` otherwise), `dropped`,
    `receiver_parts`, `held_steps`, `distance` (receiver's palm centre to the ball, m)
privileged cues:
    `assisted_gaze` (False): when on, the task points the receiver's head and eyes at the ball and
    the giver's at the receiver's right palm every control step (their angles then tell where those
    are: a leak of the ball's position into proprioception); off, head and eyes stay at rest,
    looking straight ahead at the partner. The giver's grip and release reach the receiver only
    through its skin and the ball
two learners:
    `parallel_env()`: both learn, both get the same reward; the giver must hold its own arm up (with
    zero actions it sinks and the ball falls within 0.5 s: a failure for both); nothing makes the
    giver let go but its own fingers
baselines:
    20 episodes each, reset seeds 1000-1019, `scripted_env(scripted_giver())` (the receiver acts):
    scripted `ReceiveController` 19 / 20 successes, return 10.9 +- 4.9, 204 steps (2.0 s) to
    success; zero action 0 / 20, -0.03 +- 0.04; random (uniform) 0 / 20, -1.8 +- 4.2 (3 drops);
    hacks: touch the ball (`ReachController(depth=0.02)`) 0 / 20, 1.4 +- 0.1; hold the hand out and
    leave when the ball comes (`CupAndLeave`) 0 / 20, -9.7 +- 0.2 (20 drops); command: `python -m
    pytest -m slow tests/partners/test_receive.py -s` (prints them). PPO receiver, scripted giver, 2
    seeds, 200k env steps each (SB3 defaults, 22 min): evaluation (10 episodes every 20k) 0 %
    success throughout, return between -10 and +1.3 (it learns to bring the hand to the ball, then
    alternates with knocking it down); the final models on the 20 episodes above: 0 / 20, 0.2 +- 2.9
    and 0 / 20, -2.0 +- 5.3: not above random on success (`mimo-social compare --task handover
    --mode scripted --algos ppo --seeds 2 --steps 200000 --out runs/handover15 --eval-every 20000
    --eval-episodes 10 --jobs 2`, then `mimo-social baselines handover --episodes 20 --seed 1000
    --run runs/handover15/ppo_seed0 runs/handover15/ppo_seed1`)
sources:
    not in the MIMo paper: a social task of this package; rationale (give and take, 9-18 months),
    the release rule and figures: `docs/social/handover.md`
version history:
    v0: first version, with the scripted partner `HandOffer`; v0, issue 15: the giver hands the ball
    into an open hand (tips its palm toward it) and lets go only once the receiver's hand carries
    the ball (was: opened at the first touch of any hand); progress shaping (`shaping`,
    `shaping_scale`) and `failure_reward` -10 replace the per-step -distance and `charge_remaining`;
    head and eyes at rest unless `assisted_gaze` (was: always aimed by the task); the scripted
    receiver `ReceiveController`; v0, issue 18: an adult giver (`per_agent=[{}, {"body": "adult",
    "posture": "kneeling"}]`, kneeling leaning 15 deg; `offer_target` is then unused) holds the ball
    where the infant giver would (`ADULT_OFFER` from the receiver's right shoulder) and tips its
    palm 1.5 (`ADULT_PRESENT`); partners of other bodies placed by their measured reach, looking at
    each other's face (`tasks/dyad.py`, docs/bodies.md); two 18-month-olds unchanged

A learning giver starts with the same grasp but holds it only if it acts: with zero actions its arm
sinks under gravity and the ball falls (a failure) within half a second.

``parallel_env(n_agents=2, task_options={...}, physics={...}, per_agent=[...], **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv`; ``env(...)`` the AEC version;
``scripted_env(partner=None, **kwargs)`` a one-learner env: the receiver ``infant_0`` learns and the
giver ``infant_1`` is the task's scripted giver (:func:`~mimo_social.tasks.handover.scripted_giver`:
a :class:`~mimo_social.partners.hand_offer.HandOffer` offering at the ``offer_target`` task option
that tips the ball into the receiver's open hand and lets go only once that hand carries it) unless
another partner is given.
"""

from .task import (Handover, HandoverOptions, scripted_giver, OFFER_TARGET, parallel_env, env,
                   scripted_env)
from .controller import ReceiveController, hand_frame, palm_posture

__all__ = ["Handover", "HandoverOptions", "scripted_giver", "OFFER_TARGET", "parallel_env", "env",
           "scripted_env", "ReceiveController", "hand_frame", "palm_posture"]
