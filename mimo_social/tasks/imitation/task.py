"""The imitation task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from ...body.joint_groups import both_arms_joints, held_posture
from ...core.kinematics import hand_geoms
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup, Prop
from ...util.checks import ConfigError
from ..common import ContactProbe, face_to_face
from ..dyad import held_angles, measure, tables_of, task_plan
from ...core.factory import make_aec, make_parallel, with_options

__all__ = ["ACTIONS", "Imitation", "ImitationOptions", "Outcomes", "parallel_env", "env",
           "scripted_env"]

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
    demonstration's length (s), the reward for a wrong action (<= 0), whether the
    demonstrator (``caregiver_0``) is scripted (no eyes, no reward) and reward-free mode
    (rewards 0, measures kept)."""

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

    def held_joints(self, i, config):
        """Agent i's held joints (rad): all but both arms; standing knees a little bent (an
        18-month-old), or its own posture's angles (a kneeling adult)."""
        tables = tables_of(config)
        angles = held_angles(config, "standing", {"right_knee": -5, "left_knee": -5})
        return held_posture(tables, keep=both_arms_joints(tables), angles=angles)

    def setup(self, i, config):
        plan = task_plan(self, "standing", self.options.distance, self.held_joints, (0, 1), law="gap")
        self.pair_distance = plan.distance
        pos, facing = face_to_face(i, plan.distance)
        frozen = {**self.held_joints(i, config), **plan.gaze[i]}
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
        e0 = measure(configs[0], self.held_joints(0, configs[0]))
        e1 = measure(configs[1], self.held_joints(1, configs[1]))
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
    def bind(self, env):
        """Index tables of this world (once per world: :meth:`Task.bind`)."""
        w = env.world
        self._outcomes = Outcomes(w, getattr(self, "box_forward", None),
                                  getattr(self, "arm", None))
        q = self._outcomes.box_q[0]
        self._box_start = w.data.qpos[q:q + 7].copy() if q >= 0 else None
        self._dt = float(env.dt)

    def reset(self, env, rng):
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


# -- the env factories (``mimo_social.envs.imitation_v0`` re-exports them) ----------------

def parallel_env(**kwargs):
    return make_parallel(Imitation, **kwargs)


def env(**kwargs):
    return make_aec(Imitation, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ...partners import ScriptedPartners
    from .demonstrator import Demonstrator
    options = with_options(Imitation, kwargs.pop("task_options", None), scripted_partner=True)
    penv = parallel_env(task_options=options, **kwargs)
    # the partner: the second agent (caregiver_0 when it is the adult)
    partner = partner if partner is not None else Demonstrator()
    return ScriptedPartners(penv, {penv.possible_agents[1]: partner})
