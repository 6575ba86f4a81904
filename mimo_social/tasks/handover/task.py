"""The handover task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import mujoco
import numpy as np

from ...body.joint_groups import GAZE_JOINTS, held_posture, right_arm_joints
from ...body.tables import load_body
from ...core.kinematics import Gaze, hand_geoms
from ...core.task import Plot, Task, TaskOptions
from ...core.world import AgentSetup, Prop
from ...partners.hand_offer import OPEN_FINGERS_DEG, HandOffer, offer_posture
from ...partners.offer_target import adapts, reach_target

__all__ = ["Handover", "HandoverOptions", "scripted_giver", "OFFER_TARGET", "READY_OFFSET",
           "parallel_env", "env", "scripted_env"]
from ...util.checks import ConfigError
from ..common import parts_outside
from ..dyad import held_angles, tables_of, task_plan
from ...core.factory import make_aec, make_parallel

RECEIVER, GIVER = 0, 1
PARKED = (0.2, 1.5, 0.5)             # where the ball is built (the reset moves it to the palm)
OFFER_TARGET = (0.18, 0.10, -0.08)   # the giver's palm: m from its right shoulder (fwd, left, up)
#: where an adult giver holds its palm centre: m from the receiver's right shoulder (forward,
#: left, up, for an 18-month-old's arm): where the infant giver's palm is held for it at the
#: default `offer_target` (measured on `handover_v0.scripted_env()`: the giver's
#: HandOffer.target_position minus infant_0's right shoulder)
ADULT_OFFER = (0.170, 0.110, -0.080)
#: how far an adult giver tips its palm to present the ball (HandOffer's ``present``): the
#: adult's larger hand cups the ball; tipped as an infant's (0.75) it keeps it in 2 of 4
#: episodes (seeds 0-3), tipped 1.5 it hands it over in 4 of 4 (tests/tasks/test_partner_bodies.py)
ADULT_PRESENT = 1.5
BALL_TOWARD_FINGERS = 0.01           # m from the palm centre toward the fingers: the ball's rest
#: the ready point, where the scripted giver waits for the receiver's open hand before it tips
#: the ball into it: m from the offered ball's centre at reset, in the receiver's heading frame
#: (forward, left, up): beside the giver's palm on its little-finger side, lower than the ball;
#: there the receiver's palm centre is ~5 cm from the giver's (HandOffer's ``ready_radius``: 8
#: cm). The shaping leads the receiver's palm centre here; ReceiveController cups its hand here
READY_OFFSET = (0.01, -0.055, -0.047)


def arms_only_touch(tables) -> dict:
    """Touch settings: skin on both arms and hands only, the normal force only."""
    return {"normal_only": True,
            "exclude": parts_outside(tables, ("right_upper_arm", "left_upper_arm"))}


@dataclass(frozen=True)
class HandoverOptions(TaskOptions):
    """Distance (m), ball radius (m) and mass (kg), hold time (s), receiver segments needed,
    how far past the ball's centre a finger must touch it for a grasp (``grasp_height``, in ball
    radii, away from the palm), drop height (m), rewards, progress shaping and its scales (per m
    toward the ready point, per unit of the palm normal's upward component, per unit of finger
    closure with the ball in the hand), giver settling time (s), receiver arm noise (deg), the
    giver's offer target (m from its right shoulder: forward, left, up), whether success ends the
    episode, and whether the task aims the eyes (a privileged cue)."""

    task = "handover"
    privileged: ClassVar[tuple[str, ...]] = ("assisted_gaze",)
    distance: float = 0.34
    ball_radius: float = 0.03
    ball_mass: float = 0.03
    hold_time: float = 0.3
    min_parts: int = 2
    grasp_height: float = 0.0
    drop_height: float = 0.25
    success_reward: float = 10.0
    failure_reward: float = -10.0
    shaping: bool = True
    shaping_scale: float = 10.0
    palm_up_scale: float = 2.0
    grip_scale: float = 2.0
    settle_time: float = 0.3
    arm_noise: float = 10.0
    offer_target: tuple[float, float, float] | None = OFFER_TARGET
    end_on_success: bool = True
    assisted_gaze: bool = False

    def __post_init__(self):
        self._number("distance", 0.3, 0.8)
        self._number("ball_radius", 0.015, 0.045)
        self._number("ball_mass", 0.005, 0.3)
        self._number("hold_time", 0.0, 5.0)
        self._int("min_parts", 1, 10)
        self._number("grasp_height", -1.0, 1.0)
        self._number("drop_height", 0.0, 0.5)
        self._number("success_reward", -1e6, 1e6)
        self._number("failure_reward", -1e6, 1e6)
        self._bool("shaping")
        self._number("shaping_scale", 0.0, 1000.0)
        self._number("palm_up_scale", 0.0, 1000.0)
        self._number("grip_scale", 0.0, 1000.0)
        self._number("settle_time", 0.0, 2.0)
        self._number("arm_noise", 0.0, 45.0)
        self._bool("end_on_success")
        self._bool("assisted_gaze")
        t = self.offer_target
        if t is not None:
            arr = np.zeros(0)
            if not isinstance(t, (str, bytes)):
                try:
                    arr = np.asarray(t, dtype=float)
                except (TypeError, ValueError):
                    pass
            if arr.shape != (3,) or not np.isfinite(arr).all() or np.linalg.norm(arr) > 0.5:
                raise ConfigError(f"handover: task option offer_target={t!r} not allowed; "
                                  "allowed: None or (forward, left, up) in metres from the "
                                  "giver's right shoulder, within 0.5 m")
            self._put("offer_target", tuple(float(x) for x in arr))


def scripted_giver(options: HandoverOptions | None = None) -> HandOffer:
    """The handover's scripted giver: :class:`~mimo_social.partners.hand_offer.HandOffer`
    offering at the options' ``offer_target``, handing the ball over into the receiver's open
    hand (``release="on_hold"``: it lets go only once that hand carries the ball)."""
    o = options if options is not None else HandoverOptions()
    return HandOffer(target=o.offer_target, grip=True, release="on_hold",
                     adult_reach_to=ADULT_OFFER, adult_present=ADULT_PRESENT)


class Handover(Task):
    name = "handover"
    n_agents_range = (2, 2)
    default_n_agents = 2
    default_max_steps = 600
    Options = HandoverOptions

    # -- building ------------------------------------------------------------------------------
    def agent_defaults(self, i, settings):
        return {"hands": "five_fingers", "posture": "standing", "vestibular": False,
                "expressions": False, "touch": arms_only_touch(load_body("five_fingers"))}

    def setup(self, i, config):
        who = self.agent_name(i)
        if config.hands != "five_fingers":
            raise ConfigError(f"handover: {who}: hands={config.hands!r} not allowed; the task "
                              "needs hands='five_fingers' (the ball is held between the fingers)")
        allowed = ("standing", "kneeling", "sitting") if config.body == "adult" else ("standing",)
        if config.posture not in allowed:
            raise ConfigError(f"handover: {who}: posture={config.posture!r} not allowed; "
                              f"allowed for body={config.body!r}: {list(allowed)} (the task "
                              "places infants standing, hip fixed)")
        # two 18-month-olds stand `distance` apart; other bodies at the distance scaled with
        # their reach, looking at each other's face (tasks/dyad.py)
        plan = task_plan(self, "standing", self.options.distance, self.held_joints,
                         () if self.options.assisted_gaze else (0, 1), ADULT_OFFER)
        dist = plan.distance
        pos = (0.0, 0.0) if i == RECEIVER else (dist, 0.0)
        facing = (dist, 0.0) if i == RECEIVER else (0.0, 0.0)
        tables = tables_of(config)
        arm = right_arm_joints(tables)
        gaze = GAZE_JOINTS if self.options.assisted_gaze else ()
        frozen = {**self.held_joints(i, config), **plan.gaze[i]}
        return AgentSetup(config, position=config.position or pos,
                          facing=config.facing or facing, frozen=frozen, base="fixed",
                          actuated=arm, gaze_joints=gaze)

    def held_joints(self, i, config):
        """Agent i's held joints (rad): all but the right arm (and head and eyes with
        ``assisted_gaze``); standing knees a little bent, or its own posture's angles (an adult
        leaning toward the infant)."""
        tables = tables_of(config)
        gaze = GAZE_JOINTS if self.options.assisted_gaze else ()
        angles = held_angles(config, "standing", {"right_knee": -5, "left_knee": -5}, lean=True)
        return held_posture(tables, keep=right_arm_joints(tables) + gaze, angles=angles)

    def props(self):
        o = self.options
        return [Prop("ball", "sphere", (o.ball_radius,), PARKED, o.ball_mass,
                     (0.95, 0.55, 0.15, 1.0))]

    # -- index tables (once per world) ---------------------------------------------------------
    def bind(self, env):
        w = env.world
        m = w.model
        self._world = w
        self._ball_body = w.prop_bodies["ball"]
        self._ball_geom = int(np.flatnonzero(m.geom_bodyid == self._ball_body)[0])
        self._ball_q = w.prop_qpos["ball"]
        self._ball_v = w.prop_dof["ball"]
        self._hand_of = np.full(m.ngeom, -1, np.intp)   # geom -> 0 receiver / 1 giver right hand
        for i in (RECEIVER, GIVER):
            self._hand_of[hand_geoms(w, i, 0)] = i
        self._geom_body = m.geom_bodyid.astype(np.intp)
        self._gaze = [Gaze(w, i) for i in (RECEIVER, GIVER)] if self.options.assisted_gaze \
            else []
        r = w.agents[RECEIVER]
        self._receiver_palm = int(r.palm_sites[0])
        self._offer = HandOffer(target=self.options.offer_target, release=None,
                                adult_reach_to=ADULT_OFFER)
        self._giver_palm = int(w.agents[GIVER].palm_sites[0])
        self._fingers = [self._finger_tables(w, i) for i in (RECEIVER, GIVER)]
        self._hand_body = [int(m.site_bodyid[w.agents[i].palm_sites[0]]) for i in (0, 1)]
        # the receiver's four fingers' flexion joints (qpos addresses, upper limits): the closure
        tables = self._fingers[RECEIVER]
        self._flex_q = np.concatenate([q for q, _, _ in tables])
        self._flex_top = np.concatenate([top for _, top, _ in tables])
        boxes = [k for k in np.flatnonzero(m.geom_bodyid == self._hand_body[GIVER])
                 if m.geom_type[k] == mujoco.mjtGeom.mjGEOM_BOX]
        self._half_thickness = float(min(m.geom_size[k].min() for k in boxes)) if boxes else 0.006

    @staticmethod
    def _finger_tables(w, i):
        """Per finger of agent i's right hand (not the thumb): qpos addresses of mcp, pip, dip,
        their upper limits, and the finger's geoms."""
        m = w.model
        a = w.agents[i]
        out = []
        for finger in ("index", "middle", "ring", "little"):
            ks = [k for k, n in enumerate(a.joint_names)
                  if n.startswith(f"right_{finger}_") and n.split("_")[-1] in ("mcp", "pip", "dip")]
            bodies = [m.body(f"{a.name}/right_{finger}_{part}").id
                      for part in ("proximal", "middle", "distal")]
            geoms = np.flatnonzero(np.isin(m.geom_bodyid, bodies))
            out.append((a.qpos_adr[ks], a.joint_range[ks, 1], geoms))
        return out

    # -- running -------------------------------------------------------------------------------
    def place_ball(self, env, position) -> None:
        """Put the ball at a world position, at rest."""
        env.world.place_prop("ball", position)

    def ball_in_palm(self, env, i: int = GIVER) -> np.ndarray:
        """Where the ball rests on agent i's right palm: on the palm's normal, touching it."""
        w = env.world
        d = w.data
        R = d.xmat[self._hand_body[i]].reshape(3, 3)
        normal = -R[:, 1]  # the right palm faces the hand's -y
        r = self.options.ball_radius
        return (d.site_xpos[w.agents[i].palm_sites[0]]
                + (self._half_thickness + r + 0.001) * normal + BALL_TOWARD_FINGERS * R[:, 2])

    def put_ball_in_hand(self, env, i: int, target=None) -> None:
        """Pose agent i's right arm in the offer posture (palm up; ``target`` as for
        :func:`~mimo_social.partners.hand_offer.offer_posture`), lay the ball in its palm and
        curl its fingers onto it (used at reset for the giver; tests use it for the receiver)."""
        w = env.world
        a = w.agents[i]
        if adapts(w, i):   # an adult (or a larger infant) offers where the other reaches
            target = reach_target(w, i, ADULT_OFFER)
        posture = offer_posture(w, i, None, target)
        d = w.data
        for k in a.actuated_joint_idx:
            n = a.joint_names[k]
            angle = posture.get(n, np.deg2rad(OPEN_FINGERS_DEG.get(n, 0.0)))
            d.qpos[a.qpos_adr[k]] = np.clip(angle, *a.joint_range[k])
        mujoco.mj_kinematics(w.model, d)
        self.place_ball(env, self.ball_in_palm(env, i))
        self._close_fingers(env, i)

    def reset(self, env, rng):
        w = env.world
        m, d = w.model, w.data
        o = self.options
        r = w.agents[RECEIVER]
        # the receiver's arm: the hanging posture, shifted at random
        k = r.actuated_joint_idx[:7]
        noise = np.deg2rad(o.arm_noise) * rng.uniform(-1.0, 1.0, len(k))
        d.qpos[r.qpos_adr[k]] = np.clip(d.qpos[r.qpos_adr[k]] + noise, r.joint_range[k, 0],
                                        r.joint_range[k, 1])
        mujoco.mj_kinematics(m, d)
        # the giver: arm in the offer posture, the ball in its palm, fingers curled onto it
        self.put_ball_in_hand(env, GIVER, o.offer_target)
        self._settle(env)
        # the ready point: beside the offered ball, where the scripted giver waits (READY_OFFSET)
        R = d.xmat[r.root_body].reshape(3, 3)
        heading = float(np.arctan2(R[1, 0], R[0, 0]))
        fwd = np.array([np.cos(heading), np.sin(heading), 0.0])
        left = np.array([-fwd[1], fwd[0], 0.0])
        f, l, u = READY_OFFSET
        self._ready_point = d.xpos[self._ball_body] + f * fwd + l * left + (0.0, 0.0, u)
        self._held_for = 0
        self._hold_steps = max(1, int(round(o.hold_time / env.dt)))
        self._success = self._dropped = False
        self._holder = "giver"
        self._parts = 0
        self._grasped = False
        self.before_physics(env)
        self._distance = self._palm_distance(d)
        self._potential = self._shaping_potential(d, False)

    def _close_fingers(self, env, i: int):
        """Curl each of agent i's four fingers (mcp, pip, dip together, from straight toward
        their upper limits) until it is within 1 mm of the ball: the grasp starts in contact,
        without the impact of fingers closing dynamically."""
        m, d = env.world.model, env.world.data
        ball = self._ball_geom
        for qadr, top, geoms in self._fingers[i]:
            last = np.zeros(len(qadr))
            for alpha in np.linspace(0.0, 1.0, 41):
                d.qpos[qadr] = alpha * top
                mujoco.mj_kinematics(m, d)
                if min(mujoco.mj_geomDistance(m, d, ball, int(g), 0.01, None)
                       for g in geoms) < 0.001:
                    break
                last = alpha * top
            d.qpos[qadr] = last
        mujoco.mj_kinematics(m, d)

    def _settle(self, env):
        """The giver's own motors hold the offer posture and close the fingers on the ball for
        ``settle_time`` (the receiver is still); time restarts at 0."""
        w = env.world
        m, d = w.model, w.data
        n = int(round(self.options.settle_time / env.dt))
        offer = self._offer
        giver = env.possible_agents[GIVER]
        offer.reset(env, giver, np.random.default_rng(0))
        act = env.actuation[GIVER]
        for _ in range(n):
            u = offer.act(env, giver, None)
            act.apply(m, d, np.asarray(u["motors"] if isinstance(u, dict) else u, float))
            env.advance(env.frame_skip)
        act.reset(m, d)
        env.controls[GIVER][:] = 0.0
        d.time = 0.0
        mujoco.mj_forward(m, d)

    def before_physics(self, env):
        if not self._gaze:
            return
        w = env.world
        m, d = w.model, w.data
        self._gaze[RECEIVER](m, d, "body", self._ball_body)
        self._gaze[GIVER](m, d, "site", self._receiver_palm)

    def _palm_distance(self, d) -> float:
        """Distance (m) from the receiver's right palm centre to the ball's centre."""
        return float(np.linalg.norm(d.site_xpos[self._receiver_palm]
                                    - d.xpos[self._ball_body]))

    def _shaping_potential(self, d, in_hand: bool) -> float:
        """The shaping's potential (the reward is its increase): minus ``shaping_scale`` x the
        distance (m) from the receiver's right palm centre to the ready point, plus
        ``palm_up_scale`` x the palm normal's upward component (-1 to 1), plus, while the ball
        touches the receiver's hand and not the giver's (``in_hand``), ``grip_scale`` x the
        closure of its four fingers (mcp, pip, dip: mean fraction of their flexion range,
        0 straight, 1 fully flexed)."""
        o = self.options
        ready = float(np.linalg.norm(d.site_xpos[self._receiver_palm] - self._ready_point))
        self._ready_distance = ready
        up = -float(d.xmat[self._hand_body[RECEIVER], 7])   # the right palm faces the hand's -y
        phi = -o.shaping_scale * ready + o.palm_up_scale * up
        if in_hand:
            closure = np.clip(d.qpos[self._flex_q] / self._flex_top, 0.0, 1.0)
            phi += o.grip_scale * float(closure.mean())
        return phi

    def _contacts(self, d):
        """How the ball is touched now: the segments of the receiver's right hand touching it,
        whether the giver's right hand touches it, and whether the receiver's hand is closed
        around it: touching it on both sides of its centre along the palm's normal, at least
        ``grasp_height`` radii past the centre away from the palm (fingers curled over it) and
        on the palm's side (the height of each contact point over the ball's centre, along the
        normal out of the receiver's palm)."""
        n = d.ncon
        if n == 0:
            return 0, False, False
        c = d.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        ob = self._ball_geom
        other = np.where(g1 == ob, g2, np.where(g2 == ob, g1, -1))
        idx = np.flatnonzero((other >= 0) & (c.dist[:n] <= 0.0))
        other = other[idx]
        whose = self._hand_of[other]
        mine = whose == RECEIVER
        giver = bool(np.any(whose == GIVER))
        if not mine.any():
            return 0, giver, False
        parts = len(np.unique(self._geom_body[other[mine]]))
        normal = -d.xmat[self._hand_body[RECEIVER]].reshape(3, 3)[:, 1]  # out of the palm
        height = (c.pos[idx[mine]] - d.xpos[self._ball_body]) @ normal / self.options.ball_radius
        closed = bool((height >= self.options.grasp_height).any() and (height < 0.0).any())
        return parts, giver, closed

    def rewards(self, env):
        d = env.world.data
        o = self.options
        self._parts, giver_touches, self._grasped = self._contacts(d)
        ball = d.xpos[self._ball_body]
        self._dropped = bool(ball[2] < o.drop_height)
        # the receiver holds the ball: enough of its segments, closed around it, the giver's
        # hand off it, and the ball above the drop height
        receiver_holds = (self._parts >= o.min_parts and self._grasped and not giver_touches
                          and not self._dropped)
        self._holder = "giver" if giver_touches else "receiver" if receiver_holds else "none"
        self._held_for = self._held_for + 1 if receiver_holds else 0
        self._success = self._held_for >= self._hold_steps
        self._distance = self._palm_distance(d)
        phi = self._shaping_potential(d, self._parts > 0 and not giver_touches)
        r = phi - self._potential if o.shaping else 0.0
        self._potential = phi
        if self._success:
            r += o.success_reward
        if self._dropped:
            r += o.failure_reward
        return np.array([r, r])

    def plots(self):
        """The shared reward (one line), the ball's distance to the receiver's palm, the palm's
        distance to the ready point, who holds the ball (-1 giver, 0 nobody, 1 receiver) and
        success."""
        holder = {"giver": -1.0, "none": 0.0, "receiver": 1.0}
        return [Plot.reward(shared=True),
                Plot("ball_to_hand", "m", lambda env: self._distance, per_agent=False),
                Plot("hand_to_ready", "m", lambda env: self._ready_distance, per_agent=False),
                Plot("holder", "-1 giver, 0 none, 1 receiver",
                     lambda env: holder[self._holder], per_agent=False),
                Plot("success", "0/1", lambda env: self._success, per_agent=False)]

    def info_spec(self, i):
        """The task's info keys and their kinds (see MimoParallelEnv.info_spec)."""
        return {"is_success": "number", "holder": ("giver", "receiver", "none"),
                "dropped": "number", "receiver_parts": "number", "held_steps": "number",
                "distance": "number"}

    def terminations(self, env):
        done = self._dropped or (self._success and self.options.end_on_success)
        info = {"is_success": self._success, "holder": self._holder, "dropped": self._dropped,
                "receiver_parts": self._parts, "held_steps": self._held_for,
                "distance": self._distance}
        return np.array([done, done]), [dict(info), dict(info)]


# -- the env factories (``mimo_social.envs.handover_v0`` re-exports them) -----------------

def parallel_env(**kwargs):
    return make_parallel(Handover, **kwargs)


def env(**kwargs):
    return make_aec(Handover, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ...partners import ScriptedPartners
    penv = parallel_env(**kwargs)
    if partner is None:
        partner = scripted_giver(penv.task.options)
    return ScriptedPartners(penv, {penv.possible_agents[1]: partner})
