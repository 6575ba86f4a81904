"""The social_touch task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import mujoco
import numpy as np
from gymnasium import spaces

from ...body.joint_groups import (
    EYE_GAZE_JOINTS,
    HEAD_GAZE_JOINTS,
    both_arms_joints,
    held_posture,
    right_arm_joints,
)
from ...body.tables import load_body, subtree
from ...core.kinematics import Gaze, hand_geoms
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup
from ..dyad import held_angles, tables_of, task_plan
from ...util.checks import ConfigError
from ..common import (
    CROSS_LEGGED_DEG,
    hands_setting,
    require_skin,
    right_hand_parts,
    skin_parts,
    touch_only_on,
)
from ...core.factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "scripted_env", "SocialTouch", "DEFAULT_TARGETS",
           "SocialTouchOptions"]

TOUCHER, TOUCHED = 0, 1
DISTANCE = 0.37
# sitting infants at play face to face, hip to hip (see docs/social/social_touch.md)
DISTANCE_RANGE = (0.35, 0.40)
# cross-legged (the legs of the self-body pose), the knees bent as far as they go (-145 deg) so
# that the crossed feet stay clear of the partner's (2 cm at 0.35 m; at -130 deg the toes of the
# two infants would overlap by 2.4 cm)
SITTING_DEG = {**{k: v for k, v in CROSS_LEGGED_DEG.items()
                  if "hip" in k or "knee" in k or "ankle" in k},
               "right_knee": -145.0, "left_knee": -145.0}
# the touched infant leans back a little, so that the leaning toucher's head stays clear of it
RECLINE_DEG = -6.0
# the toucher's lower trunk bend (the upper trunk follows, coupled: 61 deg in all), at the
# joint's limit: leaning in as far as it goes gives the arm its reach at 0.35-0.40 m
LEAN_DEG = 30.5
# the toucher's head tilted back against the lean, so that it faces the partner
HEAD_TILT_DEG = -60.0
# the toucher's left arm hangs at its side, out of the way
SIDE_ARM_DEG = {"left_shoulder_abduction": 15.0, "left_elbow": -10.0}
# the toucher's right arm at the start: out to its side, elbow a little bent, touching nothing
ARM_START_DEG = {"right_shoulder_abduction": 45.0, "right_shoulder_horizontal": 0.0,
                 "right_elbow": -30.0}
#: the partner's parts that the toucher's right hand reaches over the whole distance range
#: (0.35-0.40 m): for each, a posture of the right arm found by inverse kinematics puts the hand
#: into the part, touching nothing else of the partner (tests/tasks/test_social_touch.py); the
#: head, the hip, the far (right) side and the feet are not offered. ``targets`` may name only
#: these.
REACHABLE = ("upper_body", "lower_body", "left_upper_arm", "left_lower_arm", "left_hand",
             "left_upper_leg", "left_lower_leg")
#: the targets by default: the reachable parts but the left thigh, where a dropped arm lands
#: (uniformly random actions touch it first, palm side, in a third of the episodes; it is
#: offered with ``targets=[...]``)
DEFAULT_TARGETS = tuple(p for p in REACHABLE if p != "left_upper_leg")
#: an adult partner's parts that the toucher's right hand reaches (by posture), measured with
#: the scripted toucher (SocialTouchController) at the default distance: 2 / 2 seeds each (the
#: partner's other parts: 0 / 2, the hand meeting the kneeling adult's hanging left hand or its
#: thigh first, the sitting adult's shin); they are the adult's default targets. Kneeling
#: upright, the adult's thighs are in front of its belly and its upper arm is above the
#: infant's reach; sitting cross-legged, its shins are in front of everything else.
ADULT_REACHABLE = {"kneeling": ("left_lower_arm", "left_hand", "left_upper_leg"),
                   "sitting": ("left_lower_leg",)}
#: random start postures tried until the arms touch nothing they should not
START_TRIES = 50
#: a hand contact is made with the back of the hand (which does not count) when the contact
#: normal (from the hand into the partner) has a component at or below this along the palm's
#: normal (-0.5: more than 120 deg from it); palm, finger pads, fingertips and edges count
BACK_COS = -0.5


@dataclass(frozen=True)
class SocialTouchOptions(TaskOptions):
    """The partner's target parts (None: :data:`DEFAULT_TARGETS`), one fixed target (None:
    drawn each episode), the reward for touching the target first, whether the first touch ends
    the episode, the distance between the infants (m), the per-step distance shaping, and
    whether the task aims the eyes (the toucher's at the target, the touched infant's at the
    toucher's hand: a privileged cue), and the start's randomness: the spread of the toucher's
    right-arm start posture and of the touched infant's arms (fractions of each joint's range)
    and of the distance (m, either way)."""

    task = "social_touch"
    privileged: ClassVar[tuple[str, ...]] = ("assisted_gaze",)
    targets: tuple[str, ...] | None = None
    target: str | None = None
    success_reward: float = 100.0
    end_on_touch: bool = True
    distance: float = DISTANCE
    shaping: bool = True
    assisted_gaze: bool = False
    start_spread: float = 0.2
    partner_spread: float = 0.1
    distance_spread: float = 0.02

    def __post_init__(self):
        self._names("targets", "body part names of the partner")
        self._name("target", "a body part name from targets")
        self._number("success_reward", 0.0)
        self._bool("end_on_touch")
        self._number("distance", *DISTANCE_RANGE)
        self._bool("shaping")
        self._bool("assisted_gaze")
        self._number("start_spread", 0.0, 1.0)
        self._number("partner_spread", 0.0, 1.0)
        self._number("distance_spread", 0.0, DISTANCE_RANGE[1] - DISTANCE_RANGE[0])


class SocialTouch(Task):
    name = "social_touch"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 500

    Options = SocialTouchOptions

    def __init__(self, n_agents: int = 2, options=None, /, **values):
        if isinstance(n_agents, (int, np.integer)) and not isinstance(n_agents, bool) \
                and n_agents != 2:
            raise ConfigError(f"social_touch: n_agents={n_agents!r} not allowed; allowed: 2 to 2 "
                              "(a dyad: the toucher infant_0 and the touched partner)")
        super().__init__(n_agents, options, **values)
        self.targets: tuple[str, ...] = ()

    def agent_defaults(self, i, settings):
        common = {"posture": "sitting", "vestibular": False, "expressions": False}
        if i == TOUCHER:
            tables = load_body(hands_setting(settings))
            return dict(common, touch=touch_only_on(tables, subtree(tables, "right_upper_arm")))
        return dict(common, touch={"density": 0.25, "normal_only": True})

    # -- building ------------------------------------------------------------------------------
    def _resolve_targets(self, tables, config=None) -> tuple[str, ...]:
        parts = skin_parts(tables)
        given = self.options.targets
        reachable, defaults = REACHABLE, DEFAULT_TARGETS
        if config is not None and config.body == "adult":
            if config.posture not in ADULT_REACHABLE:
                raise ConfigError(f"social_touch: {self.agent_name(TOUCHED)}: posture="
                                  f"{config.posture!r} not allowed for body='adult'; allowed: "
                                  f"{list(ADULT_REACHABLE)}")
            reachable = defaults = ADULT_REACHABLE[config.posture]
        if given is None:
            targets = tuple(p for p in defaults if p in parts)
        else:
            bad = [p for p in given if p not in parts]
            if bad:
                raise ConfigError(f"social_touch: targets {bad} are not body parts of the "
                                  f"partner ({tables.hands} body); body parts: {list(parts)}")
            far = [p for p in given if p not in reachable]
            if far:
                raise ConfigError(f"social_touch: targets {far} are out of the toucher's reach "
                                  f"at {DISTANCE_RANGE[0]}-{DISTANCE_RANGE[1]} m; allowed: "
                                  f"{[p for p in reachable if p in parts]}")
            targets = tuple(given)
        fixed = self.options.target
        if fixed is not None and fixed not in targets:
            raise ConfigError(f"social_touch: target={fixed!r} not allowed; one of "
                              f"{list(targets)}")
        return targets

    def _actuated(self, i, tables):
        return right_arm_joints(tables) if i == TOUCHER else both_arms_joints(tables)

    def held_joints(self, i, config):
        """Agent i's held joints (rad): sitting cross-legged (or its own posture), the toucher
        leaning in with its head tilted back, the touched infant leaning back a little; all
        but the actuated arms and the eyes."""
        tables = tables_of(config)
        if i == TOUCHER:
            angles = {**SITTING_DEG, **SIDE_ARM_DEG, "lower_trunk_bend": LEAN_DEG,
                      "head_tilt": HEAD_TILT_DEG}
        else:
            angles = {**SITTING_DEG, "lower_trunk_bend": RECLINE_DEG}
        angles = held_angles(config, "sitting", angles)
        return held_posture(tables, keep=self._actuated(i, tables) + EYE_GAZE_JOINTS,
                            angles=angles)

    def setup(self, i, config):
        # two 18-month-olds sit `distance` apart; other bodies keep the floor between their
        # forward depths as two 18-month-olds have it; a partner of another body turns its head
        # to the toucher's face (tasks/dyad.py)
        # other bodies: clear of each other even at the closest distance a reset draws
        o = self.options
        slack = min(o.distance_spread, o.distance - DISTANCE_RANGE[0])
        plan = task_plan(self, "sitting", o.distance, self.held_joints, (TOUCHED,), law="gap",
                         slack=slack)
        dist = plan.distance
        pos = (0.0, 0.0) if i == TOUCHER else (dist, 0.0)
        facing = (dist, 0.0) if i == TOUCHER else (0.0, 0.0)
        tables = tables_of(config)
        actuated = self._actuated(i, tables)
        if i == TOUCHER:
            require_skin(self.name, self.agent_name(i), config, right_hand_parts(tables),
                         "the touch it gives")
        else:
            self.targets = self._resolve_targets(tables, config)
            require_skin(self.name, self.agent_name(i), config, self.targets,
                         "the touch it receives on every target part")
        head = {k: v for k, v in plan.gaze[i].items() if k in HEAD_GAZE_JOINTS}
        frozen = {**self.held_joints(i, config), **head}
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=actuated,
                          gaze_joints=EYE_GAZE_JOINTS)

    def task_spaces(self, env, i):
        if i == TOUCHER:
            return {"target": spaces.Box(0.0, 1.0, (len(self.targets),), np.float32)}
        return {}

    def bind(self, env):
        w = env.world
        m = w.model
        self._world = w
        toucher, touched = w.agents[TOUCHER], w.agents[TOUCHED]
        self._gaze = [Gaze(w, TOUCHER), Gaze(w, TOUCHED)]
        self._eyes = [g.look.qpos for g in self._gaze]
        self._eye_dofs = np.concatenate([g.look.dof for g in self._gaze])
        # the toucher's right arm (upper arm to fingertips): 1 = arm, 2 = hand; else 0
        self._arm = np.zeros(m.ngeom, np.int8)
        root = m.body(f"{toucher.name}/right_upper_arm").id
        below = np.zeros(m.nbody, bool)
        below[root] = True
        for b in sorted(toucher.body_ids.tolist()):
            if b != root and below[m.body_parentid[b]]:
                below[b] = True
        self._arm[toucher.geom_ids[below[m.geom_bodyid[toucher.geom_ids]]]] = 1
        self._arm[hand_geoms(w, TOUCHER, 0)] = 2
        # every geom of the touched infant -> its body id; every other geom -> -1
        self._partner_body = np.full(m.ngeom, -1, dtype=np.intp)
        self._partner_body[touched.geom_ids] = m.geom_bodyid[touched.geom_ids]
        prefix = len(touched.name) + 1
        self._part_name = {int(b): m.body(int(b)).name[prefix:]
                           for b in np.unique(m.geom_bodyid[touched.geom_ids])}
        self._target_bodies = np.array([m.body(f"{touched.name}/{t}").id for t in self.targets],
                                       dtype=np.intp)
        # each target's bodies: the part, and for a hand the fingers below it
        self._target_sets = []
        for t, b in zip(self.targets, self._target_bodies):
            inside = np.zeros(m.nbody, bool)
            inside[b] = True
            if t.endswith("_hand"):
                for c in sorted(touched.body_ids.tolist()):
                    if c != b and inside[m.body_parentid[c]]:
                        inside[c] = True
            self._target_sets.append(np.flatnonzero(inside))
        self._target_names = [[self._part_name[int(b)] for b in ids if int(b) in self._part_name]
                              for ids in self._target_sets]
        self._fingertip = int(toucher.fingertip_sites[0])
        self._palm = int(toucher.palm_sites[0])
        self._head = [int(w.agents[j].head_site) for j in (TOUCHER, TOUCHED)]
        idx = {n: k for k, n in enumerate(toucher.joint_names)}
        ks = [idx[n] for n in ARM_START_DEG if n in idx]
        self._arm_qpos = toucher.qpos_adr[ks]
        self._arm_start = np.clip(np.deg2rad([ARM_START_DEG[toucher.joint_names[k]] for k in ks]),
                                  toucher.joint_range[ks, 0], toucher.joint_range[ks, 1])
        self._source = toucher.name
        self._touch = env.systems.get("touch")
        self._geom_body = m.geom_bodyid.copy()
        # the start's randomness: each agent's actuated joints (the toucher's right arm, the
        # touched infant's arms) around their start angles, and the touched infant's hip along
        # the line between the two (its root body hangs from the world: body_pos)
        start = w.initial_qpos.copy()
        start[self._arm_qpos] = self._arm_start
        self._spread_joints = []
        for a in (toucher, touched):
            k = a.actuated_joint_idx
            lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
            self._spread_joints.append((a.qpos_adr[k], start[a.qpos_adr[k]].copy(), lo, hi))
        self._root = int(touched.root_body)
        xy = [np.array(st.position, float) for st in w.agent_setups]
        self._root_xy = xy[TOUCHED]
        self._axis = (xy[TOUCHED] - xy[TOUCHER]) / max(np.linalg.norm(xy[TOUCHED]
                                                                      - xy[TOUCHER]), 1e-9)
        self._geom_agent = w.geom_agent
        #: the episode's distance (m, hip to hip for two 18-month-olds; other bodies are moved
        #: by as much from where they were placed)
        self.distance = self.options.distance

    def reset(self, env, rng):
        m, d = env.world.model, env.world.data
        d.qpos[self._arm_qpos] = self._arm_start
        fixed = self.options.target
        self._target = (self.targets.index(fixed) if fixed is not None
                        else int(rng.integers(len(self.targets))))
        self._randomise_start(m, d, rng)
        self._onehot = np.zeros(len(self.targets), np.float32)
        self._onehot[self._target] = 1.0
        self._success = self._wrong = self._felt = False
        self._first: list[str] | None = None
        self._touched: list[str] = []
        self._distance = float("nan")
        if not self.options.assisted_gaze:
            # each looks at the other's face: the heads are held, so these angles are fixed
            # for the episode and the same whatever the target
            for j, g in enumerate(self._gaze):
                g(m, d, "site", self._head[1 - j])
            self._held_eyes = [d.qpos[q].copy() for q in self._eyes]
        self.before_physics(env)

    def _randomise_start(self, m, d, rng) -> None:
        """The episode's distance (``distance`` + U(-1, 1) x ``distance_spread``, within
        0.35-0.40 m for two 18-month-olds; other bodies shifted by the same amount) and arm
        postures (each actuated joint at its start angle + U(-1/2, 1/2) x spread x its range),
        drawn again until the toucher's right arm touches nothing and the two infants do not
        touch each other (seeded by ``reset(seed=...)``)."""
        self.distance = self._draw(m, d, rng, toucher=True)

    def draw_unseen(self, model, data, rng, own_mean: bool = False) -> None:
        """What the toucher does not sense, drawn again as at reset on a copy ``data`` (a new
        ``MjData`` of ``model`` with the episode's state) of the episode's world: the touched
        infant's arms, until nothing touches that should not; the toucher's own posture is
        kept, and so is the distance, which the toucher senses (its eyes verge on the partner's
        face: their angles in its proprioception change with the distance, tested). For a
        toucher that plans without seeing its partner (a planner's twin worlds); this env is not
        changed. ``own_mean``: the toucher's right arm put at its mean start (the start posture
        without spread) first: a plan for every start."""
        if own_mean:
            q, mid, _, _ = self._spread_joints[TOUCHER]
            data.qpos[q] = mid
        self._draw(model, data, rng, toucher=False)

    def _draw(self, m, d, rng, toucher: bool) -> float:
        o = self.options
        dist = self.distance
        if toucher:
            lo_d, hi_d = DISTANCE_RANGE
            dist = float(np.clip(o.distance + rng.uniform(-1.0, 1.0) * o.distance_spread,
                                 lo_d, hi_d))
            m.body_pos[self._root, :2] = self._root_xy + (dist - o.distance) * self._axis
        spreads = (o.start_spread if toucher else None, o.partner_spread)
        for _ in range(START_TRIES):
            for (q, mid, lo, hi), spread in zip(self._spread_joints, spreads):
                if spread is None:
                    continue
                u = rng.uniform(-0.5, 0.5, len(q))
                d.qpos[q] = np.clip(mid + u * spread * (hi - lo), lo, hi)
            mujoco.mj_kinematics(m, d)
            mujoco.mj_collision(m, d)
            n = d.ncon
            g1, g2 = d.contact.geom1[:n], d.contact.geom2[:n]
            a1, a2 = self._geom_agent[g1], self._geom_agent[g2]
            pressed = d.contact.dist[:n] < 0.0
            across = (a1 >= 0) & (a2 >= 0) & (a1 != a2)
            arm = (self._arm[g1] > 0) ^ (self._arm[g2] > 0)
            if not np.any(pressed & (across | arm)):
                break
        else:   # no clear draw: the fixed start (which touches nothing)
            for (q, mid, _, _), spread in zip(self._spread_joints, spreads):
                if spread is not None:
                    d.qpos[q] = mid
        return dist

    @property
    def target(self) -> str:
        """The current episode's target part (of the touched infant's body)."""
        return self.targets[self._target]

    def before_physics(self, env):
        m, d = env.world.model, env.world.data
        if self.options.assisted_gaze:
            self._gaze[TOUCHER](m, d, "body", self._target_bodies[self._target])
            self._gaze[TOUCHED](m, d, "site", self._palm)
        else:
            for q, held in zip(self._eyes, self._held_eyes):
                d.qpos[q] = held
            d.qvel[self._eye_dofs] = 0.0

    def observe(self, env, i):
        return {"target": self._onehot.copy()} if i == TOUCHER else {}

    def _arm_contacts(self, d) -> tuple[np.ndarray, np.ndarray]:
        """The touched infant's parts (body ids) in contact with the toucher's right arm this
        step, and whether each contact is made by the palm side of the toucher's hand (hand or
        finger geom, the contact normal into the partner within 90 deg of the palm's normal:
        the segment's local -y)."""
        n = d.ncon
        if n == 0:
            return np.empty(0, np.intp), np.empty(0, bool)
        c = d.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        a1, a2 = self._arm[g1], self._arm[g2]
        first = a1 > 0
        keep = (first ^ (a2 > 0)) & (c.dist[:n] <= 0.0)
        body = self._partner_body[np.where(first, g2, g1)]
        keep &= body >= 0
        if not keep.any():
            return np.empty(0, np.intp), np.empty(0, bool)
        mine = np.where(first, g1, g2)[keep]
        normal = c.frame[:n, :3][keep] * np.where(first[keep], 1.0, -1.0)[:, None]
        palm = -d.xmat[self._geom_body[mine]].reshape(-1, 3, 3)[:, :, 1]
        volar = (self._arm[mine] == 2) & (np.einsum("ij,ij->i", normal, palm) > BACK_COS)
        return body[keep], volar

    def rewards(self, env):
        d = env.world.data
        target = self._target_bodies[self._target]
        bodies, by_hand = self._arm_contacts(d)
        self._touched = sorted({self._part_name[int(b)] for b in bodies})
        hand_on_target = bool(np.any(by_hand & np.isin(bodies, self._target_sets[self._target])))
        self._felt = False
        if hand_on_target and self._touch is not None:
            record = self._touch.touched_by(TOUCHED)
            self._felt = any(self._source in record[p]["agents"]
                             for p in self._target_names[self._target] if p in record)
        self._distance = float(np.linalg.norm(d.site_xpos[self._fingertip] - d.xipos[target]))
        r = -self._distance if self.options.shaping else 0.0
        if self._first is None and len(bodies):
            # the attempt is decided by the first contact of the arm with the partner
            self._first = list(self._touched)
            if hand_on_target:
                self._success = True
                r += self.options.success_reward
            else:
                self._wrong = True
                if self.options.end_on_touch and self.options.shaping:
                    # ending early saves nothing: the rest of the episode's shaping, at the
                    # current distance, is charged now
                    r -= self._distance * max(env.max_steps - env.steps, 0)
        return np.array([r, r])

    def plots(self):
        """The shared reward (one line), the toucher's fingertip distance to the target part,
        the target felt, and success."""
        return [Plot.reward(shared=True),
                Plot("fingertip_distance", "m", lambda env: self._distance, per_agent=False),
                Plot("target_felt", "0/1", lambda env: self._felt, per_agent=False),
                Plot("success", "0/1", lambda env: self._success, per_agent=False)]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"target_part": tuple(self.targets), "is_success": "number",
                "wrong_touch": "number", "first_touch": "count", "target_felt": "number",
                "fingertip_distance": "number", "touched_parts": "count"}

    def terminations(self, env):
        done = self._first is not None and self.options.end_on_touch
        info = {"target_part": self.target, "is_success": self._success,
                "wrong_touch": self._wrong, "first_touch": self._first,
                "target_felt": self._felt, "fingertip_distance": self._distance}
        return np.array([done, done]), [dict(info, touched_parts=list(self._touched),
                                             first_touch=None if self._first is None
                                             else list(self._first)) for _ in range(2)]


# -- the env factories (``mimo_social.envs.social_touch_v0`` re-exports them) -------------

def parallel_env(**kwargs):
    return make_parallel(SocialTouch, **kwargs)


def env(**kwargs):
    return make_aec(SocialTouch, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ...partners import ScriptedPartners, Still
    penv = parallel_env(**kwargs)
    # the partner: the second agent (caregiver_0 when it is the adult)
    partner = partner if partner is not None else Still()
    return ScriptedPartners(penv, {penv.possible_agents[1]: partner})
