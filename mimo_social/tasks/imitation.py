"""Imitation: the learner reproduces an action its partner demonstrated, seen through its eyes.

TABLE

The demonstration and the turn are scored by the same outcome detectors (:class:`Outcomes`),
which read only each agent's own body: contacts of its own hands with its own head or with each
other, and its right palm's height over its head.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from ..body.joint_groups import both_arms_joints, held_posture
from ..core.kinematics import hand_geoms
from ..core.task import Task, TaskOptions
from ..core.world import AgentSetup
from ..util.checks import ConfigError
from .common import ContactProbe, face_to_face
from .dyad import held_angles, tables_of, task_plan

__all__ = ["ACTIONS", "Imitation", "ImitationOptions", "Outcomes", "summary"]

#: the demonstrated actions, in the order of the outcome vector and the ``instruction``
ACTIONS = ("head_touch", "hand_raise", "clap")
DISTANCE = 1.0        # m between two standing 18-month-olds (scaled for other bodies)
EYE_SIZE = 64
DEMO_S = 2.5          # s: the demonstration phase
MAX_STEPS = 550       # 2.5 s demonstration + 3 s turn at 10 ms a step
RAISE_MARGIN = 0.5    # head radii: how far the right palm must be over the top of the head
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
        self._number("distance", 0.4, 1.5)
        self._number("demo_s", 0.5, 10.0)
        self._number("wrong_reward", -10.0, 0.0)
        self._bool("scripted_partner")
        self._bool("reward_free")


class Outcomes:
    """The outcome detectors of every action, for every agent, from its own body only:

    - ``head_touch``: a hand (either) of the agent in contact with its own head (head geom);
    - ``hand_raise``: its right palm at least :data:`RAISE_MARGIN` head radii above the top of
      its head, the hand not touching the head;
    - ``clap``: its two hands in contact with each other.

    Index tables are resolved once; a call is a few gathers over the contacts."""

    def __init__(self, world):
        m = world.model
        self.world = world
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

    def __call__(self, data, i: int) -> np.ndarray:
        """Agent ``i``'s outcomes this step: a bool per action of :data:`ACTIONS`."""
        touch = self.head_touch[i](data)
        top = data.geom_xpos[self.head_geom[i], 2] + self.head_radius[i]
        raised = data.site_xpos[self.palm[i], 2] > top + self.margin[i] and not touch
        return np.array([touch, raised, self.clap[i](data)], bool)


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
        arms = both_arms_joints(tables_of(config))
        return AgentSetup(config, position=config.position or pos,
                          facing=config.facing or facing, frozen=frozen, base="fixed",
                          actuated=arms)

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
            self._outcomes = Outcomes(w)
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


def partner_policy(partner, agent: str = "infant_0"):
    """A ``policy`` for :func:`run_episodes` from a scripted Partner (reset at each episode's
    first step)."""
    def policy(obs, env):
        inner = env.unwrapped
        if inner.task.step_count == 0:
            partner.reset(inner, agent, np.random.default_rng(inner.task.demonstrated))
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
