"""Vocal turn-taking: an infant's vocalisations with a caregiver who answers them, or speaks anyway.

agents:
    2: `infant_0` (the learner, an 18-month-old body) and `caregiver_0` (by default the adult
    body, kneeling; an infant partner, then named `infant_1`, with `per_agent=[{}, {"body":
    "infant"}]`). `scripted_env` drives the caregiver (`TurnTakingCaregiver`, below);
    `parallel_env` makes it a second learner (condition "contingent" only, no scripted answers)
body:
    as in `contingency_v0`: the learner stands, hip fixed, every joint held but (`gaze_free`,
    on) its head and eyes (9 motors, with head support: a zero action holds the head); the
    caregiver kneels, every joint held, head and eyes on the learner's face. Both have the voice
    (`voice=True`); expressions, vision and the vestibular sense are off by default (a vocal
    paradigm; turn them on per agent)
scene:
    the pair face to face as in `contingency_v0` (`distance` 0.3 m between two infants; the
    kneeling adult placed by its arm's reach)
conditions:
    option `condition`, or `env.unwrapped.task.set_condition(name)` from the next reset on.
    **contingent**: the scripted caregiver answers each offset of the infant's vocalisations
    (any non-silent kind, its sound as the last step left it, read from `env.sounds`) that
    finds it silent with no answer pending, with probability `response_probability` (0.8), by
    "speech" of `utterance_s` (1 s) at loudness `caregiver_loudness` (0.25: 60 dB at 1 m), after
    a latency drawn from a lognormal distribution of mean `latency_mean_s` (0.7 s) and sd
    `latency_sd_s` (0.3 s), counted from the offset in whole control steps (it hears the offset
    one control step after it happens). **noncontingent**: as many utterances as it made in this
    env's last contingent episode, at uniformly random, non-overlapping times drawn at reset
    (yoked, as Goldstein et al.'s control group); before any contingent episode a Poisson process
    of `timer_rate_hz` (0.25 per second of silence). **replay**: the utterances of this env's last
    contingent episode (or `scripted_env(onsets=...)`), at the same steps, whatever the infant
    does (as contingency's replay). In noncontingent and replay nothing the infant does changes
    the caregiver (tested: the same schedule whether the infant vocalises or not). Two learners:
    "contingent" only (the caregiver is the other learner; the others need the script: a
    ConfigError)
reset:
    both silent; nothing random in the task (the scripted caregiver draws its answers, latencies
    and non-contingent times from the env's seed)
action:
    `Dict(motors=Box(-1, 1, (9,)), voice=Discrete(6), loudness=Box(0, 1, (1,)))`: its head and
    eye motors (held, `gaze_free=False`: `Box(0,)`), a kind of `SOUNDS` (silence, coo, babble,
    cry, laugh, speech) and its loudness; `expression` too with `expressions=True`
observation:
    `proprioception` (its head and eye joints) and `audition` (one row per voiced agent, itself
    included: the kind one-hot, the level at each ear, ILD, ITD; `mimo_social.senses.audition`):
    the caregiver reaches the learner only through its ears; never the caregiver's schedule,
    condition or latencies
reward:
    +1 on the step the caregiver answers: a caregiver utterance begins within `window_s` (1 s) of
    the offset of the learner's vocalisation of at least `min_vocal_s` (0.2 s), the learner
    silent in between (our choice: infants
    find answers rewarding, and the answer is what the paradigm manipulates); the same rule in
    every condition, so a learner that vocalises more in the contingent condition does so because
    answers follow there, not because vocalising is paid; with `reward_free` (False) 0 on every
    step, every measure still in the infos. Two learners: each is paid the same answer events
success:
    per episode: `is_success` becomes True on the step at which the answers reach
    `success_answers` (10 in the 60-s episode); meant for the contingent condition (in the others
    answers come by chance and success is reported, not a goal)
termination:
    none; truncation at 6000 steps (60 s, our choice: the scripted infant's rate effect needs
    about a minute to show)
infos:
    `condition` (0 contingent, 1 noncontingent, 2 replay), `infant_sound` and `caregiver_sound`
    (this step's kind ids), `answer` (an answer began this step), `answers` (so far),
    `infant_vocalisations`, `infant_rate_per_min`, `vocal_fraction`, `speech_like_fraction` (babble
    or speech among the infant's vocalisations), `cry_fraction`, `caregiver_utterances`,
    `caregiver_rate_per_min`, `mean_latency_s` (caregiver onsets after an infant offset, answered or
    not), `answered_fraction` (of the infant's resolved vocalisations of at least `min_vocal_s`,
    answered within `window_s`), `turns` (answers plus infant onsets within `window_s` of a
    caregiver offset), `infant_turns`, `mean_turn_gap_s`, `is_success` (definitions:
    `mimo_social/tasks/turn_taking/turns.py`)
options:
    `condition` ("contingent", "noncontingent", "replay"; "replay" when the env is made needs
    `scripted_env(onsets=...)`), `distance` (0.3 m, 0.25 to 2.0), `latency_mean_s` (0.7, 0.01 to
    10), `latency_sd_s` (0.3, 0 to 10; 0: a constant latency), `response_probability` (0.8, 0 to 1),
    `utterance_s` (1.0, 0.01 to 10), `caregiver_loudness` (0.25, 0 to 1), `timer_rate_hz` (0.25, 0
    to 10), `window_s` (1.0, 0.05 to 10), `min_vocal_s` (0.2, 0.01 to 5: shorter vocalisations
    are never answers), `success_answers` (10, 1 to 10000), `reward_free`
    (False), `gaze_free` (True), `scripted_partner` (False; set by `scripted_env`)
privileged cues:
    none: the caregiver's voice reaches the learner only through its ears (`audition`); the
    reward and the measures read both agents' sounds from the world (`env.sounds`, no
    observation)
baselines:
    contingent, 20 episodes of 6000 steps, seeds 1000-1019 (`mimo-social baselines turn_taking
    --episodes 20 --seed 1000`): uniform random actions (a new kind each step: its vocalisations
    rarely last `min_vocal_s`) 0 / 20 successes, return 0.15 +- 0.65 (3 / 20, 6.05 +- 2.77
    before `min_vocal_s`); zero action (silence) 0 / 20, 0 +- 0 (never answered); scripted
    `TurnTakingInfantController` 19 / 20, 13.8 +- 2.62, success at step 4386 on average (the same
    figures with the learner's audition on and off: no policy here reads it). A hack and an
    upper bound, same seeds (`python tests/tasks/test_turn_taking.py`): babbling on every step 0
    / 20, 0 answers (no offset, nothing to answer); babble switched on and off at random each
    step (64 % on: the PPO pilot's hack, version history) 0 / 20, 0; 0.2 s of babble whenever
    both have been silent 1.5 s 20 / 20, 13.45 +- 1.4 answers, and 0.3 s 20 / 20, 15.25 +- 1.6:
    the reward's optimum is to vocalise and leave the turn, i.e. uses the contingency. Learner
    (recipe `turn_taking`, `mimo-social recipe turn_taking --seeds 0,1`, 30 episodes): echoic
    memory on (audition `memory_s` 2), gaze held (the action: the sound kind), a warm start
    cloned from 20 scripted episodes, PPO 200k steps with the cloning kept: sampled 100 % in
    both seeds (return 18.7, 16.7), the most likely sound 0 % (silence), 12 min a seed; plain
    PPO, 1M steps, no memory: 0 % both ways (docs/training/issue30/recipes/turn_taking*)
summary:
    `measures.run` / `measures.effects` run blocks of a contingent, a non-contingent (yoked to
    the block's contingent episode) and a replay episode; measured, 10 blocks, seeds 1000-1009
    (`mimo-social paradigm turn_taking --learner scripted random zero --episodes 10 --seed
    1000`), the scripted infant, mean +- sd, contingent / noncontingent / replay: vocalisations
    per minute 21.6 +- 1.9 / 16.3 +- 4.1 / 18.8 +- 3.3; speech-like share 0.78 +- 0.07 / 0.52 +-
    0.10 / 0.56 +- 0.16; answered within 1 s 0.68 +- 0.11 / 0.27 +- 0.07 / 0.41 +- 0.11; turns
    27.9 / 11.2 / 18.4, mean turn gap 0.52 / 0.40 / 0.46 s; caregiver utterances per minute 16.9
    in each (yoked and replayed: the same count); mean latency of caregiver onsets after an
    infant offset 0.69 +- 0.05 s (contingent: the configured 0.7 s) / 1.31 / 0.94; success 10 /
    0 / 3 of 10. Effect per block, contingent minus noncontingent / minus replay: vocalisations
    per minute +5.3 +- 3.6 / +2.8 +- 4.0, speech-like share +0.26 +- 0.16 / +0.22 +- 0.16,
    answered share +0.41 +- 0.09 / +0.28 +- 0.12, turns +16.7 +- 5.0 / +9.5 +- 5.3. Uniform
    random actions: never answered (0.00 in every condition) and no effect on the speech-like share
    (+0.01 / +0.005; 0.40 in each condition, 2 of 5 kinds), its vocalisations per minute (about
    840: a new kind nearly every step) +12 +- 16 / +18 +- 23 (noise); zero action 0 on every
    measure. The caregiver's latencies, as scheduled, follow the configured lognormal
    (`tests/tasks/test_turn_taking.py`, a Kolmogorov-Smirnov check; `measures.latencies`).
    Learnt infants (the recipe's two seeds, sampled actions, 10 blocks, seeds 1000-1009:
    `mimo-social paradigm turn_taking --learner RUN0 RUN1 --stochastic --episodes 10 --seed
    1000`; docs/training/issue30/recipes/turn_taking/paradigm.md): contingent minus
    noncontingent / minus replay, seed 0 and seed 1: answered share +0.24 and +0.30 / +0.06 and
    +0.19, turns +10.9 and +12.4 / +2.0 and +5.6, speech-like share +0.10 and +0.11 / -0.01 and
    +0.05; vocalisations per minute -1.8 and -0.9 / -0.2 and -1.0 (27-34 a minute in every
    condition): unlike the scripted infant, whose rule raises its rate within the episode as
    answers come, the learnt policy is the same in every condition (it does not learn within an
    episode), so it takes more turns where answers come but does not vocalise more
sources:
    not in the MIMo paper: a paradigm of this package after Goldstein, King and West (2003, PNAS
    100:8030-8035: mothers of 8-month-olds answered their babbling contingently or, in a yoked
    control group, at the same times regardless of the infant; only contingent answers brought more
    mature, syllabic vocalisations) and Bloom (1988, J Child Lang: 3-month-olds with an
    adult who took turns, against random responsiveness, vocalised in a speak-listen pattern, and
    verbal turns raised the share of syllabic sounds). Answers from the offset of the infant's
    vocalisation: mothers vocalise contingent on the offset of their infants' non-distress
    vocalising (Bornstein et al. 2015, Child Dev, 684 dyads in 11 countries);
    caregivers take turns with protophones (Yoo, Bowman and Oller 2018, Front Psychol 9:1510).
    Latency 0.7 +- 0.3 s, probability 0.8, utterances of 1 s, loudness and the infant's rule: our
    choice (answers within about a second; `infant.py` gives the rule's values)
version history:
    v0, issue 33: first version; the same day, before any release, `min_vocal_s`: a PPO pilot
    (300k steps, seed 0) found that a voice flickering on and off (about 770 onsets a minute) was
    "answered" 14.4 times a minute live and 13.4 with the non-contingent caregiver (success in
    both: a recent offset precedes every utterance by chance); with vocalisations of 0.2 s at
    least, it is not (baselines)
"""

from .task import (CONDITIONS, MEASURES, TurnTakingOptions, TurnTaking, TurnTakingCaregiver,
                   parallel_env, env, scripted_env)
from . import measures
from .controller import TurnTakingInfantController

__all__ = ["measures", "CONDITIONS", "MEASURES", "TurnTakingOptions", "TurnTaking",
           "TurnTakingCaregiver", "parallel_env", "env", "scripted_env",
           "TurnTakingInfantController"]
