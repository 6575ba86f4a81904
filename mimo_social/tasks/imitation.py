"""Imitation: the learner reproduces an action its partner demonstrated, seen through its eyes.

| | |
|---|---|
| agents | 2: `infant_0` (the learner, an 18-month-old) and `infant_1` (the demonstrator: by default the adult caregiver, `body="adult"`, kneeling; an infant demonstrator with `per_agent=[{}, {"body": "infant"}]`, then standing); with `scripted_env` `infant_1` is the scripted `Demonstrator`, else a second learner |
| body | hip fixed in the world; every joint held but both arms (shoulder 3, elbow, wrist 3, mitten fingers each: 16 motors), `actuation="positional"` (the controls are target angles across each joint's range, `body/actuation/positional.py`: a pose is one action, so an act is a short sequence of poses; zero action = every arm joint at mid-range). The learner stands, its head and eyes held looking at its partner, tilted to centre its view between the partner's raised hand and the partner's box (`_learner_tilt`); the adult kneels, its head and eyes held on the learner's face (`tasks/dyad.py`) |
| scene | the pair face to face, `distance` (1.4 m) apart for two 18-month-olds, the kneeling adult 1.50 m away (the "gap" law of `tasks/dyad.py`: the same floor between their fronts); the whole demonstrator, from its raised hand to its box, is in the learner's 60-degree view: 1.5 s into the demonstration (the act held) each act has changed 137-264 of the 4096 pixels of the learner's left eye image (a channel by over 30 of 255) and any two acts differ in 122-363 (`tests/tasks/test_imitation.py` checks over 100). Each agent has its own box (a cube of 0.2 arm lengths: 4.3 cm for the 18-month-old, 12 cm for the adult; yellow for the learner, blue for the demonstrator) on a fixed table to the right of its midline, its centre 0.45 arm lengths ahead of, 0.55 to the right of and 0.42 below its right shoulder (out of the way of the arm's other acts), the table reaching 0.85 arm lengths beyond it (the box slides without falling off) |
| reset | one action drawn uniformly (seeded) from `actions`; arms at rest (hanging), boxes at their start. Before the demonstration begins every episode looks the same to the learner (tested) |
| actions | `head_touch` (a hand on its own head), `hand_raise` (the right palm above the head), `clap` (the two hands together in front of the chest), `push_box` (its own box pushed away on its table): a gesture on the own body (Meltzoff and Moore 1977), an arm gesture, a two-handed gesture, and an act on an object (Meltzoff 1988); one pose (or two, for the push) of the arms each (`partners/demonstrator.py` `ACTION_POSES`, the same angles for the adult and the 18-month-old) |
| outcomes | per agent, from its own body only (`Outcomes`): `head_touch` a contact of either of its hands with its head; `hand_raise` its right palm over the top of its head by `RAISE_MARGIN` (0.2) head radii, not touching the head; `clap` a contact of its two hands; `push_box` its box slid `PUSH` (0.15) arm lengths away from it (3.2 cm for the 18-month-old, 8.8 cm for the adult) from where it started. An agent's *act* is the first step with an outcome; several outcomes on one step are an act of none of them (`response` 4) |
| episode | a demonstration phase of `demo_s` (2.5 s, 250 steps): the demonstrator holds still 0.3 s, moves its arms to the action's pose in 0.5 s per pose, holds it 1 s, moves back and holds still; then the learner's turn (the demonstrator still, holding its start pose) to the end, 3 s. The learner's box is put back at its start when its turn begins (a push during the demonstration is no act: as in the paradigm, the objects are handed to the infant only after the demonstration) |
| action | `Box(-1, 1, (16,))`: the learner's arm targets (positional; spring-damper and muscle actuation are allowed settings, the scripted agents need positional) |
| observation | `eye_left`, `eye_right` (64x64x3 RGB: the only way the demonstration reaches the learner), `proprioception` (96: its own arm joints, `[u, torque]` per motor and angles), `turn` (1: 0 during the demonstration, 1 from the learner's turn on: the experimenter's "your turn"); with two learners also `instruction` (4: one-hot of the action to demonstrate for `infant_1`, zeros for `infant_0`) |
| reward | the learner: on its act in its turn, +1 if it is the demonstrated action's outcome alone, else `wrong_reward` (0; -10 to 0); nothing on any other step (sparse, once per episode). Two learners: the demonstrator the same for its first act in the demonstration phase against its `instruction`. `reward_free=True`: every reward 0, the measures (infos) kept |
| success | `is_success` (the learner): its act in its turn is the demonstrated action (the episode's verdict once it ends); the demonstrator's: its first act in the demonstration phase was the instructed one |
| termination | the learner's act in its turn ends the episode (its first act is its answer: acting out every action in turn earns only the first one's, so success is the return optimum and no fixed act or sweep earns more than the demonstrated action's share of the episodes); truncation at 550 steps (5.5 s) |
| infos | `demonstrated` (index into `ACTIONS`), `turn`, `outcomes` (this agent's outcomes this step, bit k = `ACTIONS[k]`), `response` (the learner's act: -1 none yet, 0-3, 4 several at once), `response_step` (steps into its turn), `demonstration` (the demonstrator's first act), `demonstration_outcomes` (every outcome the demonstrator produced in the demonstration phase, bits), `is_success`. `summary(records)` tabulates per demonstrated action the episodes, success rate, mean return and the responses (the paradigm's per-act scores) from `run_episodes` |
| options | `actions` (None: all four; or a list of names), `distance` (1.4 m, 0.4 to 3), `demo_s` (2.5 s, 0.5 to 10; a shorter phase compresses the demonstrator's script), `wrong_reward` (0, -10 to 0), `scripted_partner` (False; set by `scripted_env`: the demonstrator has no eyes, no reward and no instruction), `reward_free` (False) |
| privileged cues | none: which action is demonstrated reaches the learner only through its eyes (`instruction` is zeros for it; observations at reset are identical whatever is drawn, tested); `turn` tells the phase, not the action. The scripted `ImitationController` reads the action from the task (an oracle baseline); the reward reads outcomes from the world |
| two learners | `parallel_env()`: `infant_1` (the adult by default) sees its `instruction` and is rewarded for demonstrating it, `infant_0` for reproducing the demonstrator's act; the same learner in both roles needs an infant demonstrator (`per_agent=[{}, {"body": "infant"}]`: both 18-month-olds; the poses work for both bodies, tested) |
| baselines | scripted demonstrator, learner's eyes rendered, 30 episodes (seeds 1000-1029: head_touch 4, hand_raise 6, clap 15, push_box 5 demonstrated): scripted `ImitationController` (reads the action from the task, moves its arms through the action's poses in 0.3 s each) 30 / 30, return 1.00, act 0.38 s into its turn; random 0 / 30 (act in 10: push_box 8, head_touch 1, clap 1), 0.00; zero action 0 / 30 (no act), 0.00; always one act (`ImitationController(action=...)`): head_touch 4 / 30, hand_raise 6 / 30, clap 15 / 30, push_box 5 / 30, exactly the episodes in which it was demonstrated (over 200 draws, seeds 1000-1199: 41, 50, 59, 50: each about 1/4) (`mimo-social baselines imitation --episodes 30 --seed 1000`: random 3 / 30 (another random stream), zero 0 / 30, scripted 30 / 30, 117 s for the three on 2 shared cores; the fixed acts with `run_episodes(imitation_v0.scripted_env(), partner_policy(ImitationController(action=a)), 30, seed=1000)` and `summary`). Random over 200 episodes (seeds 1000-1199, eyes off: they do not change what a random policy does): 13 / 200 (6.5 %), an act in 77 (push_box 53, clap 14, head_touch 10, hand_raise 0); its success when push_box was demonstrated 11 / 50 |
| sources | deferred imitation of acts on objects: 14-month-olds reproduce acts on objects, one of six of them novel, a week after watching an adult without touching the objects (Meltzoff 1988, Developmental Psychology 24(4), 470-476); the observation-only procedure (Klein and Meltzoff 1999, Developmental Science 2(1), 102-113); imitation of facial and manual gestures by 12-21-day-olds (Meltzoff and Moore 1977, Science 198, 75-78). The set of acts, the poses, the distance and the scoring are this package's (the paradigm scores the infant's acts per demonstrated act; here the first act in the turn) |
| version history | v0: first version (issue 19), with the scripted `Demonstrator` and the scripted learner `ImitationController`; four acts (head_touch, hand_raise, clap, push_box) |

The demonstration and the turn are scored by the same outcome detectors (:class:`Outcomes`),
which read only each agent's own body and its own box: contacts of its hands with its head or
with each other, its right palm's height over its head, how far its box slid away from it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from ..body.joint_groups import both_arms_joints, held_posture
from ..core.kinematics import hand_geoms
from ..core.task import Plot, Task, TaskOptions
from ..core.world import AgentSetup, Prop
from ..util.checks import ConfigError
from .common import ContactProbe, face_to_face
from .dyad import held_angles, measure, tables_of, task_plan

__all__ = ["ACTIONS", "Imitation", "ImitationOptions", "Outcomes", "summary"]

#: the demonstrated actions, in the order of the outcome vector and the ``instruction``
ACTIONS = ("head_touch", "hand_raise", "clap", "push_box")
DISTANCE = 1.4        # m between two standing 18-month-olds (scaled for other bodies)
EYE_SIZE = 64
DEMO_S = 2.5          # s: the demonstration phase
MAX_STEPS = 550       # 2.5 s demonstration + 3 s turn at 10 ms a step
RAISE_MARGIN = 0.2    # head radii: how far the right palm must be over the top of the head
#: each agent's box (a cube) and the fixed table under it, in the agent's own frame (forward,
#: left, up) from its right shoulder, in lengths of its (straight) right arm: the box to the
#: right of its midline, below its shoulder, within reach of a forward push
BOX_CENTRE = (0.45, -0.55, -0.42)
BOX_HALF = 0.1
TABLE_HALF = (0.5, 0.15, 0.03)     # the table top, centred under the box, forward reaching on
TABLE_AHEAD = 0.35                 # the table's centre this far ahead of the box's
BOX_MASS = 0.05                    # kg for the 18-month-old's box; the arm ratio cubed else
PUSH = 0.15                        # arm lengths: how far the box must slide away to count
BOX_RGBA = ((0.95, 0.75, 0.1, 1.0), (0.2, 0.45, 0.95, 1.0))
TABLE_RGBA = (0.55, 0.4, 0.25, 1.0)
STANDARD_ARM = 0.2155              # m: the 18-month-old's straight right arm (dyad.measure)
#: the response of a step on which several outcomes came at once
SEVERAL = len(ACTIONS)


@dataclass(frozen=True)
class ImitationOptions(TaskOptions):
    """The demonstrated actions (names from :data:`ACTIONS`; one is drawn per episode), the
    distance between the agents (m, for two 18-month-olds; scaled for other bodies), the
    demonstration's length (s), the reward for a wrong action (<= 0), whether ``infant_1`` is
    a scripted demonstrator (no eyes, no reward) and reward-free mode (rewards 0, measures
    kept)."""

    task = "imitation"
    actions: tuple | None = None
    distance: float = DISTANCE
    demo_s: float = DEMO_S
    wrong_reward: float = 0.0
    scripted_partner: bool = False
    reward_free: bool = False

    def __post_init__(self):
        self._names("actions", "action names")
        bad = [a for a in self.actions or () if a not in ACTIONS]
        if bad:
            raise ConfigError(f"imitation: actions {bad} unknown; allowed: None (all) or a "
                              f"non-empty list of distinct names from {list(ACTIONS)}")
        self._number("distance", 0.4, 3.0)
        self._number("demo_s", 0.5, 10.0)
        self._number("wrong_reward", -10.0, 0.0)
        self._bool("scripted_partner")
        self._bool("reward_free")


class Outcomes:
    """The outcome detectors of every action, for every agent, from its own body only:

    - ``head_touch``: a hand (either) of the agent in contact with its own head (head geom);
    - ``hand_raise``: its right palm at least :data:`RAISE_MARGIN` head radii above the top of
      its head, the hand not touching the head;
    - ``clap``: its two hands in contact with each other;
    - ``push_box``: its own box slid at least :data:`PUSH` arm lengths away from it (along its
      forward direction) from where it started.

    Index tables are resolved once; a call is a few gathers over the contacts."""

    def __init__(self, world, forward=None, arm=None):
        m = world.model
        #: per agent: the box's free-joint qpos address (-1: no box), its forward direction and
        #: the distance it must slide (m)
        self.box_q, self.forward, self.push = [], [], []
        self.head_touch, self.clap = [], []
        self.head_geom, self.head_radius, self.palm, self.margin = [], [], [], []
        for i, a in enumerate(world.agents):
            right, left = hand_geoms(world, i, 0), hand_geoms(world, i, 1)
            self.head_touch.append(ContactProbe(m.ngeom, np.concatenate([right, left]),
                                                [a.head_geom]))
            self.clap.append(ContactProbe(m.ngeom, right, left))
            self.head_geom.append(int(a.head_geom))
            self.head_radius.append(float(m.geom_rbound[a.head_geom]))
            self.palm.append(int(a.palm_sites[0]))
            self.margin.append(RAISE_MARGIN * float(m.geom_rbound[a.head_geom]))
            box = world.prop_qpos.get(f"box_{i}", -1)
            self.box_q.append(int(box))
            self.forward.append(np.asarray(forward[i] if forward else (1.0, 0.0), float))
            self.push.append(PUSH * (arm[i] if arm else STANDARD_ARM))
        self.start = [world.data.qpos[q:q + 2].copy() if q >= 0 else None for q in self.box_q]

    def box_slid(self, data, i: int) -> float:
        """How far (m) agent i's box slid away from it (along its forward direction) since its
        start; 0 without a box."""
        q = self.box_q[i]
        if q < 0:
            return 0.0
        return float((data.qpos[q:q + 2] - self.start[i]) @ self.forward[i])

    def __call__(self, data, i: int) -> np.ndarray:
        """Agent ``i``'s outcomes this step: a bool per action of :data:`ACTIONS`."""
        touch = self.head_touch[i](data)
        top = data.geom_xpos[self.head_geom[i], 2] + self.head_radius[i]
        raised = data.site_xpos[self.palm[i], 2] > top + self.margin[i] and not touch
        pushed = self.box_slid(data, i) >= self.push[i]
        return np.array([touch, raised, self.clap[i](data), pushed], bool)


