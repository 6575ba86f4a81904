"""Mirror: two infants face to face; the follower copies the face its partner shows.

agents:
    2: `infant_0` (the learner) and `infant_1` (the partner: scripted, e.g. `ExpressionShow`, or a
    second learner; an adult partner is `caregiver_0`)
body:
    standing, hip fixed in the world, every joint held; head and eyes held at rest, looking straight
    ahead: the partner's face (at the same height, `distance` away) is in the middle of both eye
    images without any aiming. With `assisted_gaze` the head and eyes are free joints that the task
    points at the partner's face every control step (the first version)
scene:
    the two infants `distance` (0.3 m) apart, face to face: the partner's face fills about a third
    of each 64x64 eye image (see docs/social/mirror_views.png)
reset:
    both faces neutral; two learners with `roles="leader"` (default): one of them, drawn at random
    (seeded), is the episode's leader; nothing else random in the task (a scripted partner draws its
    faces and how long it shows them)
action:
    `Dict(motors=Box(0,), expression=Discrete(7))`: the expression is the action (no motor is free;
    the empty motor Box flattens to nothing in `FlattenParallel` / `make_sb3_single`, which leave 7
    expression logits). The leader's expression action is ignored: its face is set by the task
    (below)
observation:
    `eye_left`, `eye_right` (64x64x3 RGB; the only way the partner's face reaches the learner),
    `proprioception` only with `assisted_gaze` (36: the head and eye angles, constant since neither
    face moves; by default every joint is held, so there is no such key); never the partner's
    expression
two learners:
    `roles="leader"` (default): per episode one agent is the leader, whose face the task's script
    sets (each face held for a time drawn from `leader_hold_s` (1-2 s), the next one drawn among the
    other six); only the other agent, the follower, is rewarded. No fixed face can earn more than
    chance (1/7 of the steps): copying is the only way to the reward. With a shared policy each
    agent is the follower in about half the episodes (the leader's reward is 0 whatever it does, so
    its steps carry no gradient in expectation). `roles="free"`: both faces are the agents' own
    actions and both are rewarded on every match: any shared convention ("always neutral", or any
    fixed face) earns the full reward without looking; for studying how a convention forms, not
    mimicry
reward:
    the follower: +1 on a step where its expression equals its partner's, else 0; the leader 0. With
    `scripted_partner` (set by `scripted_env`) `infant_0` is the follower and `infant_1` has no
    eyes; with `roles="free"` both are rewarded on a match
success:
    per episode: `is_success` becomes True on the step at which the matched steps reach
    `success_fraction` (0.8) of the episode's `max_steps` (500: 400 steps), i.e. the step from which
    the episode can no longer fail; the last step's value is the episode's verdict. A reactive
    copier misses one step per change of the partner's face (about 4 an episode: 99 % matched);
    chance (1/7 of the steps) never comes near 80 % (random and zero: 0 %)
termination:
    none; truncation at 500 steps (5 s)
infos:
    `match` (the faces are equal this step), `matched_steps` (so far this episode), `is_success`,
    `is_leader` (this agent's face is set by the task this episode)
options:
    `distance` (0.3 m, 0.25 to 2.0), `scripted_partner` (False), `assisted_gaze` (False), `roles`
    (`"leader"`, or `"free"`), `leader_hold_s` ((1.0, 2.0) s), `success_fraction` (0.8, 0.01 to 1)
privileged cues:
    none by default: the partner's face reaches the learner only through its eyes, which look
    straight ahead at it (the posture). `assisted_gaze` (False): the task points head and eyes at
    the partner's face; it would leak no expression (the face does not move, so the angles are the
    same every step and every episode), kept as an option for other `distance` / posture settings.
    The reward reads both expressions from the world (the reward is no observation)
baselines:
    20 episodes of 500 steps, seeds 1000-1019, scripted `ExpressionShow` partner, the learner's eyes
    rendered (`docs/social/mirror.md` gives the script): random policy (uniform expression) 0 / 20
    successes, return 70.2 +- 9.5; zero action (always neutral, the two-learner convention) 0 / 20,
    93.0 +- 93.6; always happy 0 / 20, 70.5 +- 105.9; scripted `MirrorController` (copies the
    partner's face read from the world) 20 / 20, 496.5 +- 0.7, success secured at step 402.8 on
    average. PPO, scripted partner (`--normalize-obs`, gamma 0, 32x32 eyes, 2 seeds, 30k env steps,
    3.7 and 9 min on the loaded machine): 100 % evaluation success from the first evaluation (5k env
    steps, 30 s) on, both seeds; on 20 fresh episodes (seeds 1000-1019) 20 / 20 for both, return
    496.5 +- 0.7, success secured at step 403: the scripted mirror's level (`mimo-social compare
    --task mirror --mode scripted --algos ppo --seeds 2 --steps 30000 --out runs/mirror15
    --eval-every 5000 --eval-episodes 10 --normalize-obs --algo-kwargs '{"gamma": 0.0}' --env-kwargs
    '{"per_agent": [{"vision": {"width": 32, "height": 32}}, {}]}'`, then `mimo-social baselines
    mirror --episodes 20 --seed 1000 --run runs/mirror15/ppo_seed0 runs/mirror15/ppo_seed1`).
    Without input normalisation PPO stayed at chance (first version, three variants, 70k-120k steps)
sources:
    not in the MIMo paper: a social task of this package; rationale (facial mimicry, the
    correspondence problem) and figures: `docs/social/mirror.md`
version history:
    v0: first version, with joint attention and the scripted partners `ExpressionShow` and
    `GazeAtTarget`; v0, issue 15: success per episode (`success_fraction` of the steps matched; it
    was the step's match, which random met on 14 % of the steps), head and eyes held looking
    straight ahead (the task's aiming is the `assisted_gaze` option), two learners as leader (face
    set by the task) and follower by default (`roles`; the old symmetric reward, where "always
    neutral" earns everything, is `roles="free"`); v0, issue 18: partners of other bodies
    (`tasks/dyad.py`, docs/bodies.md): placed by their measured reach, each in its own posture, held
    heads and eyes on the partner's face (a kneeling adult 0.37 m away); two 18-month-olds unchanged

The learner's action and the partner's face shown on the same step are compared; the eye images of a
step show the faces as the previous step left them, so a copy lags the model by one step (10 ms):
the best reactive policy loses one step per change of the partner's face.

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns a
:class:`~mimo_social.core.env.MimoParallelEnv` with two learners (both see, both are rewarded for
matching); ``env(...)`` the AEC version; ``scripted_env(partner=None, **kwargs)`` a one-learner env
(``infant_0`` learns) whose partner ``infant_1`` is driven by a scripted
:class:`~mimo_social.partners.Partner`, by default
:class:`~mimo_social.partners.expression.ExpressionShow` (the task option ``scripted_partner`` is
set: the partner has no eyes and no reward).
"""

from .task import (parallel_env, env, scripted_env, Mirror, MirrorOptions)
from .controller import MirrorController

__all__ = ["parallel_env", "env", "scripted_env", "Mirror", "MirrorController", "MirrorOptions"]
