"""The catch task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import mujoco
import numpy as np
from gymnasium import spaces

from ...body.joint_groups import GAZE_JOINTS, RIGHT_WRIST, held_posture
from ...body.tables import load_body, subtree
from ...core.kinematics import Gaze, hand_geoms
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup, Prop
from ...partners.base import torque_controls
from ...util.checks import ConfigError
from ..common import geoms_touching, parts_outside, settle
from ...core.factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "Catch", "CatchOptions"]

# the published task's shoulder and elbow angles: (1.7, 0.8, -1.6, -0.4) rad
ARM_DEG = {"right_shoulder_horizontal": 97.4, "right_shoulder_abduction": 45.8,
           "right_shoulder_rotation": -91.7, "right_elbow": -22.9}
WRIST = RIGHT_WRIST
WRIST_START_DEG = -80.0   # wrist rotation that turns the palm up (after settling, 6 deg off)
#: the warning of the paper's reward (``pay_remaining=False``), with the measured returns
PAPER_REWARD_WARNING = (
    "catch: task option pay_remaining=False (the paper's +100 on success alone) makes holding "
    "the ball pay more than catching it: with the default options, holding it all episode "
    "without finishing earns 782 +- 8, catching it (CatchController) 202 +- 4 (seeds 0-19); a "
    "learner that maximises this return learns to hold, not to catch. The default "
    "pay_remaining=True also pays the steps left on success (catching: 882 +- 8)")
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
        if not self.pay_remaining:
            warnings.warn(PAPER_REWARD_WARNING, UserWarning, stacklevel=3)
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

    def bind(self, env):
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

    @property
    def ball_radius(self) -> float:
        """This episode's ball radius (m)."""
        return self._radius

    @property
    def ball_mass(self) -> float:
        """This episode's ball mass (kg)."""
        return self._mass

    def hold_hand(self, env) -> None:
        """Set the agent's controls (and, for muscles, their activations) to those that hold
        the wrist and fingers where they are against gravity and the joints' springs (static:
        :func:`~mimo_social.partners.base.torque_controls` of MuJoCo's bias force)."""
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
        self._held_for = 0
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
        self._held_for = self._held_for + 1 if in_hand else 0
        ball = d.xpos[self._ball_body]
        palm = d.site_xpos[self._palm]
        self._dropped = bool(ball[2] < palm[2] - o.drop_margin
                             or np.linalg.norm(ball - palm) > o.max_distance)
        self._success = not self._dropped and self._held_for >= self._hold_steps
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
                  "parts_touching": self._n_touch, "held_steps": self._held_for,
                  "ball_radius": self._radius, "ball_mass": self._mass}])


# -- the env factories (``mimo_social.envs.catch_v0`` re-exports them) --------------------

def parallel_env(**kwargs):
    return make_parallel(Catch, **kwargs)


def env(**kwargs):
    return make_aec(Catch, **kwargs)