def bits(flags) -> int:
    """Outcome flags as an integer (bit k: :data:`ACTIONS` [k])."""
    return int(sum(1 << k for k, f in enumerate(flags) if f))


def first_act(flags) -> int:
    """The act of a step with outcomes ``flags``: the action's index, or :data:`SEVERAL` when
    more than one outcome came at once (which counts as no action in particular)."""
    on = np.flatnonzero(flags)
    return int(on[0]) if len(on) == 1 else SEVERAL


class Imitation(Task):
    name = "imitation"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = MAX_STEPS
    Options = ImitationOptions

    def __init__(self, n_agents: int = 2, options=None, /, **values):
        super().__init__(n_agents, options, **values)
        acts = self.options.actions or ACTIONS
        #: indices into ACTIONS of the actions this env demonstrates
        self.action_ids = np.array([ACTIONS.index(a) for a in acts], np.intp)
        self.demonstrated = -1     # index into ACTIONS of this episode's action
        self.step_count = 0

    # -- building ------------------------------------------------------------------------------
    def agent_defaults(self, i, settings):
        scripted = i == 1 and self.options.scripted_partner
        out = {"posture": "standing", "expressions": False, "vestibular": False,
               "actuation": "positional",
               "vision": False if scripted else {"width": EYE_SIZE, "height": EYE_SIZE}}
        if i == 1 and settings.get("body", "adult") == "adult":
            out.update(body="adult", posture="kneeling")
        return out

    def _held(self, i, config):
        """Agent i's held joints (rad): all but both arms; standing knees a little bent (an
        18-month-old), or its own posture's angles (a kneeling adult)."""
        tables = tables_of(config)
        angles = held_angles(config, "standing", {"right_knee": -5, "left_knee": -5})
        return held_posture(tables, keep=both_arms_joints(tables), angles=angles)

    def setup(self, i, config):
        plan = task_plan(self, "standing", self.options.distance, self._held, (0, 1), law="gap")
        self.pair_distance = plan.distance
        pos, facing = face_to_face(i, plan.distance)
        frozen = {**self._held(i, config), **plan.gaze[i]}
        if i == 0:
            frozen.update(self._learner_tilt(plan, frozen))
        arms = both_arms_joints(tables_of(config))
        self._place_box(i, config, frozen, config.position or pos, config.facing or facing)
        return AgentSetup(config, position=config.position or pos,
                          facing=config.facing or facing, frozen=frozen, base="fixed",
                          actuated=arms)

    def _learner_tilt(self, plan, frozen) -> dict:
        """The learner's head tilt (rad) that centres its view between its partner's raised
        hand (the partner's shoulder height plus its arm) and its partner's box: the head held
        by the pair's plan (looking at the partner's face) tilted by the difference of the two
        elevations, seen from the learner's head."""
        configs = tuple(getattr(self, "configs", ()) or ())
        if len(configs) != 2:
            return {}
        e0 = measure(configs[0], self._held(0, configs[0]))
        e1 = measure(configs[1], self._held(1, configs[1]))
        far = plan.distance - e0.head[0]

        def elevation(x_own, z):     # a point x_own ahead of the partner's hip, at height z
            return np.arctan2(z - e0.head[2], far - x_own)

        face = elevation(e1.head[0], e1.head[2])
        hand = elevation(e1.shoulder[0], e1.shoulder[2] + e1.arm)
        box = elevation(e1.shoulder[0] + BOX_CENTRE[0] * e1.arm,
                        e1.shoulder[2] + BOX_CENTRE[2] * e1.arm)
        return {"head_tilt": float(frozen.get("head_tilt", 0.0) + face - 0.5 * (hand + box))}

    def _place_box(self, i, config, frozen, position, facing):
        """Agent i's box and table (:data:`BOX_CENTRE` ..., from its measured right shoulder and
        arm), in the world frame; and the box's forward direction (unit, x y)."""
        e = measure(config, frozen)
        p, f = np.asarray(position, float), np.asarray(facing, float)
        fwd = (f - p) / max(np.linalg.norm(f - p), 1e-9)
        left = np.array([-fwd[1], fwd[0]])

        def world(x, y, z):
            xy = p + x * fwd + y * left
            return (float(xy[0]), float(xy[1]), float(z))

        A = e.arm
        sh = np.array(e.shoulder)
        c = sh + A * np.array(BOX_CENTRE)
        half = BOX_HALF * A
        top = c[2] - half
        t = (c[0] + TABLE_AHEAD * A, c[1], top - TABLE_HALF[2] * A)
        size = tuple(float(h * A) for h in TABLE_HALF)
        if abs(fwd[1]) > abs(fwd[0]):      # an axis-aligned table: swap its sides
            size = (size[1], size[0], size[2])
        mass = BOX_MASS * (A / STANDARD_ARM) ** 3
        if not hasattr(self, "_box_props"):
            self._box_props = [None, None]
            self.box_forward = [None, None]
            self.arm = [None, None]
        self._box_props[i] = (
            Prop(f"table_{i}", "box", size, world(*t), 1.0, TABLE_RGBA, fixed=True),
            Prop(f"box_{i}", "box", (half,) * 3, world(*c), mass, BOX_RGBA[i]))
        self.box_forward[i] = fwd
        self.arm[i] = A

    def props(self):
        if "push_box" not in (self.options.actions or ACTIONS):
            return []
        return [p for pair in self._box_props for p in pair]

    def task_spaces(self, env, i):
        out = {"turn": spaces.Box(0.0, 1.0, (1,), np.float32)}
        if self.two_learners:
            out["instruction"] = spaces.Box(0.0, 1.0, (len(ACTIONS),), np.float32)
        return out

    @property
    def two_learners(self) -> bool:
        return not self.options.scripted_partner

    # -- running -------------------------------------------------------------------------------
    def reset(self, env, rng):
        w = env.world
        if not hasattr(self, "_outcomes"):
            self._outcomes = Outcomes(w, getattr(self, "box_forward", None),
                                      getattr(self, "arm", None))
            q = self._outcomes.box_q[0]
            self._box_start = w.data.qpos[q:q + 7].copy() if q >= 0 else None
            self._dt = float(env.dt)
        self._allowed = np.zeros(len(ACTIONS), bool)
        self._allowed[self.action_ids] = True
        self._weights = np.array([1.0, 0.0 if self.options.scripted_partner else 1.0])
        self.demo_steps = max(1, int(round(self.options.demo_s / self._dt)))
        self.demonstrated = int(self.action_ids[rng.integers(len(self.action_ids))])
        self.step_count = 0
        self.response = -1          # the learner's response (index into ACTIONS), -1: none yet
        self.response_step = -1     # steps into the turn at which it came
        self.demo_response = -1     # the demonstrator's first act in the demonstration phase
        self.demo_done = False      # ... was the demonstrated action's outcome alone
        self.demo_first = -1        # step at which it came
        self.demo_outcomes = 0      # every outcome of the demonstrator in the phase (bits)
        self.success = False
        self._flags = np.zeros((2, len(ACTIONS)), bool)
        self._ended = False

    @property
    def demonstrated_action(self) -> str:
        """The name of this episode's demonstrated action (what scripted agents read)."""
        return ACTIONS[self.demonstrated] if self.demonstrated >= 0 else ""

    @property
    def turn(self) -> bool:
        """Whether the learner's turn has begun (after the demonstration phase)."""
        return self.step_count >= self.demo_steps

    def before_physics(self, env):
        self.step_count += 1
        if self.step_count == self.demo_steps and self._box_start is not None:
            # the learner's turn begins with its box where it started (the objects presented
            # anew): a push during the demonstration does not count as its act
            env.world.place_prop("box_0", self._box_start[:3], self._box_start[3:7])

    def observe(self, env, i):
        out = {"turn": np.array([1.0 if self.turn else 0.0], np.float32)}
        if self.two_learners:
            ins = np.zeros(len(ACTIONS), np.float32)
            if i == 1 and self.demonstrated >= 0:
                ins[self.demonstrated] = 1.0
            out["instruction"] = ins
        return out

    def rewards(self, env):
        d = env.world.data
        for i in range(2):
            self._flags[i] = self._outcomes(d, i) & self._allowed
        r = np.zeros(2)
        k = self.demonstrated
        if not self.turn:
            # the demonstrator's first act of the demonstration phase is its demonstration
            self.demo_outcomes |= bits(self._flags[1])
            if self.demo_response < 0 and self._flags[1].any():
                self.demo_response = first_act(self._flags[1])
                self.demo_done = self.demo_response == k
                self.demo_first = self.step_count
                r[1] = 1.0 if self.demo_done else self.options.wrong_reward
        elif self.response < 0 and self._flags[0].any():
            # the learner's first act in its turn is its response; the episode ends with it
            self.response = first_act(self._flags[0])
            self.success = self.response == k
            self.response_step = self.step_count - self.demo_steps
            r[0] = 1.0 if self.success else self.options.wrong_reward
            self._ended = True
        if self.options.reward_free:
            return np.zeros(2)
        return r * self._weights

    def plots(self):
        """Reward, the learner's turn (0: the demonstration), its response (the action's index,
        -1 none yet) and success (learner: the demonstrated action; demonstrator: its
        demonstration)."""
        return [Plot.reward(),
                Plot("turn", "0/1", lambda env: self.turn, per_agent=False),
                Plot("response", "action, -1 none", lambda env: self.response,
                     per_agent=False),
                Plot("success", "0/1", lambda env: (self.success, self.demo_done))]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"demonstrated": "number", "turn": "number", "outcomes": "number",
                "response": "number", "response_step": "number",
                "demonstration": "number", "demonstration_outcomes": "number",
                "is_success": "number"}

    def terminations(self, env):
        infos = [{"demonstrated": self.demonstrated, "turn": self.turn,
                  "outcomes": bits(self._flags[i]), "response": self.response,
                  "response_step": self.response_step, "demonstration": self.demo_response,
                  "demonstration_outcomes": self.demo_outcomes,
                  "is_success": self.success if i == 0 else self.demo_done}
                 for i in range(2)]
        return np.full(2, self._ended), infos


