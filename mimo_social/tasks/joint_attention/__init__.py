"""Joint attention: the learner follows its partner's gaze, read from its eyes, to one of the toys.

agents:
    2: `infant_0` (the learner) and `infant_1` (the partner: scripted, by default `GazeAtTarget`,
    which looks at one toy after another, or a second learner; an adult partner is `caregiver_0`)
body:
    sitting, hip fixed in the world, every joint held except the head (swivel, tilt, sideways tilt)
    and the eyes (horizontal, vertical, torsional), which are motors: each agent turns its own head
    and eyes; with `head_support` (on) the task cancels gravity on head and eyes (neck tone: a zero
    action does not let the head drop). The eyeballs (white, iris, pupil) turn with the eye joints
    and are seen by the other's eyes
scene:
    the two infants `distance` (0.7 m) apart, face to face; `n_toys` (4) toys on the floor beside
    them, a red ball, a blue cube, a yellow ball and a green cube (3.5 cm), to the left and right of
    the pair, 0.25-0.45 m off the line between the infants, each at least `min_separation_deg` (25)
    from every other as seen from either head
reset:
    the toys placed at random (seeded), each turned at random about the vertical; heads and eyes at
    rest, facing the partner; with two learners (`two_learners` "leader") one of them drawn as the
    leader
action:
    the 9 head and eye motors (`Box(-1, 1, (9,))`; expressions are off by default)
observation:
    `eye_left`, `eye_right` (96x96x3 RGB), `proprioception` (54: its own joints, where its head and
    eyes point); with two learners in "leader" mode also `instruction` (`n_toys`: one-hot of the toy
    the leader is to look at; all zeros for the follower); never the partner's target or joint
    angles. With the agent option `faces` (face perception, docs/senses.md "Faces"; the shipped
    recipe's learner: eyes off, `faces` with a 160-degree view) also `faces` (10): while the
    partner's face is in view, turned to it and not hidden, where the partner's head is, where
    it is turned and its line of sight, in the learner's head frame; zeros otherwise
partner:
    the scripted `GazeAtTarget` holds each toy 1.5-3 s (then another, never the same twice); per
    gaze shift its head makes a share of the turn drawn uniformly from `partner_head_share` +-
    `partner_head_jitter` (0.3 +- 0.3: from 0 to 0.6) and its eyes the rest (the head makes up what
    the eyes cannot reach, 40 degrees), so that which of the toys on a side it looks at is told by
    its eyes, its head turn telling mostly the side
gaze:
    an agent's gaze ray starts between its eyes (the mean of the two eye cameras) along the mean of
    the two cameras' viewing axes; it *lands on* a toy when the angle to the toy's centre is below
    the toy's angular radius plus `margin_deg` (5); the nearest such toy is the one looked at
reward:
    the follower (`infant_0` with a scripted partner): +1 on a step where its gaze lands on the toy
    the leader's gaze lands on (shared attention), minus `shaping` (0.1) x the angle (rad) between
    its gaze ray and that toy while the leader looks at one; the leader (two learners, "leader"
    mode): the same toward its `instruction`; with `two_learners` "shared" both are followers of
    each other (+1 whenever they look at the same toy). With `scripted_partner` (set by
    `scripted_env`) only `infant_0` is rewarded and `infant_1` has no eyes
success:
    per episode: `is_success` says whether, so far, the agent's gaze was on its target on at least
    `success_share` (0.6) of the steps on which it had one (follower: the steps the leader looked at
    a toy; leader: every step), after at least 1 s of such steps; the last step's value is the
    episode's. Infos also `looked_at` (own toy or -1), `target` (the toy it is rewarded for, -1
    none, e.g. while the leader turns), `gaze_error_deg` (-1 without a target), `shared` (on target
    this step), `on_target_fraction`, `leader`
termination:
    none; truncation at 500 steps (5 s)
options:
    `distance` (0.7-1.5 m), `n_toys` (2-4), `margin_deg` (0-30), `shaping` (0-100, default 0.1),
    `success_share` (0.05-1, 0.6), `partner_head_share` (0-1, 0.3), `partner_head_jitter` (0-0.5,
    0.3), `two_learners` ("leader" or "shared"), `min_separation_deg` (0-35), `head_support` (True),
    `scripted_partner` (False)
privileged cues:
    none for the follower: the partner's head and eye turns reach it only through its own eyes, and
    nothing of the partner's target is in its observation; the leader's `instruction` is its own
    task, not the partner's state. `faces` gives the partner's line of sight only while the
    learner sees the face (not the toy it lands on: the learner finds that itself). The shaping
    term reads the partner's toy from the geometry (the reward, not an observation)
two learners:
    `two_learners` "leader" (default): per episode the task draws a leader, which is rewarded for
    looking at the toy of its `instruction` (a new toy every 1.5-3 s, never the same twice), and the
    follower for looking where the leader looks; "both always look at the same toy" earns the leader
    its instruction's share of the steps only (about 1/`n_toys`) and fails. "shared": the v0
    convention, both rewarded for any shared look: "both always look at the red toy" earns the full
    reward
baselines:
    scripted partner, 20 episodes (seeds 1000-1019): random success 0/20, return -67.4 +- 12.0; zero
    action 0/20, -46.8 +- 8.7 (`mimo-social baselines joint_attention --episodes 20 --seed 1000`);
    scripted `GazeFollowController` (reads the partner's eyes from the world) 20/20, 369.3 +- 28.8
    (the same with 64x64 eyes rendered, `mimo-social baselines`), success from step 125 on average;
    hacks: always the red ball 1/20, 108.5 +- 114.6; head-only reader (`read="head"`) 3/20, 143.8 +-
    131.1 (tests/tasks/test_joint_attention.py, slow variant); `CheckingFollowController` (reads
    the partner only while it watches the partner's face, looks back at the partner's head turn:
    what a learner's eyes allow) 20/20 (`scripts/joint_attention_checking_follower.py`). PPO,
    `--normalize-obs`, 32x32 eyes, 2 seeds, 51k steps (13 min wall for both): success 0/20
    each, return -37.2 +- 19.1 and -51.3 +-
    4.9 (above random, not above zero for seed 1); 64x64 eyes, 2 seeds, 100k steps (18 min wall for
    both): 0/20 each, -49.0 +- 12.6 and -47.0 +- 12.9 (the zero action's level): PPO does not follow
    the partner's gaze in these budgets (commands, curves and machine in
    `docs/social/joint_attention.md`). The shipped recipe (issue 30: eyes off, `faces` at 160
    degrees, an LSTM cloned from 300 episodes of `SensedFollowController`, which reads only
    through that sense and succeeds in 20/20, then RecurrentPPO 50k with the cloning kept): 90 %
    / 87 % and 87 % / 83 % (mean / sampled, 2 seeds, 30 episodes; docs/baselines.md)
sources:
    not in the MIMo paper: a social task of this package; rationale (gaze following from 9-18
    months; 18-month-olds follow eye turns alone, Moore & Corkum 1998; eyes matter from 10-12
    months, Brooks & Meltzoff 2002, 2005) and figures: `docs/social/joint_attention.md`
version history:
    v0: first version, with mirror and the scripted partners `ExpressionShow` and `GazeAtTarget`.
    v0, issue 15: visible eyeballs (the partner's eyes show where it looks); the scripted partner
    turns mostly its eyes (`partner_head_share`, `partner_head_jitter`); shaping on by default
    (0.1); per-episode success (`success_share`); two learners: leader and follower (`two_learners`,
    default "leader"; the old convention as "shared"); scripted follower `GazeFollowController`; v0,
    issue 18: partners of other bodies (`tasks/dyad.py`, docs/bodies.md): placed by their measured
    reach (a kneeling adult 1.34 m away), each in its own posture; two 18-month-olds unchanged

What the learner sees: the partner's head turn and its eyeballs (iris and pupil on white), a few
pixels across at 0.7 m in a 96x96 eye (`docs/social/eyes_partner_gaze.png`). With the partner's head
making 0-60 % of each turn, the side it looks to shows in its head, the toy on that side mostly in
its eyes.

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns a
:class:`~mimo_social.core.env.MimoParallelEnv` with two learners (both see, both get the shared
reward); ``env(...)`` the AEC version; ``scripted_env(partner=None, **kwargs)`` a one-learner env
(``infant_0`` learns) whose partner ``infant_1`` is driven by a scripted
:class:`~mimo_social.partners.Partner`, by default :class:`~mimo_social.partners.gaze.GazeAtTarget`
looking at the toys (the task option ``scripted_partner`` is set: the partner has no eyes and no
reward).
"""

from .task import (parallel_env, env, scripted_env, JointAttention, JointAttentionOptions)
from .controller import GazeFollowController
from .checking import CheckingFollowController
from .sensed import SensedFollowController

__all__ = ["parallel_env", "env", "scripted_env", "JointAttention", "GazeFollowController",
           "CheckingFollowController", "SensedFollowController", "JointAttentionOptions"]
