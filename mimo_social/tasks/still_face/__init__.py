"""Still face: face-to-face play, then the caregiver's still, unresponsive face, then reunion.

agents:
    2: `infant_0` (the learner infant) and `caregiver_0` (the caregiver: by default the adult body
    kneeling, `body="adult"`, `posture="kneeling"`; an infant partner, then named `infant_1`, is
    allowed, e.g. `per_agent=[{}, {"body": "infant", "posture": "sitting"}]`); scripted
    (`scripted_env`: by default a `ContingentCaregiver`, `partners/contingent.py`) or a second
    learner
body:
    the learner sits (the infant seat of the paradigm), hip fixed in the world, every joint held
    except head and eyes (9 motors) and, with `arms_free` (on), both shoulders and elbows (8
    motors): it can look at or away from the caregiver and bring its hands to its own body
    (self-directed behaviour); without `arms_free` no self-touch is possible; without
    `gaze_free` its head and eyes are no motors and are held aimed at the caregiver's face
    (`gaze_on_face` at every step: the gaze measures are then 1; with both off its action is its
    face alone). The caregiver holds its posture (legs, trunk) and moves its head and eyes and
    its right arm (shoulder, elbow, wrist: 7 motors; its fingers held), as `ContingentCaregiver`
    needs (its gaze response and its pat).
    Both have faces (expressions on). With `head_support` (on) the task cancels gravity on both
    agents' head and eye joints (neck tone: a zero action does not let the head drop)
scene:
    the pair face to face; two sitting 18-month-olds `distance` (0.6 m) apart, or farther where
    their feet would start inside each other (at 0.6 m a foot was 3.6 cm in the other's shin: they
    sit 0.696 m apart, `tasks/dyad.py` `clear_distance`; at 0.45 m the scripted infant's hands
    caught on the partner's toes on their way to its chest); other bodies placed by measured
    reach (`tasks/dyad.py`): the kneeling adult's hip
    1.01 m from the infant's, at arm's length, its eyes (1.13 m high) 1.0 m from the sitting
    infant's (0.42 m high), 45 degrees above them; its head (0.18 m across) spans 10 degrees, 11
    pixels of a 64x64 eye (60 degree field; `per_agent=[{"vision": {"width": 128, "height": 128}},
    {}]` doubles it). Closer, the adult's face would be nearly overhead (the "gap" law of
    `tasks/dyad.py`: 0.61 m, 67 degrees up)
phases:
    `phases_s` = (interaction, still face, reunion) seconds, default (5, 5, 5): phase k lasts
    `round(phases_s[k] / dt)` control steps (dt 0.01 s: 500 each) times, for interaction and still
    face, a uniform draw within 1 +- `phase_jitter` (0.5: 2.5-7.5 s each) at every reset (from the
    env's seed; 0: fixed), so no clock tells the learner when the face will freeze or thaw, only the
    face does; `max_steps` defaults to the sum of `phases_s` at the default dt (1500; reunion fills
    what the first two phases leave, and steps past the last phase stay in reunion). Laboratory
    phases last 1-2 min (Mesman et al. 2009); seconds here keep episodes short enough to train.
    Interaction and reunion: the caregiver acts; the scripted form sets a caregiver with `set_mode`
    to `"interactive"`. Still face: the scripted form sets it to `"still"`, and the task holds the
    caregiver still whoever drives it (a script or a second learner, whose actions are then
    ignored): its face shown neutral, its free joints written back to the angles they had when the
    phase began and their velocities zeroed every control step, its controls replaced by ones that
    hold (spring-damper: none, gravity and springs cancelled by applied forces; positional: the held
    angles plus the gravity torque over the servo stiffness). Measured: no free joint of the
    caregiver moves more than 1e-3 rad in the still phase (tests/tasks/test_still_face.py,
    spring-damper and positional, random caregiver actions)
reset:
    heads and eyes at rest: the learner's line of sight passes 51 degrees below the caregiver's face
    (it sees the caregiver's trunk and thighs, the face above its view), so a still learner does not
    look at the face; both faces neutral; arms at their sitting rest. Random: the lengths of the
    interaction and still-face phases (`phase_jitter`), drawn from the env's seed; the scripted
    caregiver draws whether it answers each cue (with its defaults, `probability` 1, it always
    does)
action:
    learner: `Dict(motors=Box(-1, 1, (17,)), expression=Discrete(7))` (9 head and eye motors, then
    the 8 arm motors; 9 without `arms_free`, 8 without `gaze_free`, 0 without both); caregiver (two
    learners): its 16 motors and expression (and `voice`, `loudness` with `caregiver_speech`)
observation:
    `eye_left`, `eye_right` (64x64x3 RGB: the only way the caregiver's face and movements reach the
    learner), `proprioception` (102 floats: its own free joints); a scripted caregiver has no eyes;
    never the phase, nor the caregiver's expression or mode; with `caregiver_speech`, `audition`
    (and `audition_memory` where set): the caregiver's voice
measures:
    per learner step, from `learner_cues` (`partners/cues.py`, the same cues the contingent
    caregiver answers): `smiling` (its face is "happy": positive expression), `gaze_on_face` (its
    line of sight passes within 10 degrees of the caregiver's face centre), and `self_touch`
    (self-directed behaviour: a contact between a hand of the learner and its own head, trunk or
    other arm and hand; a hand on its legs or hip does not count, nor a touch by or of the
    caregiver); per phase, so far this episode, the fraction of that phase's steps with each:
    `smile_<phase>`, `gaze_<phase>`, `self_touch_<phase>` (phases `interaction`, `still`,
    `reunion`), and `phase` (0, 1, 2: the step's phase, names in `PHASES`).
    `measures.still_face_summary(infos)` gives their mean and spread over episodes from each
    episode's last info; `format_still_face_summary` prints it
effects:
    `measures.effects(policy, episodes, seed, env_kwargs)` runs any policy as the learner (a
    scripted partner, a function `obs -> action`, or an SB3 model: its observation flattened or
    its images made channel-first and its flat action decoded as the model needs;
    `measures.as_learner`) in seeded episodes of `scripted_env(**env_kwargs)` and returns the
    paradigm's effect, per episode then mean +- sd over episodes: `smile_still_drop` and
    `gaze_still_drop` (interaction minus still face), `smile_reunion_recovery` and
    `gaze_reunion_recovery` (reunion minus still face), `self_touch_still_rise` (still face minus
    interaction), each a difference of shares of the phase's steps (`format_effects` prints
    them). Measured, 20 episodes (seeds 1000-1019, default settings, the phases drawn, the
    learner's eyes off: no policy here reads them; `mimo-social paradigm still_face --episodes 20
    --seed 1000 --env-kwargs '{"per_agent": [{"vision": false}, {}]}'`): `StillFaceInfantController`
    smile drop 0.991 +- 0.001, recovery 0.990 +- 0.001, gaze drop 0.939 +- 0.014, recovery 0.925
    +- 0.043, self-touch rise 0.940 +- 0.019; uniform random +0.009 +- 0.025, +0.015 +- 0.025,
    -0.045 +- 0.110, -0.012 +- 0.148, +0.001 +- 0.024 (no effect); zero action 0 on every effect (it
    never smiles, looks or touches)
reward:
    a social reward, +1 on a step of mutual engagement: the learner looks at the caregiver's face
    while both smile (the learner's and the caregiver's face "happy"); -`unshared_cost` (1) on a
    step on which the learner smiles and is not engaged (the caregiver's face neutral, the still
    face included, or its gaze elsewhere), to the learner only; else 0. The default caregiver smiles
    back 0.5 s after each onset of the learner's smile, for 1 s: a smile held without renewal is
    answered once, so engagement needs renewed bids, as in a real exchange. Two learners both get it
    (cooperative); with `scripted_partner` only `infant_0`. `reward_free` (off): every reward 0, the
    measures unchanged (for a learning signal of one's own: curiosity, contingency detection). The
    still phase pays nothing (the caregiver's face is held neutral) and charges smiling at the still
    face: sobering, the first part of the paradigm's classic still-phase response, avoids that cost;
    looking away and self-touch earn nothing by default (the effects row measures whether a learner
    shows them). `still_response_reward` (0: off) pays that much more on each still-phase step of
    the classic response (`still_response` in the infos: a hand of the learner touches its own head,
    trunk or other arm, it does not smile, its gaze is off the caregiver's face), to the learner
    only; it needs `arms_free`. Measured (phases 1 s each, seed 0, before the unshared cost): the
    scripted infant's return 97 without it, 133 with 0.5 (72 response steps of the 100 still ones);
    smiling through the still face, or a zero action, gets nothing of it
success:
    per episode: `is_success` is True on a step at which the engaged steps have reached
    `success_fraction` (0.8) of the episode's interaction and reunion steps (within `max_steps`:
    1000 on average by default) and are at least `success_match` (0.8) of the learner's smiling
    steps so far (`matched_fraction`: smiling at the still face, or at a caregiver that has not
    answered, lowers it); the last step's value is the verdict. Success measures engagement in the
    interactive phases and that the learner's smiles follow the face it sees: smiling blind through
    the still face fails (hacks, below)
termination:
    none; truncation at `max_steps`
infos:
    `phase`, `smiling`, `gaze_on_face`, `self_touch`, `engaged`, `still_response`, `engaged_steps`,
    `interactive_steps` (interaction and reunion steps so far), `matched_fraction` (engaged steps
    over the learner's smiling steps; 0 before it smiles), `smile_<phase>`, `gaze_<phase>`,
    `self_touch_<phase>`, `is_success` (the learner's measures; the caregiver's infos are the same).
    The caregiver's `expression` info is its action's, also while the task shows its face neutral
options:
    `phases_s` ((5, 5, 5) s, each 0.05-600), `phase_jitter` (0.5, 0-0.9: see phases; 0: the
    fixed phases before issue 30's fix), `distance` (0.6 m, 0.3-1.5: two sitting 18-month-olds'
    hip distance), `gaze_free` (True: see body), `arms_free` (True), `head_support` (True),
    `unshared_cost` (1.0, 0-10; 0: the reward before the fix), `success_fraction` (0.8, 0.05-1;
    0.5 before the fix), `success_match` (0.8, 0-1; 0: the success before the fix),
    `still_response_reward` (0, 0-10: see reward), `caregiver_speech` (False: see speech),
    `reward_free` (False), `scripted_partner` (False)
speech:
    with `caregiver_speech` the caregiver has a voice (`voice=True`) and the learner ears
    (`audition=True`; a learner caregiver too): the parent talks in the interaction and the
    reunion and falls silent in the still face, as in the paradigm's protocol (Tronick et al. 1978;
    Mesman et al. 2009). The scripted `ContingentCaregiver` talks whatever the learner does, from
    the first step of each interactive phase: utterances ("speech") of 0.5-1.5 s with pauses of
    0.3-1.2 s (its `speech_s`, `pause_s`, `speech_loudness`); the task mutes the caregiver in the
    still face whoever drives it (`env.mute`). With an echoic memory (`per_agent=[{"audition":
    {"memory_s": 2.0, "memory_bin_s": 0.1}}, {}]`) the learner's last 1.3 s hold the caregiver's
    voice at every interactive step and none from 1.3 s into the still face (tested): a policy
    without memory of its own can tell the phases apart, also while it looks away, which it cannot
    with the silent caregiver (the still face's neutral face is the interaction's face between two
    answered smiles). Off by default: v0's spaces and figures are those of the silent caregiver
privileged cues:
    none: the caregiver's face, head and arm reach the learner only through its eyes; the phase and
    the caregiver's mode are never observed. The reward and the measures read both faces, the gaze
    line and the contacts from the world (they are no observation)
baselines:
    scripted form, default settings, 20 episodes of 15 s (seeds 1000-1019; the first two phases
    drawn): scripted `StillFaceInfantController` 20 / 20, return 782.6 +- 126 (it reads the phase;
    each phase change costs it the caregiver's 0.5-s answer delay), success secured at step 1412 on
    average; its measures per phase (fraction of the phase's steps, mean over episodes; smile / gaze
    at the face / self-touch): interaction 0.99 / 0.95 / 0.00, still 0.00 / 0.01 / 0.94, reunion
    0.99 / 0.93 / 0.01, the still-face pattern (the gaze fractions miss the 0.3 s head turns).
    Random 0 / 20, -180.8 +- 19.7; zero action 0 / 20, 0.0 +- 0.0, every measure 0 (`mimo-social
    baselines still_face --episodes 20 --seed 1000`). The test file's own baselines and hacks, with
    every measure (`python tests/tasks/test_still_face.py 20`): uniform random 0 / 20, -185.8 +-
    22.3, smile 0.14-0.15, gaze 0.09-0.14, self-touch 0.02-0.03 in every phase; "stare" (smiles and
    looks, never renews its smile: answered once a phase) 0 / 20, -599.2 +- 124.5; "look" (looks,
    never smiles) 0 / 20, 0.0; looks with a random face every step 0 / 20, 38.8 +- 40.2; smiles
    (renewed every second) without turning its head 0 / 20, -1485; looks and smiles blind through
    every phase (a one-step dip every 0.5 s, each a new bid) 0 / 20, 234.5 +- 246.3 (880 and 20 /
    20 before issue 30's fix); looks and smiles blind on the default schedule (the dips, neutral
    from 5 to 10 s) 4 / 20, 501.8 +- 185.3: it succeeds when the drawn phases fall near their
    means. `test_baselines_scripted_succeeds_random_zero_and_hacks_fail` (slow) checks these on 5
    episodes
sources:
    Tronick, Als, Adamson, Wise & Brazelton (1978), The infant's response to entrapment between
    contradictory messages in face-to-face interaction, J. Am. Acad. Child Psychiatry 17: 1-13 (the
    paradigm: interaction, still face, reunion; infants sober, look away and comfort themselves when
    the mother's face is still); Mesman, van IJzendoorn & Bakermans-Kranenburg (2009), The many
    faces of the Still-Face Paradigm, Developmental Review 29: 120-162 (review and meta-analysis of
    the measures: positive affect and gaze at the parent drop in the still face and partly recover
    in reunion)
version history:
    v0, issue 19: first version, with the contingent caregiver (`partners/contingent.py`), the
    learner's cues (`partners/cues.py`) and the scripted infant `StillFaceInfantController`; v0,
    issue 30: `measures.effects` for any policy, the `still_response_reward` option (default off:
    rewards unchanged) and the `still_response` info; v0, issue 30 (the still-face fix): a blind
    face succeeded (looking at the face and smiling with a one-step dip every 0.5 s through every
    phase: 880 of the scripted infant's 888, success in every episode), so the interaction and
    still-face phases are drawn (`phase_jitter`), smiling that is not engaged costs
    (`unshared_cost`), success needs 0.8 of the interactive steps engaged (was 0.5) and 0.8 of the
    learner's smiling engaged (`success_match`); `phase_jitter=0`, `unshared_cost=0`,
    `success_fraction=0.5`, `success_match=0` give the old task; v0, issue 30 (fifth session): the
    `caregiver_speech` option (default off)

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns a
:class:`~mimo_social.core.env.MimoParallelEnv` with two learners (the infant ``infant_0`` and the
caregiver ``caregiver_0``, by default the kneeling adult; the task holds the caregiver still in the
still phase, whatever its actions); ``env(...)`` the AEC version; ``scripted_env(partner=None,
**kwargs)`` a one-learner env (``infant_0`` learns) whose caregiver ``caregiver_0`` is driven by a
scripted :class:`~mimo_social.partners.Partner`, by default
:class:`~mimo_social.partners.contingent.ContingentCaregiver`: before every step the wrapper sets a
partner that has ``set_mode`` to ``"still"`` in the still phase and to ``"interactive"`` in the
others (the task option ``scripted_partner`` is set: the caregiver has no eyes and no reward).
"""

from .task import (PHASES, MEASURES, LEARNER_ARM_JOINTS, StillFace, StillFaceOptions,
                   self_touch_geoms, parallel_env, env, scripted_env, PhasedPartners)
from . import measures
from .controller import StillFaceInfantController

__all__ = ["measures", "PHASES", "MEASURES", "LEARNER_ARM_JOINTS", "StillFace", "StillFaceOptions",
           "self_touch_geoms", "parallel_env", "env", "scripted_env", "PhasedPartners",
           "StillFaceInfantController"]
