"""Catch (paper Sec. VI-A): a ball falls onto the infant's open right hand; grasp it and hold it.

| | |
|---|---|
| agents | 1 (`infant_0`), five-fingered hands, muscle actuation |
| body | standing, hip fixed; the right arm held stretched forward at the published angles (shoulder 97.4, 45.8, -91.7 deg, elbow -22.9 deg: 1.7, 0.8, -1.6, -0.4 rad), palm up; the thumb held at its rest angles (to the side); everything else held except the right wrist and fingers; head and eyes fixate the ball (set each control step) |
| scene | a ball: radius U(0.5, 2.5) cm, mass U(0.05, 0.5) kg, dropped from 9 cm (+-8 cm) above the palm surface, +-1 cm sideways (drawn each episode) |
| reset | the wrist turned palm up (rotation -80 deg); 50 physics steps without gravity and without the ball settle the hand (the rotation ends near -73 deg, the palm's normal 6 deg off vertical); then the muscles are set to hold the hand there against gravity (activations and controls: the agonists' static activations, 0 to 2.5 % here, see :func:`~mimo_social.partners.controllers.catch.torque_controls`; the learner's first action then keeps or changes them); then the ball is placed, at rest |
| action | 40 muscle controls in [0, 1]: a negative and a positive muscle for each of the right wrist's 3 axes and the 17 finger joints other than the thumb's (with `actuation="spring_damper"`: 20 motors in [-1, 1]) |
| observation | `proprioception` (196, the muscles' activations included), `touch` (1702: the right arm's and hand's skin only, at the published spacing; the normal force only, 1 float a point), `ball_size` (1: radius, m) |
| reward | `-100` (`failure_reward`) when the ball falls more than 10 cm below the palm centre or goes more than 0.5 m from it; on success `+100 + 1 x` the steps left (this one included; `success_reward`, `contact_reward`, `pay_remaining`); otherwise `1 - c_w(a)`: `contact_reward` (1) while any part of the infant touches the ball, 0 when none does, minus the weighted muscle cost (paper eq. for muscles; `cost_weight` 1) |
| success | the right hand has touched the ball for 1 s (100 steps) without a break (`is_success`) |
| termination | on success (held 1 s) or failure (dropped); truncation at 800 steps; `env.dt` 0.01 s (2 physics steps of 5 ms) |
| infos | `is_success`, `dropped`, `parts_touching` (the paper's N_c: the infant's body parts touching the ball), `held_steps`, `ball_radius`, `ball_mass` |
| privileged cues | the task points the head and eyes at the ball every control step (its position reaches the learner as its own head and eye angles); `ball_size` gives the ball's radius directly |
| differences from the paper | (1) the paper's text pays `N_c`, the number of primitives touching the ball, each step; the published code pays +1 a step in contact: we pay +1 (the code), because `N_c` made holding without finishing the optimum (summed `N_c` of the controller holding the ball a whole episode without the success: 3,675, against 447 + 100 for its catches; seeds 0-19). (2) the paper pays +100 on success; we add what the best continuation could still collect (1 a step left), so succeeding beats every non-catching continuation by 100 minus the muscle cost (at most 0.025 a step) -- without it, holding the ball all episode without finishing (782, below) beats a catch (202); `pay_remaining=False` gives the paper's +100. (3) the paper does not say how the episode starts; at zero activation the wrist sags (39 deg in 0.6 s, `wrist_after` in the tests) and the ball rolls off before a finger can close, so the episode starts with the muscles holding the hand (the reset row). (4) the published code's starting wrist angle is not recorded: we turn the wrist until the palm faces up |
| baselines | seeds 0-19, the policies of `tests/tasks/test_catch.py` (`pytest tests/tasks/test_catch.py -m 'slow or not slow'`, ~15 s): the scripted :class:`~mimo_social.partners.controllers.catch.CatchController` (a cupped palm held by PD through the muscles, fingers closing on touch) succeeds in 20 of 20, return 882 +- 8 (seeds 0-99: 99 of 100); with actuation="spring_damper" the controller catches 7 of 10 (seeds 0-9); uniform random controls each step 0 of 20, return -82 (0 of 100); smooth random actions (`core.random_actions`, seeds 2000-2019) 1 of 20, -30; zero action 0 of 20, -92 (0 of 100); keeping the start controls 0 of 20, -86 (0 of 100: they hold the empty hand within 2.4 deg for 0.5 s, but are too soft for a falling ball); holding the ball all episode without the success (the controller with `hold_time` 9 s) 782 +- 8; the controller under the paper's +100 alone (`pay_remaining=False`) 202. `mimo-social baselines catch --episodes 30 --seed 1000 --run <6 runs>` (seeds 1000-1029; docs/baselines.md): scripted 97 % (29/30), 849 +- 168, 125 steps to success; random 0 %, -83; zero 0 %, -92; PPO (SB3 defaults, 100k steps, 3 seeds) 13 / 0 / 0 %, return 71 / -49 / -42; SAC (10k steps, 3 seeds) 0 / 0 / 3 %, -64 / -86 / -39 |
| sources | the MIMo paper (Mattern et al.), Sec. VI-A: the catching demo; the published task's settings (`mimo-figures.md`, MIMoCatch-v0) |
| version history | v0: first version, with the paper's other one-agent demos (stand up, self-body touch); v0, issue 14: reward +1 a step in contact (not `N_c`), success pays the steps left, the episode starts with the muscles holding the hand, scripted controller |

`c_w(a) = sum(a_i^2 fmax_i) / (N sum fmax_i)` is at most `1/N` = 0.025 here; the published code
scaled it by 40 (`task_options={"cost_weight": 40}`). Succeeding is the return optimum while
`cost_weight x 0.025 x 800 < success_reward`, i.e. `cost_weight` < 5.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from gymnasium import spaces

from ..body.joint_groups import GAZE_JOINTS, RIGHT_WRIST, held_posture
from ..body.tables import load_body, subtree
from ..core.kinematics import Gaze, hand_geoms
from ..core.task import Plot, Task, TaskOptions
from ..core.world import AgentSetup, Prop
from ..partners.controllers.catch import torque_controls
from ..util.checks import ConfigError
from .common import geoms_touching, parts_outside, settle

# the published task's shoulder and elbow angles: (1.7, 0.8, -1.6, -0.4) rad
ARM_DEG = {"right_shoulder_horizontal": 97.4, "right_shoulder_abduction": 45.8,
           "right_shoulder_rotation": -91.7, "right_elbow": -22.9}
WRIST = RIGHT_WRIST
WRIST_START_DEG = -80.0   # wrist rotation that turns the palm up (after settling, 6 deg off)
PARKED = (0.0, 1.5, 0.5)  # where the ball waits while the hand settles


def catch_joints(tables) -> tuple[str, ...]:
    """The right wrist's 3 joints and the right fingers' joints except the thumb's."""
    hand = set(subtree(tables, "right_hand")) - {"right_hand"}
    fingers = [j.name for j in tables.joints if j.body in hand and "thumb" not in j.name]
    return WRIST + tuple(fingers)


