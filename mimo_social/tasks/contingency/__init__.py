"""Contingency: smiling with a caregiver who answers live, replays a session or smiles on a timer.

agents:
    2: `infant_0` (the learner, an 18-month-old) and `caregiver_0` (the caregiver: by default the
    adult body, kneeling; an infant partner, then named `infant_1`, is allowed with
    `per_agent=[{}, {"body": "infant"}]`).
    `scripted_env` drives the caregiver (`ContingencyCaregiver`, below); `parallel_env` makes it a
    second learner (condition "live" only)
body:
    the learner stands (as in `mirror_v0`), hip fixed in the world, every joint held but, by
    default (`gaze_free`, on), its head and eyes: they are its own (9 motors: head swivel, tilt,
    sideways tilt, each eye's 3), starting at rest, with head support (the task cancels gravity
    on them: a zero action keeps the head where it is), so it can look at the caregiver's face or
    away, and the gaze measure (`gaze_fraction`) is the learner's: Murray and Trevarthen's gaze
    avoidance is measurable. The held variant (`gaze_free=False`, the default before issue 30)
    holds head and eyes looking at the caregiver's face (`tasks/dyad.py` aims them for the pair's
    bodies), so the caregiver's face is in the middle of both eye images without any aiming and
    nothing moves but the faces: its gaze measure is 1.0 for every learner, random and zero
    included, by construction (a constant, not a measure of the learner). Measured (free gaze,
    adult caregiver, 600 steps, seed 0): the rest pose looks 62 degrees below the kneeling adult's
    face, so zero action 0.00 of the steps on the face, uniform random 0.05, turning head and eyes
    to the face (`GazeAtTarget`, PD on its own motors; the scripted
    `ContingencyDetectorController` does so) 0.97 (0.3 s to turn), turning them to its own right
    hand 0.00; with an 18-month-old partner
    (`per_agent=[{}, {"body": "infant"}]`) the rest pose already looks at its face (2 degrees off:
    zero action 1.00). The caregiver kneels (its own posture's legs), every joint held, head and
    eyes on the learner's face
scene:
    the pair face to face, `distance` (0.3 m) apart for two 18-month-olds; the kneeling adult is
    placed by the measured reach of its arm (0.37 m, `tasks/dyad.py`), as in `mirror_v0`: its face
    spans about a third of each of the learner's 64x64 eye images (about 20 pixels across on a
    rendered frame)
conditions:
    option `condition`, or `env.unwrapped.task.set_condition(name)` from the next reset on.
    **live**: the scripted caregiver answers each of the learner's smiles (its face turning "happy")
    with probability `response_probability` (0.8) by a smile `response_delay_s` (0.5 s) later, held
    `response_duration_s` (1 s; a new answer restarts it), else a neutral face
    (`ContingentCaregiver`, mode "interactive", cue: the expression only). **replay**: the
    caregiver's action stream (its faces, step by step) of an earlier live episode is played back
    regardless of the learner (`ReplayCaregiver`): by default the last live episode of this env (run
    one first), or the `stream` given to `scripted_env` (a stream dict, e.g.
    `mimo_social.partners.replay.load_stream(path)` of one saved with `save_stream(path,
    env.partners["caregiver_0"].recorded)`); Murray and Trevarthen's double video: the same
    caregiver behaviour, out of sync with the infant. **non_contingent**: the caregiver smiles, each
    smile held `response_duration_s`, at the rate it answered in this env's last live episode
    (before any live episode: `timer_rate_hz`, 0.5 per second), started on a random timer
    independent of the learner (mode "non_contingent"; a Poisson process from the partner's seeded
    generator). In replay and non-contingent nothing the learner does changes the caregiver
    (tested). Two learners: "live" only (the caregiver is the other learner's policy; replay and
    non-contingent need the script: a ConfigError)
reset:
    both faces neutral; nothing random in the task (the scripted caregiver draws its responses and
    timer from the env's seed)
action:
    `Dict(motors=Box(-1, 1, (9,)), expression=Discrete(7))`: its head and eye motors and its
    face; held (`gaze_free=False`) `motors=Box(0,)`, the face alone
observation:
    `eye_left`, `eye_right` (64x64x3 RGB: the caregiver's face reaches the learner only through its
    eyes), `proprioception` (54 floats: its head and eye joints; held: no free joint, so no such
    key; nor for a learning caregiver, whose joints are all held); never the caregiver's
    expression, mode or stream
reward:
    +1 on a step of shared smiling: the learner and the caregiver both show "happy" while the
    learner's gaze is on the caregiver's face (`partners/cues.py`, `learner_cues`), else 0; with
    `reward_free` (False) 0 on every step, every measure still in the infos (for curiosity,
    empowerment or contingency-detection signals of one's own). Two learners: each is rewarded when
    both smile and its own gaze is on the other's face. A learner that smiles at random (1/7 of the
    steps) shares at most 1/7 of the steps; the zero action (neutral) none
success:
    per episode: `is_success` becomes True on the step at which the shared-smile steps reach
    `success_fraction` (0.2) of the episode's `max_steps` (2000: 400 steps); the last step's value
    is the episode's verdict. Meant for the live condition, where the learner's smiles bring the
    caregiver's: a smile held on (one answer of 1 s) or a copy of the caregiver's face (which never
    smiles first) fails; a face drawn at random each step is happy on 1/7 of the steps (13.8 %
    shared with the gaze held on the face, measured; uniform random actions, head and eyes
    included, share 1.6 %), far from 20 %. In replay and non-contingent it depends on the
    caregiver's own timing and is reported, not a goal
termination:
    none; truncation at 2000 steps (20 s: a contingency needs several smiles and answers to show;
    Murray and Trevarthen's live and replay sessions lasted 30-60 s)
infos:
    `condition` (0 live, 1 replay, 2 non_contingent), `smiling` (the learner, this step),
    `caregiver_smiling`, `gaze_on_face` (the learner's), `shared` (a shared-smile step),
    `shared_steps`, `learner_smiles` and `caregiver_smiles` (smile onsets so far: the face turning
    "happy"), `learner_smile_rate` and `caregiver_smile_rate` (onsets per second so far),
    `smiling_fraction` (of the steps so far), `gaze_fraction`, `shared_fraction`, `response_rate`
    (the share of the learner's smiles, among those whose window has passed or been answered,
    followed by a caregiver smile onset within `window_s` (1.5 s)), `baseline_rate` (the share of
    control windows, `window_s` blocks of the episode holding no learner smile and not within
    `window_s` after one, in which the caregiver begins to smile), `contingency_index`
    (`response_rate - baseline_rate`: Watson's conditional-probability difference: about the
    response probability in live, lower in replay and non-contingent, where the caregiver's smiles
    follow the learner's only by chance), `is_success`. `gaze_on_face` and `gaze_fraction` are the
    learner's own gaze (held, `gaze_free=False`: always 1)
options:
    `condition` ("live", "replay", "non_contingent"; "replay" when the env is made needs
    `scripted_env(stream=...)`, else a ConfigError), `distance` (0.3 m, 0.25 to 2.0),
    `response_delay_s` (0.5 s, 0 to 5), `response_probability` (0.8, 0 to 1), `response_duration_s`
    (1.0 s, 0.01 to 10), `timer_rate_hz` (0.5, 0 to 10: the non-contingent rate before any live
    episode), `window_s` (1.5 s, 0.05 to 10: the contingency index's window; keep it above the
    delay), `success_fraction` (0.2, 0.01 to 1), `reward_free` (False), `gaze_free` (True: the
    learner's head and eyes free; False: held on the caregiver's face, see body),
    `scripted_partner` (False; set by `scripted_env`)
privileged cues:
    none: the caregiver's face reaches the learner only through its eyes; the reward and the
    measures read both faces and the gaze from the world (no observation)
baselines:
    live, 20 episodes of 2000 steps, seeds 1000-1019, the learner's eyes rendered (`mimo-social
    baselines contingency --episodes 20 --seed 1000`; free gaze, the default): uniform random
    actions (face, head and eye motors) 0 / 20 successes, return 31.75 +- 16.5 (its gaze on the
    face about a tenth of the steps, see effects); zero action (neutral, head at rest, looking
    below the face) 0 / 20, 0 +- 0; scripted `ContingencyDetectorController` (turns head and eyes
    to the face) 19 / 20, 665 +- 117, success secured at step 1122 on average. Held
    (`gaze_free=False`, same command with `--env-kwargs '{"task_options": {"gaze_free":
    false}}'`): random face each step 0 / 20, 276.8 +- 13.2; zero 0 / 20, 0 +- 0; scripted the same
    19 / 20, 665 +- 117 (free, it reaches the face in 0.3 s, before any shared smile). Hacks and
    an upper bound, same seeds (`python tests/tasks/test_contingency.py`; eyes off, no policy
    reads them; free gaze: each face hack turns head and eyes to the caregiver's face,
    `GazeAtTarget`): always happy 0 / 20, 90.0 +- 30.0 (one answer); copying the caregiver's face
    (`MirrorController`) 0 / 20, 0 +- 0 (the caregiver never smiles first); smiling with a one-step
    neutral dip every 0.5 s (each dip a new smile, answered before the last answer ends) 20 / 20,
    1851.3 +- 59.1: the reward's optimum uses the contingency, and the detector, which also tests
    it, reaches a third of it (held: the same figures). No trained learner yet
summary:
    `measures.condition_summary(episodes, seed, controller)` runs blocks of live, replay (of that
    block's live episode) and non-contingent episodes and returns each measure's mean and sd per
    condition (`format_summary` prints it); the scripted `ContingencyDetectorController`, 10 blocks,
    seeds 1000-1009 (`condition_summary(episodes=10, seed=1000)`; free gaze, the default; eyes off,
    or `mimo-social paradigm contingency --episodes 10 --seed 1000 --env-kwargs '{"per_agent":
    [{"vision": false}, {}]}'`), mean +- sd live / replay / non-contingent: share of the steps
    smiling 0.576 +- 0.073 / 0.381 +- 0.136 / 0.364 +- 0.158; smile onsets per second 0.42 / 0.40 /
    0.38; response rate 0.851 +- 0.124 / 0.438 +- 0.210 / 0.369 +- 0.215; baseline rate 0.000 /
    0.392 / 0.135; contingency index 0.851 +- 0.124 / 0.046 +- 0.554 / 0.234 +- 0.381; shared
    smiling 0.344 / 0.173 / 0.152 of the steps; success 9 / 5 / 3 of 10; caregiver smile onsets per
    second 0.35 / 0.35 (the same stream) / 0.24; gaze on the face 0.989 in each (held: 1.0; every
    other figure the same). The pattern Murray and Trevarthen report (fewer positive expressions
    when the same mother is replayed) shows in the share of the steps smiling, not in the smile
    onsets (the detector keeps bidding briefly)
effects:
    `measures.effects(policy, episodes, seed, env_kwargs)` runs any policy as the learner (a
    scripted partner, a function `obs -> action`, or an SB3 model: its observation flattened or its
    images made channel-first and its flat action decoded as the model needs;
    `measures.as_learner`) in the blocks of `condition_summary` and returns, per block, the live
    episode's measure minus the replay's (`live_minus_replay`: Murray and Trevarthen's double
    video) and minus the non-contingent one's (`live_minus_non_contingent`), mean +- sd over
    blocks, for `smiling_fraction`, `learner_smile_rate`, `gaze_fraction`, `contingency_index` and
    `shared_fraction` (`format_effects` prints them). The reward pays shared smiling in every
    condition: smiling less or looking away in replay earns nothing; the effects measure whether a
    learner does. Measured, 10 blocks of 2000 steps (seeds 1000-1009, the learner's eyes off: no
    policy here reads them; free gaze, the default: `mimo-social paradigm contingency --episodes
    10 --seed 1000 --env-kwargs '{"per_agent": [{"vision": false}, {}]}'`), live minus replay /
    live minus non-contingent: the scripted `ContingencyDetectorController` smiling +0.195 +- 0.156
    / +0.212 +- 0.136 of the steps, contingency index +0.81 +- 0.58 / +0.62 +- 0.34, shared
    smiling +0.170 +- 0.103 / +0.192 +- 0.097, smile onsets per second +0.02 / +0.05, gaze 0 (it
    looks at the face 0.99 of the steps in every condition: no gaze avoidance; its script has
    none); uniform random actions smiling +0.001 +- 0.009 / +0.004 +- 0.012, contingency index
    +0.001 +- 0.008 / +0.029 +- 0.010, shared +0.005 / -0.001 (no effect), gaze on the face 0.12 /
    0.09 / 0.12 of the steps (live / replay / non-contingent), gaze effect +0.027 +- 0.043 / +0.002
    +- 0.086, shared smiling 0.02 of the live steps (0 of 10 successes); zero action 0 on every
    effect (gaze 0 in every condition). Held (`gaze_free=False`, measured before issue 30 with
    `measures.effects`): the scripted detector the same effects, gaze 0 (1.0 everywhere); a random
    face each step smiling -0.001 +- 0.009 / 0.000 +- 0.006, contingency index -0.005 +- 0.019 /
    +0.027 +- 0.024, shared -0.001 / -0.003 (no effect); zero action 0 on every effect
sources:
    not in the MIMo paper: a paradigm of this package after Watson (1972, 1979: infants detect the
    contingency of events on their own behaviour, measured as conditional probabilities; the smile
    as the response to a contingent stimulus), Watson and Ramey (1972: contingent mobiles raise the
    infant's response rate), Murray and Trevarthen (1985: double video, 6-12-week-olds with their
    mothers live versus a replay of the same mother, which brought gaze avoidance and fewer positive
    expressions), Nadel et al. (1999, live-replay-live), Bigelow and Rochat (2006: 2-month-olds
    smile less to a partner whose contingency for smiles differs from their mother's). Response
    delay 0.5 s: a prompt answer, within the 1-s resolution at which face-to-face interaction is
    coded (Beebe et al. 2016), and well below the delays of a few seconds that keep young infants
    from learning a contingency (Millar 1972)
version history:
    v0, issue 19: first version, with `still_face_v0`, `imitation_v0` and the contingent and replay
    caregivers; v0, issue 30: the `gaze_free` option (at first off: the held gaze, spaces and
    numbers unchanged; the gaze measure was 1.0 for every learner), the scripted infant looks at the
    face when its gaze is free, `measures.effects` for any policy; v0, issue 30: `gaze_free` on by
    default

The learner's action and the caregiver's face of the same step are compared; a scripted caregiver
reads the learner's face before the learner's action of a step applies, so its answers come one
control step (10 ms) after `response_delay_s`.

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns a
:class:`~mimo_social.core.env.MimoParallelEnv` with two learners (the caregiver ``caregiver_0`` an
adult learner by default; condition "live" only); ``env(...)`` the AEC version;
``scripted_env(partner=None, stream=None, **kwargs)`` a one-learner env (``infant_0`` learns) whose
caregiver ``caregiver_0`` is driven by :class:`~mimo_social.tasks.contingency.ContingencyCaregiver`
(live, replay of the last live episode or of ``stream``, non-contingent, as the task's condition
says), or by ``partner``.
"""

from .task import (CONDITIONS, MEASURES, ContingencyOptions, Contingency, ContingencyCaregiver,
                   ContingencyMeasures, parallel_env, env, scripted_env)
from . import measures
from .controller import ContingencyDetectorController

__all__ = ["measures", "CONDITIONS", "MEASURES", "ContingencyOptions", "Contingency",
           "ContingencyCaregiver", "ContingencyMeasures", "parallel_env", "env", "scripted_env",
           "ContingencyDetectorController"]
