"""Handover: one infant holds out a ball in its right hand, the other takes it into its own.

agents:
    2: `infant_0` the receiver, `infant_1` the giver (an adult giver is `caregiver_0`; scripted:
    :func:`scripted_giver`, a :class:`~mimo_social.partners.HandOffer` with `release="on_hold"`, in
    `scripted_env`; or a learner); standing face to face, `distance` (0.34 m) hip to hip
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
    cm from the shoulder to the palm centre (27.7 cm to the fingertips); the *ready point*
    (:data:`READY_OFFSET`: 1 cm ahead of the offered ball's centre at reset, 5.5 cm to the
    receiver's right, 4.7 cm lower, in the receiver's heading frame: beside the giver's palm on its
    little-finger side, ~5 cm from its centre), where the scripted giver waits for the receiver's
    open hand and where :class:`~mimo_social.tasks.handover.controller.ReceiveController` holds its
    palm up, lies 20.2 cm from the receiver's shoulder, reached by its inverse kinematics within 1
    mm (measured at the default options; tests/tasks/test_receive_controller.py)
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
    reading the ball's position): holds its hand out open, palm up, at the ready point, lets the
    ball roll in and closes the fingers gently (0.05 of the motors' strength: they curl over the
    ball, up to ~0.3 radii past its centre, the grasp the success needs). With the scripted
    giver: 29 / 30 successes (seeds 1000-1029)
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
    `shaping` (on): the increase, this step, of a potential that leads the receiver's right hand
    to the giver's ready posture (what the scripted giver waits for before it tips the ball in: an
    open palm up beside its hand): minus `shaping_scale` (10) x the distance (m) from the
    receiver's palm centre to the ready point, plus `palm_up_scale` (2) x the upward component of
    the palm's normal (-1 to 1), plus, while the ball touches the receiver's hand and not the
    giver's, `grip_scale` (2) x the closure of its four fingers (mean fraction of the mcp, pip,
    dip flexion ranges). Progress only: it sums to the potential's end minus start (the scripted
    receiver: ~+4.5), so hovering earns nothing more and leaving gives it back; `+success_reward`
    (10) on success; `failure_reward` (-10) when the ball drops. Holding the ball is the optimum;
    dropping it is worse than never trying (zero action: ~0)
success:
    the receiver holds the ball, without a break, for `hold_time` (0.3 s): it touches at least
    `min_parts` (2) segments of the receiver's right hand (palm, finger segments); the hand is
    closed around it (contacts on both sides of the ball's centre along the palm's normal: one at
    least `grasp_height` (0) radii past the centre away from the palm, i.e. fingers curled over
    the ball, and one on the palm's side); it does not touch the giver's hand; and it is above
    `drop_height`. A ball resting on an open palm, or on the back of the hand, is not held (the
    hack `OpenPalm`: 0 / 30). `is_success` in the last step's info is the episode's outcome; one
    test per clause: tests/tasks/test_handover_clauses.py
termination:
    both agents, on success (`end_on_success`) or when the ball falls below `drop_height` (0.25 m:
    well below the hands, near the floor); truncation at `max_steps` (600, 6 s)
infos:
    `is_success`, `holder` (`"giver"`: the ball touches the giver's hand; `"receiver"`: the
    receiver holds it, as the success says, this step; `"none"` otherwise), `dropped`,
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
    30 episodes each, reset seeds 1000-1029, `scripted_env(scripted_giver())` (the receiver acts;
    issue 30's success and shaping): scripted `ReceiveController` 29 / 30 successes, return 13.9 +-
    3.7, 216 steps (2.2 s) to success (1 drop: seed 1005); zero action 0 / 30, 0.01 +- 0.13; random
    (uniform) 0 / 30, -1.0 +- 3.1 (3 drops); hacks: the open never-closing palm (`OpenPalm`: held
    out like the scripted cup, fingers never closed) 0 / 30, -3.6 +- 4.4 (22 drops), the same with
    the fingers pre-curled (`OpenPalm(cup_deg=(20, 20, 10))`: the ball rests in it for the whole
    episode) 0 / 30, 3.8 +- 0.2; touch the ball (`ReachController(depth=0.02)`) 0 / 30, 0.4 +- 0.2;
    hold the hand out and leave when the ball comes (`CupAndLeave`) 0 / 30, -9.0 +- 0.1 (30 drops).
    Before issue 30 (the ball resting on 2 hand segments was a success) `OpenPalm` succeeded 3 / 20
    (seeds 1000-1019; the same with `grasp_height=-1`). Command: `python -m pytest -m slow
    tests/tasks/test_receive_controller.py -s` (prints them, ~5 min). PPO receiver (issue 15's
    reward and success, not rerun since): scripted giver, 2 seeds, 200k env steps each (SB3
    defaults, 22 min): evaluation (10 episodes every 20k) 0 % success throughout, return between -10
    and +1.3 (it learns to bring the hand to the ball, then alternates with knocking it down); the
    final models on seeds 1000-1019: 0 / 20, 0.2 +- 2.9 and 0 / 20, -2.0 +- 5.3: not above random on
    success (`mimo-social compare --task handover --mode scripted --algos ppo --seeds 2 --steps
    200000 --out runs/handover15 --eval-every 20000 --eval-episodes 10 --jobs 2`, then `mimo-social
    baselines handover --episodes 20 --seed 1000 --run runs/handover15/ppo_seed0
    runs/handover15/ppo_seed1`). The shipped recipe (issue 30; `mimo-social recipe handover
    --seeds 0,1 --jobs 2 --out runs/recipes/handover`): with `assisted_gaze`, a warm start from
    the scripted receiver with 6 DAgger rounds, then PPO 200k with the cloning kept up; each
    run's best evaluated model, seeds 1000-1029, assisted gaze for every policy: 30 / 30 and
    30 / 30 (mean action; sampled 1 / 30 and 4 / 30), return 14.4 and 14.5 (scripted 29 / 30,
    13.9); the final models 7 / 30 and 26 / 30 (docs/baselines.md, "Recipes")
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
    each other's face (`tasks/dyad.py`, docs/bodies.md); two 18-month-olds unchanged; v0, issue 30:
    success needs the ball held in a closed hand (contacts on both sides of its centre,
    `grasp_height`; was: resting on 2 hand segments, which an open palm met) and above
    `drop_height` to count as held; the shaping leads to the giver's ready posture (ready point,
    palm up, finger closure with the ball in hand; `palm_up_scale`, `grip_scale`; was: the palm's
    distance to the ball, which pointed at the ball still in the giver's hand); the hack `OpenPalm`

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

from .task import (Handover, HandoverOptions, scripted_giver, OFFER_TARGET, READY_OFFSET,
                   parallel_env, env, scripted_env)
from .controller import ReceiveController, OpenPalm, hand_frame, palm_posture

__all__ = ["Handover", "HandoverOptions", "scripted_giver", "OFFER_TARGET", "READY_OFFSET",
           "parallel_env", "env", "scripted_env", "ReceiveController", "OpenPalm", "hand_frame",
           "palm_posture"]