def touch_exclude(tables) -> tuple[str, ...]:
    """Every body part with skin outside the right arm (upper arm to fingertips)."""
    return parts_outside(tables, ("right_upper_arm",))


@dataclass(frozen=True)
class CatchOptions(TaskOptions):
    """Ball radius and mass ranges (drawn each episode), drop height above the palm and position
    noise (m), hold time (s), failure margins (m), rewards (``pay_remaining``: the success also
    pays ``contact_reward`` for each step left), muscle cost weight, settling steps, and whether
    the muscles start holding the hand (``hold_start``)."""

    task = "catch"
    radius: tuple[float, float] = (0.005, 0.025)
    mass: tuple[float, float] = (0.05, 0.5)
    drop_height: float = 0.09
    position_noise: tuple[float, float, float] = (0.01, 0.01, 0.08)
    hold_time: float = 1.0
    drop_margin: float = 0.1
    max_distance: float = 0.5
    success_reward: float = 100.0
    failure_reward: float = -100.0
    contact_reward: float = 1.0
    pay_remaining: bool = True
    hold_start: bool = True
    cost_weight: float = 1.0
    settle_steps: int = 50

    def __post_init__(self):
        self._numbers("radius", 2, 0.001, 0.1, rising=True,
                      allowed="(low, high) metres, 0.001 <= low <= high <= 0.1")
        self._numbers("mass", 2, 0.001, 10.0, rising=True,
                      allowed="(low, high) kg, 0.001 <= low <= high <= 10")
        self._number("drop_height", 0.0, 1.0)
        self._numbers("position_noise", 3, 0.0, 0.5,
                      allowed="(x, y, z) metres, each from 0 to 0.5")
        self._number("hold_time", 0.0, 60.0)
        self._number("drop_margin", 0.0, 2.0)
        self._number("max_distance", 0.0, 5.0)
        self._number("success_reward")
        self._number("failure_reward")
        self._number("contact_reward", 0.0)
        self._bool("pay_remaining")
        self._bool("hold_start")
        self._number("cost_weight", 0.0)
        self._int("settle_steps", 0, 10_000)


