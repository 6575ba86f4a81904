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
    with probability `response_probability` (0.8) by a smile `response_delay_s` (0.3 s) plus a
    uniform draw up to `response_jitter_s` (1 s) later, held `response_duration_s` (1 s), else a
    neutral face (`ContingentCaregiver`, mode "interactive", cue: the expression only,
    `refractory`: a smile that begins while an answer is pending or shown is not answered, so a
    flickering face does not keep the caregiver smiling; the drawn delay keeps a blind learner
    from timing its smiles to the answer). **replay**: the
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
    learner's gaze is on the caregiver's face (`partners/cues.py`, `learner_cues`); -`unshared_cost`
    (1) on a step on which the learner smiles and it is not shared (the caregiver's face neutral, or
    the learner looking elsewhere); else 0. So the reward pays a smile returned to the caregiver's,
    which the learner sees only through its eyes, and charges smiling into a neutral face: the
    optimum is a brief bid, then the caregiver's answer returned while it lasts (what the scripted
    infant does). With `reward_free` (False) 0 on every step, every measure still in the infos (for
    curiosity, empowerment or contingency-detection signals of one's own). Two learners: each is
    rewarded when both smile and its own gaze is on the other's face, and charged for its own
    unshared smiling. The zero action (neutral) earns 0
success:
    per episode: `is_success` is True on a step at which the shared-smile steps have reached
    `success_fraction` (0.2) of the episode's `max_steps` (2000: 400 steps) and are at least
    `success_match` (0.85) of the learner's smiling steps so far (`matched_fraction`); the last
    step's value is the episode's verdict. Meant for the live condition, where the learner's bids
    bring the caregiver's smiles and the learner must see them to return them: a smile held on
    (one answer of 1 s), a copy of the caregiver's face (which never smiles first), flickering
    faces and faces drawn at random (which keep the caregiver answering, but half their smiling
    falls on its neutral face) and smiles timed blind to the likeliest moment of an answer all
    fail (hacks, below). In replay and non-contingent it depends on the caregiver's own timing and
    is reported, not a goal
termination:
    none; truncation at 2000 steps (20 s: a contingency needs several smiles and answers to show;
    Murray and Trevarthen's live and replay sessions lasted 30-60 s)
infos:
    `condition` (0 live, 1 replay, 2 non_contingent), `smiling` (the learner, this step),
    `caregiver_smiling`, `gaze_on_face` (the learner's), `shared` (a shared-smile step),
    `shared_steps`, `learner_smiles` and `caregiver_smiles` (smile onsets so far: the face turning
    "happy"), `learner_bids` (the learner's smile onsets while the caregiver's face is neutral: a
    smile returned to the caregiver's asks for nothing), `learner_smile_rate` and
    `caregiver_smile_rate` (onsets per second so far), `smiling_fraction` (of the steps so far),
    `gaze_fraction`, `shared_fraction`, `matched_fraction` (shared steps over the learner's smiling
    steps; 0 before it smiles), `response_rate` (the share of the learner's bids, among those whose
    window has passed or been answered, followed by a caregiver smile onset within `window_s` (1.5
    s)), `baseline_rate` (the share of control windows, `window_s` blocks of the episode holding no
    learner bid and not within `window_s` after one, in which the caregiver begins to smile),
    `contingency_index` (`response_rate - baseline_rate`: Watson's conditional-probability
    difference: about the response probability in live, lower in replay and non-contingent, where
    the caregiver's smiles follow the learner's only by chance), `is_success`. `gaze_on_face` and
    `gaze_fraction` are the learner's own gaze (held, `gaze_free=False`: always 1)
options:
    `condition` ("live", "replay", "non_contingent"; "replay" when the env is made needs
    `scripted_env(stream=...)`, else a ConfigError), `distance` (0.3 m, 0.25 to 2.0),
    `response_delay_s` (0.3 s, 0 to 5: the shortest delay), `response_jitter_s` (1.0 s, 0 to 5: the
    delay's uniform spread; 0: a fixed delay), `response_probability` (0.8, 0 to 1),
    `response_duration_s` (1.0 s, 0.01 to 10), `timer_rate_hz` (0.5, 0 to 10: the non-contingent
    rate before any live episode), `window_s` (1.5 s, 0.05 to 10: the contingency index's window;
    keep it above the longest delay), `unshared_cost` (1.0, 0 to 10: the reward of a smiling step
    not shared, negated; 0: the reward before issue 30's fix), `success_fraction` (0.2, 0.01 to 1),
    `success_match` (0.85, 0 to 1; 0: the success before the fix), `reward_free` (False),
    `gaze_free` (True: the
    learner's head and eyes free; False: held on the caregiver's face, see body),
    `scripted_partner` (False; set by `scripted_env`)
privileged cues:
    none: the caregiver's face reaches the learner only through its eyes; the reward and the
    measures read both faces and the gaze from the world (no observation)
baselines:
    live, 20 episodes of 2000 steps, seeds 1000-1019, the learner's eyes rendered (`mimo-social
    baselines contingency --episodes 20 --seed 1000`; free gaze, the default): uniform random
    actions (face, head and eye motors) 0 / 20 successes, return -245.9 +- 28.8 (happy on a seventh
    of the steps, its gaze on the face about a tenth of them, see effects); zero action (neutral,
    head at rest, looking below the face) 0 / 20, 0 +- 0; scripted `ContingencyDetectorController`
    (turns head and eyes to the face) 19 / 20, 521.6 +- 72.4, success secured at step 1540 on
    average. Held (`gaze_free=False`, same command with `--env-kwargs '{"task_options":
    {"gaze_free": false}}'`): random face each step 0 / 20, 9.6 +- 22.8; zero 0 / 20, 0 +- 0;
    scripted the same 19 / 20, 521.6 +- 72.4 (free, it reaches the face in 0.3 s, before any shared
    smile). Hacks, same seeds (`python tests/tasks/test_contingency.py`; eyes off, no policy reads
    them, none sees the caregiver's face; free gaze: each turns head and eyes to the caregiver's
    face, `GazeAtTarget`), successes, return, shared and matched fraction: always happy 0 / 20,
    -1820 +- 60 (one answer), 0.045, 0.045; copying the caregiver's face (`MirrorController`) 0 /
    20, 0 (the caregiver never smiles first); a one-step neutral dip every 0.5 s 0 / 20, -190 +-
    131, 0.442, 0.451; a dip every 0.05 s (a flicker) 0 / 20, 102 +- 104, 0.426, 0.532; happy at
    random on 30 % of the steps 0 / 20, 33 +- 48, 0.158, 0.527, on 70 % 0 / 20, 89 +- 91, 0.372,
    0.532; blind timed bids (every 2.5 s a 0.05-s bid, then a smile 1.0-1.8 s after it, where an
    answer is likeliest) 0 / 20, 18 +- 200, 0.175, 0.513 (its best episode: 0.754 matched);
    the scripted `ContingencyDetectorController` 19 / 20, 522 +- 72, 0.283, 0.928 (its lowest:
    0.913 matched; its one failure shared 0.197 of the steps). Held (`gaze_free=False`): the same
    figures. Before the fix (issue 30) the dip every 0.5 s scored 1851 and succeeded in 20 / 20. No
    trained learner yet
summary:
    `measures.condition_summary(episodes, seed, controller)` runs blocks of live, replay (of that
    block's live episode) and non-contingent episodes and returns each measure's mean and sd per
    condition (`format_summary` prints it); the scripted `ContingencyDetectorController`, 10 blocks,
    seeds 1000-1009 (`condition_summary(episodes=10, seed=1000)`; free gaze, the default; eyes off,
    or `mimo-social paradigm contingency --episodes 10 --seed 1000 --env-kwargs '{"per_agent":
    [{"vision": false}, {}]}'`), mean +- sd live / replay / non-contingent: share of the steps
    smiling 0.30 +- 0.04 / 0.17 +- 0.11 / 0.14 +- 0.08; smile onsets per second 0.66 / 0.48 / 0.40;
    response rate 0.81 +- 0.08 / 0.48 +- 0.26 / 0.38 +- 0.17; baseline rate 0.00 / 0.41 / 0.25;
    contingency index 0.81 +- 0.08 / 0.07 +- 0.45 / 0.12 +- 0.37; shared smiling 0.28 / 0.15 / 0.12
    of the steps; matched (shared of its smiling) 0.93 / 0.85 / 0.77; success 9 / 4 / 1 of 10;
    caregiver smile onsets per second 0.28 / 0.28 (the same stream) / 0.21; gaze on the face 0.99
    in each. The pattern Murray and Trevarthen report (fewer positive expressions when the same
    mother is replayed) shows in the share of the steps smiling and in the smile onsets. The index
    describes the contingency a learner meets, not whether it detects it: uniform random actions,
    bidding 12.8 times a second, find every bid answered within the window in live and in replay
    (index 1.00 in both; 0.40 non-contingent) and do not change their smiling (effects, below)
effects:
    `measures.effects(policy, episodes, seed, env_kwargs)` runs any policy as the learner (a
    scripted partner, a function `obs -> action`, or an SB3 model: its observation flattened or its
    images made channel-first and its flat action decoded as the model needs; `measures.as_learner`)
    in the blocks of `condition_summary` and returns, per block, the live episode's measure minus
    the replay's (`live_minus_replay`: Murray and Trevarthen's double video) and minus the
    non-contingent one's (`live_minus_non_contingent`), mean +- sd over blocks, for
    `smiling_fraction`, `learner_smile_rate`, `gaze_fraction`, `contingency_index` and
    `shared_fraction` (`format_effects` prints them). The reward pays shared smiling and charges
    unshared smiling in every condition: a learner that returns every smile it sees earns in replay
    too; the effects measure whether it smiles less, or looks away, there. Measured, 10 blocks of
    2000 steps (seeds 1000-1009, the learner's eyes off: no policy here reads them; free gaze, the
    default: `mimo-social paradigm contingency --episodes 10 --seed 1000 --env-kwargs '{"per_agent":
    [{"vision": false}, {}]}'`), live minus replay / live minus non-contingent: the scripted
    `ContingencyDetectorController` smiling +0.130 +- 0.090 / +0.161 +- 0.069 of the steps,
    contingency index +0.74 +- 0.42 / +0.69 +- 0.39, shared smiling +0.124 +- 0.085 / +0.153 +-
    0.065, smile onsets per second +0.17 / +0.26, gaze 0 (it looks at the face 0.99 of the steps in
    every condition: no gaze avoidance; its script has none); uniform random actions smiling +0.001
    +- 0.009 / +0.004 +- 0.012, contingency index +0.000 / +0.60 +- 0.25 (the caregiver's, see
    summary), shared +0.002 / +0.001 (no effect), gaze on the face 0.12 / 0.09 / 0.12 of the steps
    (live / replay / non-contingent), gaze effect +0.027 +- 0.043 / +0.002 +- 0.086, shared smiling
    0.01 of the live steps (0 of 10 successes); zero action 0 on every effect (gaze 0 in every
    condition)
sources:
    not in the MIMo paper: a paradigm of this package after Watson (1972, 1979: infants detect the
    contingency of events on their own behaviour, measured as conditional probabilities; the smile
    as the response to a contingent stimulus), Watson and Ramey (1972: contingent mobiles raise the
    infant's response rate), Murray and Trevarthen (1985: double video, 6-12-week-olds with their
    mothers live versus a replay of the same mother, which brought gaze avoidance and fewer positive
    expressions), Nadel et al. (1999, live-replay-live), Bigelow and Rochat (2006: 2-month-olds
    smile less to a partner whose contingency for smiles differs from their mother's). Response
    delay 0.3-1.3 s: prompt answers, about the 1-s resolution at which face-to-face interaction is
    coded (Beebe et al. 2016), drawn anew for each answer as a person's are, and well below the
    delays of a few seconds that keep young infants from learning a contingency (Millar 1972)
version history:
    v0, issue 19: first version, with `still_face_v0`, `imitation_v0` and the contingent and replay
    caregivers; v0, issue 30: the `gaze_free` option (at first off: the held gaze, spaces and
    numbers unchanged; the gaze measure was 1.0 for every learner), the scripted infant looks at the
    face when its gaze is free, `measures.effects` for any policy; v0, issue 30: `gaze_free` on by
    default; v0, issue 30 (the contingency fix): a blind face won (a one-step neutral dip every 0.5
    s, never looking at the caregiver's face, scored 1851 against the scripted infant's 665, and a
    face happy at random on 30-70 % of the steps, gaze held, succeeded), so the live caregiver's
    delay is drawn (0.3-1.3 s, was a fixed 0.5 s) and it is refractory, the reward charges unshared
    smiling (`unshared_cost`), success needs `success_match` of the learner's smiling shared, the
    response and baseline rates count bids, and the scripted infant bids briefly and returns the
    answers it sees (it held each bid up to 0.8 s); `unshared_cost=0`, `success_match=0`,
    `response_delay_s=0.5`, `response_jitter_s=0` give the old reward and success (the caregiver
    stays refractory)

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