# -- summaries ---------------------------------------------------------------------------------
def run_episodes(env, policy, episodes: int, seed: int = 0) -> list[dict]:
    """The learner's last infos of ``episodes`` episodes of a one-learner ``env``
    (``imitation_v0.scripted_env``), reset with seeds ``seed``, ``seed + 1``, ...;
    ``policy(obs, env) -> action`` for ``infant_0`` (a Partner: use ``partner_policy``)."""
    out = []
    for k in range(episodes):
        obs, info = env.reset(seed=seed + k)
        last = info["infant_0"]
        ret = 0.0
        while env.agents:
            obs, rew, term, trunc, info = env.step({"infant_0": policy(obs["infant_0"], env)})
            last = info["infant_0"]
            ret += float(rew["infant_0"])
        out.append({**last, "return": ret})
    return out


def partner_policy(partner, agent: str = "infant_0", seed: int = 0):
    """A ``policy`` for :func:`run_episodes` from a scripted Partner, reset at each episode's
    first step with a generator seeded ``seed``, ``seed + 1``, ... (one per episode)."""
    episodes = [0]

    def policy(obs, env):
        inner = env.unwrapped
        if inner.task.step_count == 0:
            partner.reset(inner, agent, np.random.default_rng(seed + episodes[0]))
            episodes[0] += 1
        return partner.act(inner, agent, obs)

    return policy


def summary(records) -> dict:
    """Per demonstrated action (and ``"all"``): the episodes, the success rate, the mean
    return and how often each response came (``"none"`` for no act in the turn,
    ``"several"`` for outcomes at once), from the learner's last infos of each episode
    (:func:`run_episodes`)."""
    names = list(ACTIONS) + ["several"]
    out: dict = {}
    for key in list(ACTIONS) + ["all"]:
        rows = [r for r in records if key == "all" or ACTIONS[int(r["demonstrated"])] == key]
        if not rows:
            continue
        responses = {n: 0 for n in names + ["none"]}
        for r in rows:
            k = int(r["response"])
            responses["none" if k < 0 else names[k]] += 1
        out[key] = {"episodes": len(rows),
                    "success": float(np.mean([bool(r["is_success"]) for r in rows])),
                    "return": float(np.mean([r.get("return", 0.0) for r in rows])),
                    "responses": responses}
    return out
