"""High five: two standing infants, face to face, bring their right hands together and feel it.

| | |
|---|---|
| agents | 2 (`infant_0`, `infant_1`), `distance` (0.35 m) apart hip to hip, facing each other |
| body | standing, hip fixed in the world; trunk, legs, left arm held; head and eyes held at rest, looking straight ahead at the partner (no gaze joint in the model). With `assisted_gaze` (the first version) head and eyes are joints the task points at the partner's right hand every control step |
| scene | the floor only: each infant's target is the partner's hand |
| reset | each right arm starts in its own random posture: every joint at its standing-pose angle plus U(-1/2, 1/2) x `start_spread` (0.3) x its range, resampled until the hands touch nothing (seeded by `reset(seed=...)`) |
| action | the right-arm motors (mitten hands: 8, shoulder 3, elbow, wrist 3, fingers; five fingers: 29), plus the expression (`Discrete(7)`) while expressions are on (default) |
| observation | `proprioception` (48 for the mitten body: the right arm's joints and motors; 84 with `assisted_gaze`, whose head and eye angles tell where the partner's hand is), `vestibular` (6), `touch`: the skin of the right hand only by default (hand and fingers, a tenth of the published point density, normal force only: 232 floats for the mitten hand); `touch=True` or a mapping gives more skin. Nothing of the partner before its hand touches the skin: the learner finds the meeting point by the shaped reward |
| reward (both) | with `shaping` (default): `-distance(right palms)` (m) per step (the reward reads the world; it is no observation); `+touch_bonus` (100) on a step of success |
| success (`is_success`) | both right hands feel the partner: each agent's right-hand skin (hand or fingers) senses a force whose source is the other agent, and the two right hands are in contact with each other. The partner's forearm, body or left hand on one's hand does not count (the partner's right hand feels nothing), nor do crossed arms (each right hand on the other's arm) |
| termination | both, on success (if `end_on_touch`, default); truncation at `max_steps` (500 steps, 5 s) |
| infos | `is_success`, `hands_touching` (the same, kept for older code), `hand_feels_partner` (this agent's right-hand skin senses the other agent, on any of its parts), `hand_distance` (m), and the skin's `touch` (who touches which part) |
| options | `touch_bonus` (100.0), `end_on_touch` (True), `distance` (0.35 m, 0.25 to 0.6), `start_spread` (0.3, 0 to 1; 0: the same start every episode), `assisted_gaze` (False), `shaping` (True) |
| scripted partner | `high_five_v0.scripted_env()`: `infant_1` is a `HandOffer` (holds its right hand out, fingers open: `HandOffer(grip=False, release=None)`, palm up; `palm="forward"` for a palm facing the learner). The learner's scripted solution: `HighFiveController` (`mimo_social.partners.controllers.high_five`): reads the partner's palm from the world every 50 ms, solves the arm posture that puts its palm there, facing forward (its fingertips where the palm cannot reach), PD + gravity compensation through its own motors |
| privileged cues | `assisted_gaze` (False): the task points head and eyes at the partner's right hand every control step, so the hand's position reaches the learner as its own head and eye angles (proprioception): off by default, since it leaks the partner's state. With it off the learner's observations do not change when only the partner's hand posture changes, until the hands touch (tested). The contact reaches the learner only through its skin |
| baselines | 20 episodes, seeds 1000-1019, `scripted_env()` (partner `HandOffer`, palm up; `docs/social/high_five.md` gives the script): random (uniform actions) 1 / 20 successes, return -139.9 +- 46.6; zero action 0 / 20, -136.5 +- 5.0; scripted `HighFiveController` 20 / 20, 90.0 +- 2.6, 38.2 steps to the high five; hacks: `ArmSweep` (sweeps the arm across the front, blind) 20 / 20 but less return, 64.9 +- 0.9 (120 steps), a hand held still at the midpoint between the infants (a `HandOffer` as the learner) 0 / 20, -63.5 +- 1.0. Partner palm forward (`HandOffer(grip=False, release=None, palm="forward")`): random 0 / 20, -158.4 +- 11.2; zero 0 / 20, -143.2 +- 5.1; scripted 20 / 20, 88.6 +- 4.2, 48.8 steps; `ArmSweep` 0 / 20, -127.5 +- 0.9; midpoint 0 / 20, -74.8 +- 0.9. PPO (SB3 defaults, 2 seeds each; deterministic evaluation, 10 episodes every 10k env steps): scripted partner, 60k env steps (7-9 min): seed 0 80 % at 20k, 90 % at 61k; seed 1 0 % until 30k, 80 % at 61k; on 20 fresh episodes (seeds 1000-1019) 20 / 20 (return 94.0 +- 0.8, 23 steps) and 19 / 20 (85.5 +- 38.5, 20 steps): the scripted level (`mimo-social compare --task high_five --mode scripted --algos ppo --seeds 2 --steps 60000 --out runs/high_five15_scripted --eval-every 10000 --eval-episodes 10`, then `mimo-social baselines high_five --episodes 20 --seed 1000 --run runs/high_five15_scripted/ppo_seed0 runs/high_five15_scripted/ppo_seed1`). Shared-parameter PPO, two learners, 50k env steps (5-10 min): seed 0 100 % at 51k, seed 1 100 % from 30k; 20 fresh episodes: 100 % for both infants, return 93.4 +- 1.0 (23 steps) and 90.1 +- 4.1 (78 steps) (`mimo-social compare --task high_five --mode shared --algos ppo --seeds 2 --steps 50000 --out runs/high_five15_shared --eval-every 10000 --eval-episodes 10`, then `mimo-social eval runs/high_five15_shared/ppo_seed0 --episodes 20 --seed 1000`): the two learners agree on a meeting point without the cue; the first version with it reached 100 % from 60k env steps (seed 0) |
| sources | not in the MIMo paper: a social task of this package; rationale (touch games, contingency) and figures: `docs/social/high_five.md` |
| version history | v0: first version, with the first env (the infants 0.45 m apart); later in v0: success sensed by both right-hand skins, 0.35 m apart, the `HandOffer` scripted partner, seeded random start postures (`start_spread`); v0, issue 15: the task no longer aims head and eyes at the partner's hand (that is the `assisted_gaze` option, default off: head and eyes held looking ahead, proprioception 84 -> 48), `shaping` option (default on), the scripted learner `HighFiveController` and the hack `ArmSweep`; v0, issue 18: partners of other bodies (`tasks/dyad.py`, docs/bodies.md "As a partner in the social tasks"): placed by their measured reach, each in its own posture, held heads and eyes on the partner's face; an adult partner (`per_agent=[{}, {"body": "adult", "posture": "kneeling"}]`) kneels leaning 15 deg and its `HandOffer` holds its palm where the infant reaches; two 18-month-olds unchanged |

Success is read from the same skin that the agents observe (:mod:`mimo_social.senses.touch`), so
what ends the episode is what both infants perceive. The skin must cover the right hand
(`touch=False`, or an `exclude` that names a right-hand part, raises an error).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Sequence

import mujoco
import numpy as np

from ..body.joint_groups import GAZE_JOINTS, held_posture, right_arm_joints
from ..body.tables import HAND_VERSIONS, load_body
from ..core.kinematics import Gaze, hand_geoms
from ..core.task import Plot, Task, TaskOptions
from ..core.world import AgentSetup
from ..util.checks import ConfigError
from .common import (
    HAND_TOUCH_DENSITY,
    ContactProbe,
    face_to_face,
    hands_setting,
    require_skin,
    right_hand_parts,
    touch_only_on,
)
from .dyad import held_angles, tables_of, task_plan

# 0.35 m: the right hands meet with the arms forward, half stretched; at 0.45 m (the first
# version's distance) only the outstretched fingers meet, and PPO takes many times longer
DISTANCE = 0.35
DISTANCE_RANGE = (0.25, 0.6)


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
    infants (m) and the spread of the random start postures (fraction of each joint's range)."""

    task = "high_five"
    privileged: ClassVar[tuple[str, ...]] = ("assisted_gaze",)
    touch_bonus: float = 100.0
    end_on_touch: bool = True
    distance: float = DISTANCE
    start_spread: float = 0.3
    assisted_gaze: bool = False
    shaping: bool = True

    def __post_init__(self):
        self._number("touch_bonus")
        self._bool("end_on_touch")
        self._number("distance", *DISTANCE_RANGE)
        self._number("start_spread", 0.0, 1.0)
        self._bool("assisted_gaze")
        self._bool("shaping")