class Catch(Task):
    name = "catch"
    n_agents_range = (1, 1)
    default_n_agents = 1
    default_max_steps = 800
    Options = CatchOptions

    def agent_defaults(self, i, settings):
        tables = load_body("five_fingers")
        return {"hands": "five_fingers", "actuation": "muscle", "posture": "standing",
                "vestibular": False, "expressions": False,
                "touch": {"normal_only": True, "exclude": touch_exclude(tables)}}

    def setup(self, i, config):
        if config.hands != "five_fingers":
            raise ConfigError(f"catch: hands={config.hands!r} not allowed; the task needs "
                              "hands='five_fingers' (it moves the fingers one by one)")
        tables = load_body(config.hands)
        joints = catch_joints(tables)
        frozen = held_posture(tables, keep=joints + GAZE_JOINTS, angles=ARM_DEG)
        return AgentSetup(config, position=(0.0, 0.0), facing=(1.0, 0.0), frozen=frozen,
                          base="fixed", actuated=joints, gaze_joints=GAZE_JOINTS)

    def props(self):
        o = self.options
        return [Prop("ball", "sphere", (o.radius[1],), PARKED, o.mass[1],
                     (0.95, 0.55, 0.15, 1.0))]

    def task_spaces(self, env, i):
        return {"ball_size": spaces.Box(0.0, 1.0, (1,), np.float32)}

    def _bind(self, env):
        w = env.world
        m = w.model
        a = w.agents[0]
        self._world = w
        self._ball_body = w.prop_bodies["ball"]
        self._ball_geom = int(np.flatnonzero(m.geom_bodyid == self._ball_body)[0])
        self._ball_q = w.prop_qpos["ball"]
        self._ball_v = w.prop_dof["ball"]
        self._is_hand = np.zeros(m.ngeom, bool)
        self._is_hand[hand_geoms(w, 0, 0)] = True
        self._is_agent = np.zeros(m.ngeom, bool)
        self._is_agent[a.geom_ids] = True
        self._palm = int(a.palm_sites[0])
        self._gaze = Gaze(w, 0)
        idx = {n: k for k, n in enumerate(a.joint_names)}
        self._wrist_q = int(a.qpos_adr[idx["right_wrist_rotation"]])
        self._wrist_start = float(np.clip(np.deg2rad(WRIST_START_DEG),
                                          *a.joint_range[idx["right_wrist_rotation"]]))
        # the hand's half thickness: the palm box's smallest half size
        hand_body = int(m.site_bodyid[self._palm])
        boxes = [g for g in np.flatnonzero(m.geom_bodyid == hand_body)
                 if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX]
        self._half_thickness = float(min(m.geom_size[g].min() for g in boxes)) if boxes else 0.01

    def set_ball(self, env, radius: float, mass: float) -> None:
        """Give the ball a radius (m) and a mass (kg): the model's size, bounding sphere and box,
        mass and inertia change in place (no recompiling)."""
        m = env.world.model
        g, b = self._ball_geom, self._ball_body
        m.geom_size[g, 0] = radius
        m.geom_rbound[g] = radius
        m.geom_aabb[g, 3:] = radius
        m.body_mass[b] = mass
        m.body_inertia[b] = 0.4 * mass * radius * radius
        self._radius, self._mass = float(radius), float(mass)

    def hold_hand(self, env) -> None:
        """Set the agent's controls (and, for muscles, their activations) to those that hold
        the wrist and fingers where they are against gravity and the joints' springs (static:
        :func:`~mimo_social.partners.controllers.catch.torque_controls` of MuJoCo's bias force)."""
        w = env.world
        m, d = w.model, w.data
        a = w.agents[0]
        act = env.actuation[0]
        mujoco.mj_forward(m, d)
        jk = a.actuated_joint_idx
        dadr = a.dof_adr[jk]
        u = torque_controls(act, d.qpos[a.qpos_adr[jk]], d.qfrc_bias[dadr] - d.qfrc_spring[dadr])
        env.controls[0][:] = u
        act.apply(m, d, env.controls[0])
        if hasattr(act, "activation"):
            act.activation[:] = u.reshape(act.activation.shape)

    def place_ball(self, env, position) -> None:
        """Put the ball at a world position, at rest."""
        env.world.place_prop("ball", position)

    def reset(self, env, rng):
        if getattr(self, "_world", None) is not env.world:
            self._bind(env)
        d = env.world.data
        o = self.options
        d.qpos[self._wrist_q] = self._wrist_start
        self.place_ball(env, PARKED)
        settle(env, o.settle_steps, gravity=False)
        if o.hold_start:
            self.hold_hand(env)
        r = rng.uniform(*o.radius)
        self.set_ball(env, r, rng.uniform(*o.mass))
        palm = d.site_xpos[self._palm].copy()
        noise = rng.uniform(-1.0, 1.0, 3) * np.asarray(o.position_noise)
        height = r + self._half_thickness + o.drop_height
        self.place_ball(env, palm + np.array([0.0, 0.0, height]) + noise)
        self._held = 0
        self._hold_steps = max(1, round(o.hold_time / env.dt))
        self._success = self._dropped = False
        self._n_touch = 0
        self._size = np.array([self._radius], np.float32)
        self.before_physics(env)

    def before_physics(self, env):
        w = env.world
        self._gaze(w.model, w.data, "body", self._ball_body)

    def observe(self, env, i):
        return {"ball_size": self._size.copy()}

    def _touching(self, d):
        """Body parts of the infant touching the ball, and whether the right hand does."""
        other = geoms_touching(d, self._ball_geom)
        if not len(other):
            return 0, False
        mine = other[self._is_agent[other]]
        parts = len(np.unique(self._world.model.geom_bodyid[mine]))
        return parts, bool(np.any(self._is_hand[mine]))

    def rewards(self, env):
        w = env.world
        d = w.data
        o = self.options
        self._n_touch, in_hand = self._touching(d)
        self._held = self._held + 1 if in_hand else 0
        ball = d.xpos[self._ball_body]
        palm = d.site_xpos[self._palm]
        self._dropped = bool(ball[2] < palm[2] - o.drop_margin
                             or np.linalg.norm(ball - palm) > o.max_distance)
        self._success = not self._dropped and self._held >= self._hold_steps
        if self._dropped:
            return np.array([o.failure_reward])
        if self._success:
            left = env.max_steps - env.steps + 1 if o.pay_remaining else 0
            return np.array([o.success_reward + o.contact_reward * max(left, 0)])
        cost = env.actuation[0].weighted_cost(env.controls[0])
        touch = o.contact_reward if self._n_touch else 0.0
        return np.array([touch - o.cost_weight * cost])

    def plots(self):
        """Reward, the ball's height above the palm, the body parts touching it and success
        (held long enough)."""
        def above(env):
            d = env.world.data
            return (d.xpos[self._ball_body, 2] - d.site_xpos[self._palm, 2],)
        return [Plot.reward(), Plot("ball_above_palm", "m", above),
                Plot("parts_touching", "parts", lambda env: (self._n_touch,)),
                Plot("success", "0/1", lambda env: (self._success,))]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"is_success": "number", "dropped": "number", "parts_touching": "number",
                "held_steps": "number", "ball_radius": "number", "ball_mass": "number"}

    def terminations(self, env):
        return (np.array([self._success or self._dropped]),
                [{"is_success": self._success, "dropped": self._dropped,
                  "parts_touching": self._n_touch, "held_steps": self._held,
                  "ball_radius": self._radius, "ball_mass": self._mass}])
