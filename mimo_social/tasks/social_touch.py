"""Social touch: a sitting infant touches a named part of its partner's body, who feels it.

| | |
|---|---|
| agents | 2: the toucher `infant_0` and the touched infant `infant_1`, sitting cross-legged face to face, `distance` (0.28 m) apart hip to hip, within arm's reach; exactly two (a third raises an error) |
| body | hips fixed on the floor, legs crossed; the toucher: everything but the right arm held, the trunk bent forward towards the partner (lower trunk 20 deg, the upper trunk coupled), the left arm hanging at its side; the touched infant: everything but both arms held, leaning back a little (6 deg); heads upright; the eyes are set by the task each control step: the toucher's fixate the target part, the touched infant's the toucher's right hand |
| scene | the floor only: the target is a part of the partner's body |
| reset | the toucher's right arm starts out to its side, touching nothing; the touched infant's hands rest on its legs; the target part is drawn uniformly from `targets` (task option `target` fixes it) |
| action | `infant_0`: the right arm's motors (mitten hands: 8, shoulder 3, elbow, wrist 3, fingers; five fingers: 29) in [-1, 1]; `infant_1`: both arms' motors (16; 58), zero in the scripted env (`Still` partner); expressions off by default (`expressions=True` adds them) |
| observation | both: `proprioception` (toucher 72, touched infant 120; the toucher's eye angles tell where the target is), `touch` (normal force only, 1 float a point): the toucher's skin covers its right arm (upper arm to fingertips, a tenth of the published point density: 242 floats), the touched infant's its whole body (a quarter of the density: 1400); the toucher also gets `target`, one-hot over `targets` (9 for the mitten body) |
| reward (both) | `-distance(toucher's right fingertips, target part's centre of mass)` (m) per step, `+success_reward` (100) on success |
| success (`is_success`) | the toucher's right hand (hand or fingers) touches the target part and the touched infant's skin feels it there, with the toucher as the source |
| termination | both, on success (if `end_on_touch`, default); touching another part does not end the episode; truncation at `max_steps` (500 steps, 5 s) |
| infos (both) | `target_part`, `is_success`, `touched_parts` (the partner's parts the toucher's right hand touches this step), `target_felt` (the touched infant's skin feels the toucher on the target part), `fingertip_distance` (m), and each agent's own skin record `touch` |
| options | `targets` (None: :data:`DEFAULT_TARGETS`, those of them in the partner's body), `target` (None), `success_reward` (100.0), `end_on_touch` (True), `distance` (0.28 m, 0.25 to 0.4) |
| privileged cues | the task points the toucher's eyes at the target part every control step (its eye angles tell where the target is) and gives the target as a one-hot code; the touched infant's eyes follow the toucher's right hand; the touch itself only through the skins |
| baselines | random policies (uniform actions, 20 episodes, seeds 0-19; no command in the package): `parallel_env()`, both random: return of `infant_0` -16.7 +- 80.7, 11 / 20 successes, 354 steps; `scripted_env()`, random toucher with the `Still` partner: -19.2 +- 73.7, 10 / 20, 371 steps. PPO, scripted `Still` partner, 2 seeds, 61k env steps (4.5-5 min): evaluation success (10 episodes) 0 % -> 20 % / 60 % at the end, mean return -153 -> -43 / +10: not yet better than random (`mimo-social compare --task social_touch --mode scripted --algos ppo --seeds 2 --steps 60000 --out runs/social_touch --eval-every 5000 --eval-episodes 10`) |
| sources | not in the MIMo paper: a social task of this package, the social version of self-body touch (paper Sec. VI-A); rationale (touch, body-part games) and figures: `docs/social/social_touch.md` |
| version history | v0: first version, with the skin-sensed high five |

Targets by default are the partner's parts within the toucher's reach in this pose: head, upper
and lower trunk, the partner's left arm (upper arm, lower arm, hand and the mitten's fingers: it
is on the toucher's right) and left thigh and shin; the eyes are never targets. With another
`distance`, give `targets` reachable there. The toucher's trunk is held bent forward: free, with
zero command, it sags forward under gravity until the heads meet.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from ..body.joint_groups import (
    EYE_GAZE_JOINTS,
    both_arms_joints,
    held_posture,
    right_arm_joints,
)
from ..body.tables import load_body, subtree
from ..core.kinematics import Gaze, hand_geoms
from ..core.task import Task, TaskOptions
from ..core.world import AgentSetup
from ..util.checks import ConfigError
from .common import (
    CROSS_LEGGED_DEG,
    hands_setting,
    require_skin,
    right_hand_parts,
    skin_parts,
    touch_only_on,
)

TOUCHER, TOUCHED = 0, 1
DISTANCE = 0.28
DISTANCE_RANGE = (0.25, 0.4)   # closer, the crossed feet meet; farther, little is in reach
# cross-legged (the legs of the self-body pose)
SITTING_DEG = {k: v for k, v in CROSS_LEGGED_DEG.items()
               if "hip" in k or "knee" in k or "ankle" in k}
# the touched infant leans back a little, so that the leaning toucher's head stays clear of it
RECLINE_DEG = -6.0
# the toucher's lower trunk bend (the upper trunk follows, coupled): towards the partner
LEAN_DEG = 20.0
# the toucher's left arm hangs at its side, out of the way
SIDE_ARM_DEG = {"left_shoulder_abduction": 15.0, "left_elbow": -10.0}
# the toucher's right arm at the start: out to its side, elbow a little bent, touching nothing
ARM_START_DEG = {"right_shoulder_abduction": 45.0, "right_shoulder_horizontal": 0.0,
                 "right_elbow": -30.0}
# the partner's parts that the toucher's right hand reaches at the default distance: each was
# touched by at least 20 of 4,000 uniformly random postures of the toucher's right arm; the hip
# (5) and the eyes (5) were touched by next to none, every other part by none
DEFAULT_TARGETS = ("head", "upper_body", "lower_body",
                   "left_upper_arm", "left_lower_arm", "left_hand", "left_fingers",
                   "left_upper_leg", "left_lower_leg")


@dataclass(frozen=True)
class SocialTouchOptions(TaskOptions):
    """The partner's target parts (None: :data:`DEFAULT_TARGETS`), one fixed target (None:
    drawn each episode), the reward for a felt touch of the target, whether it ends the
    episode, and the distance between the infants (m)."""

    task = "social_touch"
    targets: tuple[str, ...] | None = None
    target: str | None = None
    success_reward: float = 100.0
    end_on_touch: bool = True
    distance: float = DISTANCE

    def __post_init__(self):
        self._names("targets", "body part names of the partner")
        self._name("target", "a body part name from targets")
        self._number("success_reward")
        self._bool("end_on_touch")
        self._number("distance", *DISTANCE_RANGE)


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
                              "(a dyad: the toucher infant_0 and the touched infant_1)")
        super().__init__(n_agents, options, **values)
        self.targets: tuple[str, ...] = ()

    def agent_defaults(self, i, settings):
        common = {"posture": "sitting", "vestibular": False, "expressions": False}
        if i == TOUCHER:
            tables = load_body(hands_setting(settings))
            return dict(common, touch=touch_only_on(tables, subtree(tables, "right_upper_arm")))
        return dict(common, touch={"density": 0.25, "normal_only": True})

    # -- building ------------------------------------------------------------------------------
    def _resolve_targets(self, tables) -> tuple[str, ...]:
        parts = skin_parts(tables)
        given = self.options.targets
        if given is None:
            targets = tuple(p for p in DEFAULT_TARGETS if p in parts)
        else:
            bad = [p for p in given if p not in parts]
            if bad:
                raise ConfigError(f"social_touch: targets {bad} are not body parts of the "
                                  f"partner ({tables.hands} body); body parts: {list(parts)}")
            targets = tuple(given)
        fixed = self.options.target
        if fixed is not None and fixed not in targets:
            raise ConfigError(f"social_touch: target={fixed!r} not allowed; one of "
                              f"{list(targets)}")
        return targets

    def setup(self, i, config):
        dist = self.options.distance
        pos = (0.0, 0.0) if i == TOUCHER else (dist, 0.0)
        facing = (dist, 0.0) if i == TOUCHER else (0.0, 0.0)
        tables = load_body(config.hands)
        if i == TOUCHER:
            actuated = right_arm_joints(tables)
            angles = {**SITTING_DEG, **SIDE_ARM_DEG, "lower_trunk_bend": LEAN_DEG}
            require_skin(self.name, "infant_0", config, right_hand_parts(tables),
                         "the touch it gives")
        else:
            self.targets = self._resolve_targets(tables)
            actuated = both_arms_joints(tables)
            angles = {**SITTING_DEG, "lower_trunk_bend": RECLINE_DEG}
            require_skin(self.name, "infant_1", config, self.targets,
                         "the touch it receives on every target part")
        frozen = held_posture(tables, keep=actuated + EYE_GAZE_JOINTS, angles=angles)
        return AgentSetup(config, position=config.position or pos, facing=config.facing or facing,
                          frozen=frozen, base="fixed", actuated=actuated,
                          gaze_joints=EYE_GAZE_JOINTS)

    def task_spaces(self, env, i):
        if i == TOUCHER:
            return {"target": spaces.Box(0.0, 1.0, (len(self.targets),), np.float32)}
        return {}

    def _bind(self, env):
        w = env.world
        m = w.model
        self._world = w
        toucher, touched = w.agents[TOUCHER], w.agents[TOUCHED]
        self._touch = env.systems.get("touch")
        self._gaze = [Gaze(w, TOUCHER), Gaze(w, TOUCHED)]
        self._is_hand = np.zeros(m.ngeom, bool)
        self._is_hand[hand_geoms(w, TOUCHER, 0)] = True
        # every geom of the touched infant -> its body id; every other geom -> -1
        self._partner_body = np.full(m.ngeom, -1, dtype=np.intp)
        self._partner_body[touched.geom_ids] = m.geom_bodyid[touched.geom_ids]
        prefix = len(touched.name) + 1
        self._part_name = {int(b): m.body(int(b)).name[prefix:]
                           for b in np.unique(m.geom_bodyid[touched.geom_ids])}
        self._target_bodies = np.array([m.body(f"{touched.name}/{t}").id for t in self.targets],
                                       dtype=np.intp)
        self._fingertip = int(toucher.fingertip_sites[0])
        self._palm = int(toucher.palm_sites[0])
        idx = {n: k for k, n in enumerate(toucher.joint_names)}
        ks = [idx[n] for n in ARM_START_DEG if n in idx]
        self._arm_qpos = toucher.qpos_adr[ks]
        self._arm_start = np.clip(np.deg2rad([ARM_START_DEG[toucher.joint_names[k]] for k in ks]),
                                  toucher.joint_range[ks, 0], toucher.joint_range[ks, 1])
        self._source = toucher.name

    def reset(self, env, rng):
        if getattr(self, "_world", None) is not env.world:
            self._bind(env)
        env.world.data.qpos[self._arm_qpos] = self._arm_start
        fixed = self.options.target
        self._target = (self.targets.index(fixed) if fixed is not None
                        else int(rng.integers(len(self.targets))))
        self._onehot = np.zeros(len(self.targets), np.float32)
        self._onehot[self._target] = 1.0
        self._success = self._felt = False
        self._touched: list[str] = []
        self._distance = float("nan")
        self.before_physics(env)

    @property
    def target(self) -> str:
        """The current episode's target part (of the touched infant's body)."""
        return self.targets[self._target]

    def before_physics(self, env):
        m, d = env.world.model, env.world.data
        self._gaze[TOUCHER](m, d, "body", self._target_bodies[self._target])
        self._gaze[TOUCHED](m, d, "site", self._palm)

    def observe(self, env, i):
        return {"target": self._onehot.copy()} if i == TOUCHER else {}

    def _hand_contacts(self, d) -> np.ndarray:
        """Body ids of the touched infant's parts in contact with the toucher's right hand."""
        n = d.ncon
        if n == 0:
            return np.empty(0, np.intp)
        c = d.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        h1, h2 = self._is_hand[g1], self._is_hand[g2]
        body = self._partner_body[np.where(h1, g2, g1)]
        keep = (h1 ^ h2) & (body >= 0) & (c.dist[:n] <= 0.0)
        return body[keep]

    def rewards(self, env):
        d = env.world.data
        target = self._target_bodies[self._target]
        bodies = self._hand_contacts(d)
        self._touched = sorted({self._part_name[int(b)] for b in bodies}) if len(bodies) else []
        self._felt = False
        if np.any(bodies == target):
            felt = self._touch.touched_by(TOUCHED).get(self.target)
            self._felt = bool(felt is not None and self._source in felt["agents"])
        self._success = self._felt
        self._distance = float(np.linalg.norm(d.site_xpos[self._fingertip] - d.xipos[target]))
        r = -self._distance + (self.options.success_reward if self._success else 0.0)
        return np.array([r, r])

    def terminations(self, env):
        done = self._success and self.options.end_on_touch
        info = {"target_part": self.target, "is_success": self._success,
                "touched_parts": self._touched, "target_felt": self._felt,
                "fingertip_distance": self._distance}
        return np.array([done, done]), [dict(info, touched_parts=list(self._touched))
                                         for _ in range(2)]
