"""The high_five task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Sequence

import mujoco
import numpy as np

from ...body.joint_groups import GAZE_JOINTS, held_posture, right_arm_joints
from ...body.tables import HAND_VERSIONS, load_body
from ...core.kinematics import Gaze, hand_geoms
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup
from ...util.checks import ConfigError
from ..common import (
    HAND_TOUCH_DENSITY,
    ContactProbe,
    face_to_face,
    hands_setting,
    require_skin,
    right_hand_parts,
    touch_only_on,
)
from ..dyad import held_angles, tables_of, task_plan
from ...core.factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "scripted_env", "default_partner", "HighFive", "hand_touch",
           "HighFiveOptions", "OFFER_AT", "PALM_COS", "SUCCESS"]

# 0.35 m: the right hands meet with the arms forward, half stretched; at 0.45 m (the first
# version's distance) only the outstretched fingers meet, and PPO takes many times longer
DISTANCE = 0.35
DISTANCE_RANGE = (0.25, 0.6)
#: what counts as the high five (task option ``success``): ``"palms"`` (default): the palms meet,
#: palm side to palm side, held ``hold_time``; ``"touch"``: the first version's rule (the right
#: hands touch and both skins feel the partner, one step, any side of the hand)
SUCCESS = ("palms", "touch")
#: where the default scripted partner holds its palm centre: (forward, left, up) m from the
#: learner's right shoulder in the learner's heading frame (an 18-month-old's; scaled with the
#: learner's arm), at the midline between the infants, 6 cm below the shoulder, where the
#: learner's palm comes down onto it. The first versions' partner (``HandOffer(grip=False,
#: release=None)``) held it 15 cm to the learner's left, across its body, where a palm facing
#: down reaches it with the finger pads only
OFFER_AT = (0.195, 0.105, -0.06)
#: m: the farthest apart two 18-month-olds stand with ``success="palms"``: the scripted palm to
#: palm meets 10 / 10 at 0.25-0.4 m, 3 / 10 at 0.45 m, 0 / 10 at 0.5 m
PALMS_DISTANCE = 0.4
#: a contact is on a hand's palm side when the contact normal (from the hand into the other)
#: lies within 60 deg of the palm's normal (the hand segment's -y): the palm and the finger pads
#: facing the other hand, not its back, edges or fingertips' ends
PALM_COS = 0.5


def hand_touch(hands: str = "mitten", density: float = HAND_TOUCH_DENSITY,
               normal_only: bool = True) -> dict:
    """The default ``touch`` setting of high five: the right hand's skin only.

    ``touch=hand_touch(density=1.0, normal_only=False)`` gives the right hand at the published
    density with 3 floats a point."""
    if hands not in HAND_VERSIONS:
        raise ConfigError(f"hands={hands!r} not allowed; allowed: {list(HAND_VERSIONS)}")
    tables = load_body(hands)
    return touch_only_on(tables, right_hand_parts(tables), density, normal_only)


class SkinSource:
    """Does one body region of agent ``i`` (e.g. its right hand) feel agent ``j`` on its skin?

    A contact probe between the region's geoms and all of ``j``'s geoms gates the question (one
    pair of gathers a step); only when they are in contact is the skin's record of who touches
    which part (:meth:`~mimo_social.senses.touch.TouchSystem.touched_by`) read, for the few
    parts of the region.
    """

    def __init__(self, world, touch, i: int, region_geoms, parts: Sequence[str], j: int):
        self.touch = touch
        self.i = i
        self.parts = tuple(parts)
        self.source = world.names[j]
        self.probe = ContactProbe(world.model.ngeom, region_geoms, world.agents[j].geom_ids)

    def __call__(self, data) -> bool:
        if not self.probe(data):
            return False
        felt = self.touch.touched_by(self.i)
        return any(self.source in felt[p]["agents"] for p in self.parts if p in felt)


# -- the task ----------------------------------------------------------------------------------
START_TRIES = 50   # random start postures tried until the hands touch nothing


@dataclass(frozen=True)
class HighFiveOptions(TaskOptions):
    """Bonus for the felt high five, whether it ends the episode, the distance between the
    infants (m), the spread of the random start postures (fraction of each joint's range), what
    counts as the high five (``success``: :data:`SUCCESS`) and how long (s) the palms must stay
    together (``hold_time``, with ``success="palms"``)."""

    task = "high_five"
    privileged: ClassVar[tuple[str, ...]] = ("assisted_gaze",)
    touch_bonus: float = 100.0
    end_on_touch: bool = True
    distance: float = DISTANCE
    start_spread: float = 0.3
    assisted_gaze: bool = False
    shaping: bool = True
    success: str = "palms"
    hold_time: float = 0.1

    def __post_init__(self):
        self._number("touch_bonus")
        self._bool("end_on_touch")
        self._number("distance", *DISTANCE_RANGE)
        self._number("start_spread", 0.0, 1.0)
        self._bool("assisted_gaze")
        self._bool("shaping")
        self._choice("success", SUCCESS)
        self._number("hold_time", 0.0, 1.0)
        if self.success == "palms" and self.distance > PALMS_DISTANCE:
            raise ConfigError(f"high_five: task option distance={self.distance!r} not allowed "
                              f"with success='palms'; allowed: a number from "
                              f"{DISTANCE_RANGE[0]} to {PALMS_DISTANCE} (farther apart the palms "
                              f"do not meet), or success='touch' (up to {DISTANCE_RANGE[1]})")


GAP_CAP = 0.1   # m: the hand gap plot's top (the hands' surfaces are not measured farther)


class HighFive(Task):
    name = "high_five"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 500
    Options = HighFiveOptions

    def agent_defaults(self, i, settings):
        return {"posture": "standing", "touch": hand_touch(hands_setting(settings))}

    def held_joints(self, i, config):
        """Agent i's held joints (rad): all but the right arm (and head and eyes with
        ``assisted_gaze``), standing knees a little bent, or its own posture's angles (an adult
        leaning toward the infant)."""
        tables = tables_of(config)
        gaze = GAZE_JOINTS if self.options.assisted_gaze else ()
        angles = held_angles(config, "standing", {"right_knee": -5, "left_knee": -5}, lean=True)
        return held_posture(tables, keep=right_arm_joints(tables) + gaze, angles=angles)

    def setup(self, i, config):
        # two 18-month-olds stand `distance` apart; other bodies at the distance scaled with
        # their reach, looking at each other's face (tasks/dyad.py)
        plan = task_plan(self, "standing", self.options.distance, self.held_joints,
                         () if self.options.assisted_gaze else (0, 1))
        pos, facing = face_to_face(i, plan.distance)
        tables = tables_of(config)
        require_skin(self.name, self.agent_name(i), config, right_hand_parts(tables),
                     "the high five (the right hands meeting)")
        arm = right_arm_joints(tables)
        gaze = GAZE_JOINTS if self.options.assisted_gaze else ()
        frozen = {**self.held_joints(i, config), **plan.gaze[i]}
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=arm, gaze_joints=gaze)

    def bind(self, env):
        w = env.world
        self._world = w
        self._gaze = [Gaze(w, i) for i in range(2)] if self.options.assisted_gaze else []
        self._palms = np.array([w.agents[i].palm_sites[0] for i in range(2)], dtype=np.intp)
        hands = [hand_geoms(w, i) for i in range(2)]
        self._hand_pairs = [(int(a), int(b)) for a in hands[0] for b in hands[1]]
        self._hands_meet = ContactProbe(w.model.ngeom, hands[0], hands[1])
        touch = env.systems.get("touch")
        self._feels = [SkinSource(w, touch, i, hands[i], right_hand_parts(w.tables[i]), 1 - i)
                       for i in range(2)]
        self._hand_mask = np.zeros(w.model.ngeom, bool)
        self._hand_mask[np.concatenate(hands)] = True
        # whose right hand a geom is (0, 1; -1: no right hand) and each hand's segment (palm side
        # -y), for the palm-to-palm rule
        self._hand_of = np.full(w.model.ngeom, -1, np.int8)
        for i in range(2):
            self._hand_of[hands[i]] = i
        self._hand_bodies = np.array([w.model.site_bodyid[p] for p in self._palms], np.intp)
        self._hold_steps = max(1, int(round(self.options.hold_time / env.dt)))
        # each arm's joints: qpos/dof addresses, the standing pose's angles (rad) and ranges
        self._arms = []
        rest = w.initial_qpos
        for a in w.agents:
            k = a.actuated_joint_idx
            lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
            self._arms.append((a.qpos_adr[k], a.dof_adr[k], rest[a.qpos_adr[k]].copy(), lo, hi))

    def reset(self, env, rng):
        m, d = env.world.model, env.world.data
        spread = self.options.start_spread
        for _ in range(START_TRIES):  # each arm in its own random posture, the hands touching nothing
            for q, v, mid, lo, hi in self._arms:
                u = rng.uniform(-0.5, 0.5, len(q))
                d.qpos[q] = np.clip(mid + u * spread * (hi - lo), lo, hi)
                d.qvel[v] = 0.0
            mujoco.mj_kinematics(m, d)
            mujoco.mj_collision(m, d)
            n = d.ncon
            g1, g2 = d.contact.geom1[:n], d.contact.geom2[:n]
            if not np.any((self._hand_mask[g1] | self._hand_mask[g2]) & (d.contact.dist[:n] < 0)):
                break
        self._touching = self._palm_contact = False
        self._held = 0
        self._felt = [False, False]
        self._distance = float("nan")
        self.before_physics(env)

    def before_physics(self, env):
        if self._gaze:   # assisted gaze: head and eyes on the partner's right hand
            m, d = env.world.model, env.world.data
            for i in range(2):
                self._gaze[i](m, d, "site", self._palms[1 - i])

    def rewards(self, env):
        d = env.world.data
        p = d.site_xpos[self._palms]
        dist = float(np.linalg.norm(p[0] - p[1]))
        self._felt = [bool(f(d)) for f in self._feels]
        meet = self._felt[0] and self._felt[1] and self._hands_meet(d)
        self._palm_contact = meet and self.palms_meet(d)
        self._held = self._held + 1 if self._palm_contact else 0
        # "palms": palm side to palm side, held hold_time; "touch" (the first version): any
        # touch of the right hands that both skins feel
        self._touching = meet if self.options.success == "touch" \
            else self._held >= self._hold_steps
        r = (-dist if self.options.shaping else 0.0) \
            + (self.options.touch_bonus if self._touching else 0.0)
        self._distance = dist
        return np.array([r, r])

    def palms_meet(self, data) -> bool:
        """Whether the two right hands touch palm side to palm side this step: a contact
        between them whose normal, from each hand into the other, lies within 60 deg of that
        hand's palm normal (:data:`PALM_COS`; the palm and the finger pads count, the back of the
        hand, its edges and the fingertips' ends do not). One gather over the contacts."""
        n = data.ncon
        if n == 0:
            return False
        c = data.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        o1, o2 = self._hand_of[g1], self._hand_of[g2]
        keep = (o1 >= 0) & (o2 >= 0) & (o1 != o2) & (c.dist[:n] <= 0.0)
        if not keep.any():
            return False
        # each contact's normal from infant_0's hand into infant_1's
        normal = c.frame[:n, :3][keep] * np.where(o1[keep] == 0, 1.0, -1.0)[:, None]
        palms = -data.xmat[self._hand_bodies][:, [1, 4, 7]]   # each hand's -y (world)
        return bool(np.any((normal @ palms[0] >= PALM_COS) & (normal @ palms[1] <= -PALM_COS)))

    def plots(self):
        """The shared reward (one line), the distance between the right palms' centres (the
        reward's), the gap between the right hands' surfaces (0: touching), success (both right
        hands feel the partner's) and whether each right hand feels the partner."""
        return [Plot.reward(shared=True),
                Plot("hand_distance", "m", lambda env: self._distance, per_agent=False),
                Plot("hand_gap", f"m, up to {GAP_CAP:g}", self._hand_gap, per_agent=False),
                Plot("success", "0/1", lambda env: self._touching, per_agent=False),
                Plot("hand_feels_partner", "0/1", lambda env: self._felt)]

    def _hand_gap(self, env) -> float:
        """The least distance (m) between the two right hands' geoms (negative: pressed into
        each other), or GAP_CAP when farther (measured only with the palms within 0.2 m)."""
        if not self._distance < 0.2:
            return GAP_CAP
        m, d = env.world.model, env.world.data
        return min(mujoco.mj_geomDistance(m, d, a, b, GAP_CAP, None) for a, b in self._hand_pairs)

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"is_success": "number", "hands_touching": "number",
                "hand_feels_partner": "number", "hand_distance": "number",
                "palm_contact": "number", "palm_contact_time": "number"}

    def terminations(self, env):
        done = self._touching and self.options.end_on_touch
        held = self._held * env.dt
        infos = [{"is_success": self._touching, "hands_touching": self._touching,
                  "hand_feels_partner": self._felt[i], "hand_distance": self._distance,
                  "palm_contact": self._palm_contact, "palm_contact_time": held}
                 for i in range(2)]
        return np.array([done, done]), infos


# -- the env factories (``mimo_social.envs.high_five_v0`` re-exports them) ----------------

def parallel_env(**kwargs):
    return make_parallel(HighFive, **kwargs)


def env(**kwargs):
    return make_aec(HighFive, **kwargs)


def default_partner():
    """The scripted partner of :func:`scripted_env`: ``HandOffer(grip=False, release=None,
    reach_to=OFFER_AT)``, which brings its right hand, palm up and fingers open, to the midline
    between the infants (:data:`OFFER_AT` from the learner's right shoulder, where the learner's
    palm comes down onto it) and holds it there."""
    from ...partners.hand_offer import HandOffer
    return HandOffer(grip=False, release=None, reach_to=OFFER_AT)


def scripted_env(partner=None, **kwargs):
    from ...partners import ScriptedPartners
    penv = parallel_env(**kwargs)
    # the partner: the second agent (caregiver_0 when it is the adult)
    partner = partner if partner is not None else default_partner()
    return ScriptedPartners(penv, {penv.possible_agents[1]: partner})
