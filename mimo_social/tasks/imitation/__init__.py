"""Imitation: the learner reproduces an action its partner demonstrated, seen through its eyes.

agents:
    2: `infant_0` (the learner, an 18-month-old) and `caregiver_0` (the demonstrator: by default
    the adult caregiver, `body="adult"`, kneeling; an infant demonstrator, then named `infant_1`,
    with `per_agent=[{}, {"body": "infant"}]`, then standing); with `scripted_env` the
    demonstrator is the scripted `Demonstrator`, else a second learner
body:
    hip fixed in the world; every joint held but both arms (shoulder 3, elbow, wrist 3, mitten
    fingers each: 16 motors), `actuation="positional"` (the controls are target angles across each
    joint's range, `body/actuation/positional.py`: a pose is one action, so an act is a short
    sequence of poses; zero action = every arm joint at mid-range). The learner stands, its head and
    eyes held looking at its partner, tilted to centre its view between the partner's raised hand
    and the partner's box (`_learner_tilt`); the adult kneels, its head and eyes held on the
    learner's face (`tasks/dyad.py`)
scene:
    the pair face to face, `distance` (1.4 m) apart for two 18-month-olds, the kneeling adult 1.50 m
    away (the "gap" law of `tasks/dyad.py`: the same floor between their fronts); the whole
    demonstrator, from its raised hand to its box, is in the learner's 60-degree view: 1.5 s into
    the demonstration (the act held) each act has changed 137-264 of the 4096 pixels of the
    learner's left eye image (a channel by over 30 of 255) and any two acts differ in 122-363
    (`tests/tasks/test_imitation.py` checks over 100). Each agent has its own box (a cube of 0.2 arm
    lengths: 4.3 cm for the 18-month-old, 12 cm for the adult; yellow for the learner, blue for the
    demonstrator) on a fixed table to the right of its midline, its centre 0.45 arm lengths ahead
    of, 0.55 to the right of and 0.42 below its right shoulder (out of the way of the arm's other
    acts), the table reaching 0.85 arm lengths beyond it (the box slides without falling off)
reset:
    one action drawn uniformly (seeded) from `actions`; arms at rest (hanging), boxes at their
    start. Before the demonstration begins every episode looks the same to the learner (tested)
actions:
    `head_touch` (a hand on its own head), `hand_raise` (the right palm above the head), `clap` (the
    two hands together in front of the chest), `push_box` (its own box pushed away on its table): a
    gesture on the own body (Meltzoff and Moore 1977), an arm gesture, a two-handed gesture, and an
    act on an object (Meltzoff 1988); one pose (or two, for the push) of the arms each
    (`partners/demonstrator.py` `ACTION_POSES`, the same angles for the adult and the 18-month-old)
outcomes:
    per agent, from its own body only (`Outcomes`): `head_touch` a contact of either of its hands
    with its head; `hand_raise` its right palm over the top of its head by `RAISE_MARGIN` (0.2) head
    radii, not touching the head; `clap` a contact of its two hands; `push_box` its box slid `PUSH`
    (0.15) arm lengths away from it (3.2 cm for the 18-month-old, 8.8 cm for the adult) from where
    it started. An agent's *act* is the first step with an outcome; several outcomes on one step are
    an act of none of them (`response` 4)
episode:
    a demonstration phase of `demo_s` (2.5 s, 250 steps): the demonstrator holds still 0.3 s, moves
    its arms to the action's pose in 0.5 s per pose, holds it 1 s, moves back and holds still; then
    the learner's turn (the demonstrator still, holding its start pose) to the end, 3 s. The
    learner's box is put back at its start when its turn begins (a push during the demonstration is
    no act: as in the paradigm, the objects are handed to the infant only after the demonstration)
action:
    `Box(-1, 1, (16,))`: the learner's arm targets (positional; spring-damper and muscle actuation
    are allowed settings, the scripted agents need positional)
observation:
    `eye_left`, `eye_right` (64x64x3 RGB: the only way the demonstration reaches the learner),
    `proprioception` (96: its own arm joints, `[u, torque]` per motor and angles), `turn` (1: 0
    during the demonstration, 1 from the learner's turn on: the experimenter's "your turn"); with
    two learners also `instruction` (4: one-hot of the action to demonstrate for the
    demonstrator, zeros for `infant_0`)
reward:
    the learner: on its act in its turn, +1 if it is the demonstrated action's outcome alone, else
    `wrong_reward` (0; -10 to 0); nothing on any other step (sparse, once per episode). Two
    learners: the demonstrator the same for its first act in the demonstration phase against its
    `instruction`. `reward_free=True`: every reward 0, the measures (infos) kept
success:
    `is_success` (the learner): its act in its turn is the demonstrated action (the episode's
    verdict once it ends); the demonstrator's: its first act in the demonstration phase was the
    instructed one
termination:
    the learner's act in its turn ends the episode (its first act is its answer: acting out every
    action in turn earns only the first one's, so success is the return optimum and no fixed act or
    sweep earns more than the demonstrated action's share of the episodes); truncation at 550 steps
    (5.5 s)
infos:
    `demonstrated` (index into `ACTIONS`), `turn`, `outcomes` (this agent's outcomes this step, bit
    k = `ACTIONS[k]`), `response` (the learner's act: -1 none yet, 0-3, 4 several at once),
    `response_step` (steps into its turn), `demonstration` (the demonstrator's first act),
    `demonstration_outcomes` (every outcome the demonstrator produced in the demonstration phase,
    bits), `is_success`. `summary(records)` tabulates per demonstrated action the episodes, success
    rate, mean return and the responses (the paradigm's per-act scores) from `run_episodes`
options:
    `actions` (None: all four; or a list of names), `distance` (1.4 m, 0.4 to 3), `demo_s` (2.5 s,
    0.5 to 10; a shorter phase compresses the demonstrator's script), `wrong_reward` (0, -10 to 0),
    `scripted_partner` (False; set by `scripted_env`: the demonstrator has no eyes, no reward and no
    instruction), `reward_free` (False)
privileged cues:
    none: which action is demonstrated reaches the learner only through its eyes (`instruction` is
    zeros for it; observations at reset are identical whatever is drawn, tested); `turn` tells the
    phase, not the action. The scripted `ImitationController` reads the action from the task (an
    oracle baseline); the reward reads outcomes from the world
two learners:
    `parallel_env()`: `caregiver_0` (the adult by default) sees its `instruction` and is rewarded
    for demonstrating it, `infant_0` for reproducing the demonstrator's act; the same learner in
    both roles needs an infant demonstrator (`per_agent=[{}, {"body": "infant"}]`: both
    18-month-olds; the poses work for both bodies, tested)
baselines:
    scripted demonstrator, learner's eyes rendered, 30 episodes (seeds 1000-1029: head_touch 4,
    hand_raise 6, clap 15, push_box 5 demonstrated): scripted `ImitationController` (reads the
    action from the task, moves its arms through the action's poses in 0.3 s each) 30 / 30, return
    1.00, act 0.38 s into its turn; random 0 / 30 (act in 10: push_box 8, head_touch 1, clap 1),
    0.00; zero action 0 / 30 (no act), 0.00; always one act (`ImitationController(action=...)`):
    head_touch 4 / 30, hand_raise 6 / 30, clap 15 / 30, push_box 5 / 30, exactly the episodes in
    which it was demonstrated (over 200 draws, seeds 1000-1199: 41, 50, 59, 50: each about 1/4)
    (`mimo-social baselines imitation --episodes 30 --seed 1000`: random 3 / 30 (another random
    stream), zero 0 / 30, scripted 30 / 30, 117 s for the three on 2 shared cores; the fixed acts
    with `run_episodes(imitation_v0.scripted_env(), partner_policy(ImitationController(action=a)),
    30, seed=1000)` and `summary`). Random over 200 episodes (seeds 1000-1199, eyes off: they do not
    change what a random policy does): 13 / 200 (6.5 %), an act in 77 (push_box 53, clap 14,
    head_touch 10, hand_raise 0); its success when push_box was demonstrated 11 / 50. Learnt (issue
    30, sixth session; `mimo-social recipe imitation --seeds 0,1`, 30 episodes, seeds
    1000-1029): 100 % / 83 % and 100 % / 93 % (mean action / sampled; 20 episodes of
    `ImitationController(prepare=0.5, move_s=0.02)` cloned with DART noise into the CNN policy,
    the normaliser's scale floored at 0.01, PPO 60k with the cloning kept; docs/baselines.md)
sources:
    deferred imitation of acts on objects: 14-month-olds reproduce acts on objects, one of six of
    them novel, a week after watching an adult without touching the objects (Meltzoff 1988,
    Developmental Psychology 24(4), 470-476); the observation-only procedure (Klein and Meltzoff
    1999, Developmental Science 2(1), 102-113); imitation of facial and manual gestures by
    12-21-day-olds (Meltzoff and Moore 1977, Science 198, 75-78). The set of acts, the poses, the
    distance and the scoring are this package's (the paradigm scores the infant's acts per
    demonstrated act; here the first act in the turn)
version history:
    v0: first version (issue 19), with the scripted `Demonstrator` and the scripted learner
    `ImitationController`; four acts (head_touch, hand_raise, clap, push_box)

The demonstration and the turn are scored by the same outcome detectors (:class:`Outcomes`), which
read only each agent's own body and its own box: contacts of its hands with its head or with each
other, its right palm's height over its head, how far its box slid away from it.

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns a
:class:`~mimo_social.core.env.MimoParallelEnv` with two learners (``caregiver_0`` demonstrates the
action of its ``instruction``, ``infant_0`` reproduces it); ``env(...)`` the AEC version;
``scripted_env(partner=None, **kwargs)`` a one-learner env (``infant_0`` learns) whose demonstrator
``caregiver_0`` (the kneeling adult caregiver by default) is driven by a scripted
:class:`~mimo_social.partners.Partner`, by default
:class:`~mimo_social.tasks.imitation.demonstrator.Demonstrator` (the task option
``scripted_partner`` is set: the demonstrator has no eyes and no reward).
"""

from .task import (ACTIONS, Imitation, ImitationOptions, Outcomes, parallel_env, env, scripted_env)
from . import measures
from .controller import ImitationController
from .demonstrator import Demonstrator, ACTION_POSES, PoseScript

__all__ = ["measures", "ACTIONS", "Imitation", "ImitationOptions", "Outcomes", "parallel_env",
           "env", "scripted_env", "ImitationController", "Demonstrator", "ACTION_POSES",
           "PoseScript"]