GAP_CAP = 0.1   # m: the hand gap plot's top (the hands' surfaces are not measured farther)


class HighFive(Task):
    name = "high_five"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 500
    Options = HighFiveOptions

    def agent_defaults(self, i, settings):
        return {"posture": "standing", "touch": hand_touch(hands_setting(settings))}

    def _held(self, i, config):
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
        plan = task_plan(self, "standing", self.options.distance, self._held,
                         () if self.options.assisted_gaze else (0, 1))
        pos, facing = face_to_face(i, plan.distance)
        tables = tables_of(config)
        require_skin(self.name, f"infant_{i}", config, right_hand_parts(tables),
                     "the high five (the right hands meeting)")
        arm = right_arm_joints(tables)
        gaze = GAZE_JOINTS if self.options.assisted_gaze else ()
        frozen = {**self._held(i, config), **plan.gaze[i]}
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=arm, gaze_joints=gaze)

    def _bind(self, env):
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
        # each arm's joints: qpos/dof addresses, the standing pose's angles (rad) and ranges
        self._arms = []
        rest = w.initial_qpos
        for a in w.agents:
            k = a.actuated_joint_idx
            lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
            self._arms.append((a.qpos_adr[k], a.dof_adr[k], rest[a.qpos_adr[k]].copy(), lo, hi))

    def reset(self, env, rng):
        if getattr(self, "_world", None) is not env.world:
            self._bind(env)
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
        self._touching = False
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
        self._touching = self._felt[0] and self._felt[1] and self._hands_meet(d)
        r = (-dist if self.options.shaping else 0.0) \
            + (self.options.touch_bonus if self._touching else 0.0)
        self._distance = dist
        return np.array([r, r])

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
                "hand_feels_partner": "number", "hand_distance": "number"}

    def terminations(self, env):
        done = self._touching and self.options.end_on_touch
        infos = [{"is_success": self._touching, "hands_touching": self._touching,
                  "hand_feels_partner": self._felt[i], "hand_distance": self._distance}
                 for i in range(2)]
        return np.array([done, done]), infos
