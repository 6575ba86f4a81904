"""``HandOffer``: a scripted partner that holds its right hand out to the other infant.

The partner drives its right arm, through its own motors only, from wherever it is to an *offer
posture* in front of its body and holds it there; with ``grip=True`` it keeps its fingers closed
(on a ball it holds, for a handover) and lets go by its ``release`` rule: ``"on_hold"`` (the
default, the handover's giver) hands the ball into another infant's open hand and opens only once
that hand carries it; ``"on_touch"`` (the first version) opens at the first touch of another
hand. A high-five partner uses ``HandOffer(grip=False, release=None)``: hand out, fingers open,
nothing to release.

target:
    ``posture`` (joint -> degrees; default :data:`OFFER_POSTURE_DEG`: upper arm forward, elbow half
    bent, palm up) or, with ``target=(forward, left, up)`` (m, from the right shoulder in the
    infant's heading frame), the posture whose palm centre reaches that point; the wrist is then
    solved for ``palm``: ``"up"`` (default: the palm faces up, leaning 0.15 toward the thumb and 0.1
    toward the fingers, a pocket a ball rests in), ``"forward"`` (facing ahead as far as the wrist's
    range allows, about 25 deg off at the default posture; for a high five) or ``"posture"`` (the
    posture's wrist angles); see :func:`offer_posture` (damped least squares, solved once per reset
    on a scratch copy of the state)
adult:
    an agent with the adult body (or whose arm differs from the other's by over 5 %: an infant of
    another size) offers where the other agent's hand reaches (a point beyond its own arm brought to
    0.9 of it, raised if below): its palm centre at ``adult_reach_to`` from the other's right
    shoulder (default :data:`REACH_TO`, where the high five's 18-month-old partner holds its palm
    for the other; scaled with the other's arm), its own shoulder, elbow and wrist solved for it;
    ``reach_to`` does the same for any body
arm:
    PD control per joint toward the target angles, gains from the joint's own inertia (the diagonal
    of the joint-space mass matrix at reset; natural frequency ``frequency`` 3 Hz, damping ratio
    ``damping`` 1), plus gravity / Coriolis and passive-spring compensation read from MuJoCo
    (``qfrc_bias``, ``qfrc_spring``); the torque becomes the agent's controls: spring-damper motors
    ``u = tau / T_max`` (clipped to [-1, 1]); muscles: the agonist's activation giving ``tau`` at
    the current length on top of the passive muscle forces (isometric curve, clipped to [0, 1],
    antagonist off)
fingers:
    closed (``grip`` and not released): a constant flexing command ``grip_strength`` (0.03 of the
    motor's strength or of full activation) on the four fingers' flexors (mcp, pip, dip, the little
    finger's cup; mitten: the one finger joint), ``thumb_strength`` (0: the thumb held at rest by
    the PD) on the thumb's; spread and pivot held by the PD. Open: PD toward straight fingers, the
    thumb at its rest angles. A gentle grip holds a ball lying in the palm; a strong one squeezes it
    out (measured: 0.3 and above lose a 3 cm ball within 6 s)
release:
    ``None``: never (the fingers stay as ``grip`` says). ``"on_hold"`` (default): *present*: while
    another agent holds an open right hand out next to the giver's (its palm centre within
    ``ready_radius`` 8 cm of the giver's, lower than the object's centre, facing up within 45 deg)
    for ``ready_time`` (0.3 s), the palm tips toward its little-finger side (the palm's lean toward
    the thumb lowered by ``present``, 0.75, over ``present_time`` 0.5 s; it levels again when that
    hand goes away), so the object rolls toward that hand; *let go*: once the right hand of another
    agent, its palm facing the object, touches the object with >= ``hold_parts`` (2) segments and
    carries >= ``hold_load`` (0.5) of its weight (the upward component of that hand's contact forces
    on it, :meth:`HandOffer.carried`) for ``hold_time`` (0.2 s), the fingers open and the arm goes
    to a posture with the palm ``withdraw`` (3 cm back, 8 cm down) from the offer, shoulder and
    elbow solved, the wrist kept (at the handover's offer the arm gets the palm 1.9 cm back and 3.7
    cm down). A touch of the back of the hand or a one-finger poke neither presents nor lets go.
    ``"on_touch"``: open once a geom of another agent's hand (either hand) touches the object
    ``prop`` (a contact with dist <= 0), ``release_delay`` s later; with ``pour`` > 0 the wrist then
    also tips the palm over the fingertips (slope ``pour``) so the object rolls toward the partner
state:
    ``released`` (bool), ``touched_at`` (env time of the first touch, ``"on_touch"``, or of the
    first step the other hand held the object, ``"on_hold"``; else ``None``), ``tip`` (0-1: how far
    the palm is tipped toward the other hand), ``ready_steps``, ``held_steps``, ``load`` (the
    fraction of the weight the other hand carried last step), ``target_angles`` (rad, per motor: arm
    targets, open-finger targets), ``target_position`` (world, the palm centre of the holding
    posture)

Both hand versions and both actuation models are supported (tests: the palm within 3 cm of the
target after 1 s from the hanging arm, within 2 cm after 1.5 s, for all four combinations). The
muscles are driven from their isometric torque curve (the force-velocity factor is left out),
which the PD loop absorbs; the tracking error is the same order as with spring-damper motors.

Developmental note: holding out an object, and letting go of it only when the other's hand has
taken its weight, is the giver's half of the give-and-take games that 12-18-month-olds play with
caregivers (adults passing an object release it as the receiver's grip takes the load: Mason and
MacKenzie 2005); the partner offers a stable, predictable target, as a caregiver does.
"""

from __future__ import annotations

from typing import Mapping

import mujoco
import numpy as np

from ..body.joint_groups import RIGHT_SHOULDER_ELBOW, RIGHT_WRIST
from ..core.kinematics import hand_geoms
from ..util.checks import (ConfigError, check_bool, check_choice, check_int, check_number,
                           check_numbers, show)
from .base import (Partner, agent_motors, check_angles, motor_action, pd_gains,
                   require_prop)
from .offer_target import REACH_TO, adapts, is_adult, reach_target

__all__ = ["HandOffer", "OFFER_POSTURE_DEG", "OPEN_FINGERS_DEG", "finger_flexors",
           "offer_posture"]

# The right arm forward, the hand in front of the chest, elbow half bent, palm up (degrees): the
# palm centre ~16 cm ahead of the right shoulder, 6 cm toward the midline, 10 cm lower.
OFFER_POSTURE_DEG = {"right_shoulder_horizontal": 101.0, "right_shoulder_abduction": 15.0,
                     "right_shoulder_rotation": -91.0, "right_elbow": -52.0,
                     "right_wrist_rotation": -75.6, "right_wrist_flexion": -6.2,
                     "right_wrist_ulnar": 9.3}
# Open fingers: straight (0 deg) except the thumb at its rest angles; mitten: straight.
OPEN_FINGERS_DEG = {"right_thumb_swivel": 40.0, "right_thumb_adduction": -35.0,
                    "right_fingers": 0.0}
SHOULDER_ELBOW = RIGHT_SHOULDER_ELBOW
ARM = RIGHT_SHOULDER_ELBOW + RIGHT_WRIST
RELEASES = (None, "on_touch", "on_hold")
PALMS = ("up", "forward", "posture")
# mitten: the finger joint closes towards its lower limit (-160 deg)
MITTEN_CLOSE_SIGN = -1.0


def finger_flexors(names) -> np.ndarray:
    """Closing direction (+1 / -1) of each joint in ``names`` that flexes a right finger, 0 for
    the others (arm joints, finger spread and thumb pivot)."""
    out = np.zeros(len(names))
    for k, n in enumerate(names):
        if n == "right_fingers":
            out[k] = MITTEN_CLOSE_SIGN
        elif n.startswith("right_") and n.split("_")[1] in ("index", "middle", "ring", "little",
                                                            "thumb"):
            if n.split("_")[-1] not in ("spread", "pivot"):
                out[k] = 1.0
    return out


def _number(name, value, lo, hi):
    return check_number("HandOffer", name, value, lo, hi)


def _pair(name, value, lo, hi) -> tuple[float, float]:
    return check_numbers("HandOffer", name, value, 2, lo, hi,
                         f"two numbers from {lo:g} to {hi:g}")


def _palm_at(w, a, qadr, q) -> np.ndarray:
    """World position of agent ``a``'s right palm centre with joints ``qadr`` at ``q``."""
    d = mujoco.MjData(w.model)
    d.qpos[:] = w.data.qpos
    d.qpos[qadr] = q
    mujoco.mj_kinematics(w.model, d)
    return d.site_xpos[a.palm_sites[0]].copy()


def offer_posture(world, i: int, posture_deg: Mapping[str, float] | None = None,
                  target=None, palm: str = "up",
                  palm_tilt: tuple[float, float] = (0.15, -0.1)) -> dict[str, float]:
    """The right arm's offer posture of agent ``i`` (joint -> rad, clipped to the ranges).

    Starts from ``posture_deg`` (merged over :data:`OFFER_POSTURE_DEG`). With ``target =
    (forward, left, up)`` (m, from the right shoulder in the infant's heading frame), the
    shoulder and elbow are solved so the palm centre reaches the target. ``palm``: ``"up"``:
    the wrist's 3 joints are solved so the palm faces up, leaning by ``palm_tilt`` (slopes:
    toward the thumb, toward the wrist; the default leans toward the thumb and the fingers, so a
    ball lying in the palm settles against them); ``"forward"``: the palm faces straight ahead
    (the infant's heading, e.g. for a high five); ``"posture"``: the wrist keeps the posture's
    angles. Damped least squares on a scratch copy of the state, alternating position and
    orientation a few rounds."""
    if palm not in PALMS:
        raise ValueError(f"offer_posture: palm={palm!r}; allowed: {list(PALMS)}")
    m = world.model
    a = world.agents[i]
    posture = {**OFFER_POSTURE_DEG, **(posture_deg or {})}
    k = [a.joint_names.index(n) for n in ARM]
    lo, hi = a.joint_range[k, 0], a.joint_range[k, 1]
    q = np.clip(np.deg2rad([posture[n] for n in ARM]), lo, hi)
    if target is None and palm == "posture":
        return {name: float(v) for name, v in zip(ARM, q)}
    d = mujoco.MjData(m)
    d.qpos[:] = world.data.qpos
    qadr, dadr = a.qpos_adr[k], a.dof_adr[k]
    d.qpos[qadr] = q
    mujoco.mj_kinematics(m, d)
    site = int(a.palm_sites[0])
    hand = int(m.site_bodyid[site])
    n = len(SHOULDER_ELBOW)
    arm, wrist = slice(0, n), slice(n, len(ARM))
    goal = None
    R = d.xmat[a.root_body].reshape(3, 3)
    heading = np.arctan2(R[1, 0], R[0, 0])
    c, s = np.cos(heading), np.sin(heading)
    if target is not None:
        shoulder = int(m.jnt_bodyid[m.dof_jntid[dadr[0]]])
        f, left, up = target
        goal = d.xpos[shoulder] + np.array([c * f - s * left, s * f + c * left, up])
    jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))

    def dls(J, err, part):
        step = J.T @ np.linalg.solve(J @ J.T + 1e-4 * np.eye(3), err)
        d.qpos[qadr[part]] = np.clip(d.qpos[qadr[part]] + np.clip(step, -0.2, 0.2),
                                     lo[part], hi[part])

    for _ in range(4):
        for _ in range(60 if goal is not None else 0):
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            err = goal - d.site_xpos[site]
            if np.linalg.norm(err) < 1e-4:
                break
            mujoco.mj_jacSite(m, d, jp, None, site)
            dls(jp[:, dadr[arm]], err, arm)
        for _ in range(60 if palm != "posture" else 0):
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            Rh = d.xmat[hand].reshape(3, 3)
            normal = -Rh[:, 1]  # the right palm faces the hand's -y
            if palm == "up":
                want = np.array([0.0, 0.0, 1.0]) + palm_tilt[0] * Rh[:, 0] \
                    - palm_tilt[1] * Rh[:, 2]
                want[2] = 1.0
            else:
                want = np.array([c, s, 0.0])
            err = np.cross(normal, want / np.linalg.norm(want))
            if np.linalg.norm(err) < 1e-4:
                break
            mujoco.mj_jacBody(m, d, None, jr, hand)
            dls(jr[:, dadr[wrist]], err, wrist)
    q = d.qpos[qadr].copy()
    return {name: float(v) for name, v in zip(ARM, q)}


class HandOffer(Partner):
    """Bring the right hand to an offer position and hold it there (see the module table).

    ``posture``: arm joint angles in degrees (merged over :data:`OFFER_POSTURE_DEG`);
    ``target``: ``(forward, left, up)`` metres from the right shoulder (heading frame) for the
    palm centre, or ``None`` to use the posture as it is; ``grip``: close the fingers (hold an
    object) until released; ``release``: ``"on_hold"``, ``"on_touch"`` or ``None`` (see the
    module table; ``hold_parts``, ``hold_load``, ``hold_time``, ``present``, ``present_time``,
    ``ready_time``, ``ready_radius`` and ``withdraw`` = (back, down) m tune ``"on_hold"``);
    ``release_delay``: seconds between the touch and the opening (``"on_touch"``); ``prop``: the
    held object's prop name; ``frequency`` (Hz) and ``damping`` (ratio): the PD loop;
    ``grip_strength`` / ``thumb_strength``: the fingers' / thumb's flexing command in [0, 1];
    ``pour``: after the release, tip the palm over the fingertips with this slope (0: keep it
    level); ``palm``: ``"up"`` (hold an object), ``"forward"`` (facing the partner, e.g. for a high
    five) or ``"posture"`` (the wrist angles of ``posture``), see :func:`offer_posture`;
    ``palm_tilt``: the upturned palm's lean (slopes toward the thumb, toward the wrist);
    ``reach_to``: ``(forward, left, up)`` m from the *other* (nearest) agent's right shoulder, in
    its heading frame, for an 18-month-old's arm (scaled with that agent's arm): the palm centre
    goes there instead of ``target``, for any body; ``adult_reach_to`` (default :data:`REACH_TO`) is
    that point for an agent with the adult body, or an arm differing from the other's by over
    :data:`~mimo_social.partners.offer_target.SIZE_TOLERANCE`, when ``reach_to`` is None (a
    caregiver, or an infant of another size, offers where the other reaches, within its own reach);
    ``adult_present``: ``present`` for an adult (None: the same).
    """

    def __init__(self, posture: Mapping[str, float] | None = None, target=None,
                 grip: bool = True, release: str | None = "on_hold",
                 release_delay: float = 0.0, prop: str = "ball", frequency: float = 3.0,
                 damping: float = 1.0, grip_strength: float = 0.03, thumb_strength: float = 0.0,
                 pour: float = 0.0, palm: str = "up", hold_parts: int = 2,
                 hold_load: float = 0.5, hold_time: float = 0.2, present: float = 0.75,
                 present_time: float = 0.5, ready_time: float = 0.3, ready_radius: float = 0.08,
                 palm_tilt=(0.15, -0.1), withdraw=(0.03, 0.08), reach_to=None,
                 adult_reach_to=REACH_TO, adult_present=None):
        if posture is not None:
            posture = check_angles("HandOffer", "posture", posture, ARM)
        if target is not None:
            where = ("None or (forward, left, up) in metres from the right shoulder, within "
                     "0.5 m")
            target = check_numbers("HandOffer", "target", target, 3, allowed=where)
            if np.linalg.norm(target) > 0.5:
                raise ConfigError(f"HandOffer: target={show(target)} not allowed; allowed: "
                                  f"{where}")
        if reach_to is not None:
            reach_to = check_numbers("HandOffer", "reach_to", reach_to, 3, -1.0, 1.0,
                                     "None or (forward, left, up) in metres from the other "
                                     "agent's right shoulder, each from -1 to 1")
        self.reach_to = reach_to
        self.adult_reach_to = check_numbers("HandOffer", "adult_reach_to", adult_reach_to, 3,
                                            -1.0, 1.0, "(forward, left, up) in metres from "
                                            "the other agent's right shoulder, each from -1 to 1")
        grip = check_bool("HandOffer", "grip", grip)
        check_choice("HandOffer", "release", release, RELEASES)
        if not isinstance(prop, str) or not prop:
            raise ConfigError(f"HandOffer: prop={show(prop)} not allowed; allowed: the name of a "
                              "prop of the env")
        self.posture_deg = {**OFFER_POSTURE_DEG, **(posture or {})}
        self.target = target
        self.grip = grip
        self.release = release
        self.release_delay = _number("release_delay", release_delay, 0.0, 60.0)
        self.prop = prop
        self.frequency = _number("frequency", frequency, 0.1, 20.0)
        self.damping = _number("damping", damping, 0.1, 5.0)
        self.grip_strength = _number("grip_strength", grip_strength, 0.0, 1.0)
        self.thumb_strength = _number("thumb_strength", thumb_strength, 0.0, 1.0)
        self.pour = _number("pour", pour, 0.0, 3.0)
        check_choice("HandOffer", "palm", palm, PALMS)
        if self.pour > 0 and palm != "up":
            raise ValueError(f"HandOffer: pour={pour} needs palm='up' (it tips an upturned "
                             f"palm), got palm={palm!r}")
        self.palm = palm
        self.hold_parts = check_int("HandOffer", "hold_parts", hold_parts, 1, 16)
        self.hold_load = _number("hold_load", hold_load, 0.0, 2.0)
        self.hold_time = _number("hold_time", hold_time, 0.0, 5.0)
        self.present = _number("present", present, 0.0, 2.0)
        self.adult_present = None if adult_present is None else \
            _number("adult_present", adult_present, 0.0, 2.0)
        self.present_time = _number("present_time", present_time, 0.01, 5.0)
        self.ready_time = _number("ready_time", ready_time, 0.0, 5.0)
        self.ready_radius = _number("ready_radius", ready_radius, 0.01, 0.5)
        self.palm_tilt = _pair("palm_tilt", palm_tilt, -1.0, 1.0)
        self.withdraw = _pair("withdraw", withdraw, 0.0, 0.2)

    def __repr__(self):
        return (f"HandOffer(target={self.target}, grip={self.grip}, release={self.release!r}, "
                f"release_delay={self.release_delay})")

    # -- reset: index tables, the target posture, the gains ------------------------------------
    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        w = env.world
        m, d = w.model, w.data
        motors = agent_motors("HandOffer", env, agent, ARM, "it needs the right arm's motors "
                              "(shoulder, elbow, wrist) in its action")
        i, a, names, lo, hi = motors.index, motors.tables, motors.names, motors.lo, motors.hi
        self._i = i
        self._qadr, self._dadr, self._act = motors.qpos_adr, motors.dof_adr, motors.act
        self._muscle = self._act.name == "muscle"
        self._flex = finger_flexors(names)
        thumb = np.array(["thumb" in n for n in names])
        self._strength = np.where(thumb, self.thumb_strength, self.grip_strength)
        self._gripping = (self._flex != 0) & (self._strength > 0)
        self._is_finger = np.array([n not in ARM for n in names])
        # an adult (or any agent given reach_to) offers where the other agent reaches
        adult = is_adult(w, i)
        present = self.adult_present if adult and self.adult_present is not None \
            else self.present
        target = self.target
        if self.reach_to is not None:
            target = reach_target(w, i, self.reach_to)
        elif adapts(w, i):
            target = reach_target(w, i, self.adult_reach_to)
        self.offer_target = target
        arm = offer_posture(w, i, self.posture_deg, target, self.palm, self.palm_tilt)
        open_deg = np.array([OPEN_FINGERS_DEG.get(n, 0.0) for n in names])
        q_target = np.array([arm.get(n, np.deg2rad(open_deg[k])) for k, n in enumerate(names)])
        self.target_angles = self._hold_angles = np.clip(q_target, lo, hi)
        self.target_position = _palm_at(w, a, self._qadr, self.target_angles)
        self._after_angles = self._hold_angles     # the posture after the release
        back, down = self.withdraw
        if self.pour > 0 or back > 0 or down > 0:
            # the palm `back` and `down` from the offer: shoulder and elbow solved, the wrist
            # kept as it holds (with `pour`, the palm tipped over the fingertips)
            if target is not None:
                target = (target[0] - back, target[1], target[2] - down)
            if self.pour > 0:
                after = offer_posture(w, i, self.posture_deg, target, "up", (0.0, -self.pour))
            else:
                held = {n: float(np.rad2deg(arm[n])) for n in ARM}
                after = offer_posture(w, i, held, target, "posture")
            self._after_angles = np.clip([after.get(n, q_target[k])
                                          for k, n in enumerate(names)], lo, hi)
        self._kp, self._kd = pd_gains(m, d, self._dadr, self.frequency, self.damping)
        if not self._muscle:
            self._tneg, self._tpos = self._act.torque_neg, self._act.torque_pos
        # who may take the object: the hands of every other agent (geom -> hand number, its
        # segment's body, and whether that segment is a thumb's)
        self._object_geom = -1
        if self.release is not None:
            body = require_prop("HandOffer", w, self.prop)
            self._object_geom = int(np.flatnonzero(m.geom_bodyid == body)[0])
            self._object_body = int(body)
            self._others = np.zeros(m.ngeom, bool)
            self._hand_no = np.full(m.ngeom, -1, np.intp)
            for j in range(len(w.agents)):
                if j != i:
                    for side in (0, 1):
                        g = hand_geoms(w, j, side)
                        self._others[g] = True
                        self._hand_no[g] = 2 * j + side
            self._seg = m.geom_bodyid.astype(np.intp)
            self._weight = float(m.body_subtreemass[body] * np.linalg.norm(m.opt.gravity))
            # the other agents' right palms (site, hand body, hand number): the open hands the
            # ball may be handed into
            self._palms = [(int(w.agents[j].palm_sites[0]),
                            int(m.site_bodyid[w.agents[j].palm_sites[0]]), 2 * j)
                           for j in range(len(w.agents)) if j != i]
            self._palm_of = {h: (site, hand) for site, hand, h in self._palms}
            self._my_palm = int(a.palm_sites[0])
            tipped = offer_posture(w, i, self.posture_deg, self.offer_target, self.palm,
                                   (self.palm_tilt[0] - present, self.palm_tilt[1]))
            self._tip_angles = np.clip([tipped.get(n, q_target[k])
                                        for k, n in enumerate(names)], lo, hi)
        self._delay_steps = int(round(self.release_delay / env.dt))
        self._hold_steps = max(1, int(round(self.hold_time / env.dt)))
        self._ready_steps = max(1, int(round(self.ready_time / env.dt)))
        self._tip_step = env.dt / self.present_time
        self.released = False
        self.touched_at = None
        self.held_steps = 0
        self.ready_steps = 0
        self.tip = 0.0
        self.load = 0.0
        self._since_touch = -1

    # -- acting --------------------------------------------------------------------------------
    def _touched(self, d) -> bool:
        n = d.ncon
        if n == 0:
            return False
        c = d.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        ob = self._object_geom
        hit = ((g1 == ob) & self._others[g2]) | ((g2 == ob) & self._others[g1])
        return bool(np.any(hit & (c.dist[:n] <= 0.0)))

    def _other_contacts(self, d) -> np.ndarray:
        """Geoms of the other agents' hands in contact with the object (dist <= 0)."""
        n = d.ncon
        if n == 0:
            return np.zeros(0, np.intp)
        c = d.contact
        g1, g2, dist = c.geom1[:n], c.geom2[:n], c.dist[:n]
        ob = self._object_geom
        other = np.where(g1 == ob, g2, np.where(g2 == ob, g1, -1))
        keep = (other >= 0) & (dist <= 0.0)
        other = other[keep]
        return other[self._others[other]]

    def carried(self, m, d) -> tuple[int, float]:
        """How another agent's right hand holds the object now, counting only a hand whose palm
        faces the object (the object's centre on the palm side): (the segments of that hand
        touching it, the fraction of the object's weight it carries: the upward component of
        its contact forces on the object over the weight)."""
        n = d.ncon
        if n == 0:
            return 0, 0.0
        c = d.contact
        g1, g2 = c.geom1[:n], c.geom2[:n]
        ob = self._object_geom
        other = np.where(g1 == ob, g2, np.where(g2 == ob, g1, -1))
        idx = np.flatnonzero((other >= 0) & (c.dist[:n] <= 0.0))
        idx = idx[self._others[other[idx]]]
        if not len(idx):
            return 0, 0.0
        hands = self._hand_no[other[idx]]
        f6 = np.zeros(6)
        best_parts, best_load = 0, 0.0
        ball = d.xpos[self._object_body]
        for h in np.unique(hands):
            palm = self._palm_of.get(int(h))
            if palm is None:                         # a left hand: not a receiving hand
                continue
            site, hand = palm
            if (ball - d.site_xpos[site]) @ -d.xmat[hand].reshape(3, 3)[:, 1] <= 0.0:
                continue                             # the object is on the back of the hand
            up = 0.0
            for k in idx[hands == h]:
                mujoco.mj_contactForce(m, d, int(k), f6)
                fz = float(d.contact.frame[k, 2::3] @ f6[:3])  # world z, on geom2
                up += fz if g2[k] == ob else -fz
            parts = len(np.unique(self._seg[other[idx[hands == h]]]))
            best_parts = max(best_parts, parts)
            best_load = max(best_load, up / self._weight)
        return best_parts, best_load

    def open_hand_ready(self, d) -> bool:
        """Whether another agent holds an open right hand out to take the object: its palm
        centre within ``ready_radius`` of the giver's, lower than the object's centre, and
        facing up (within 45 degrees)."""
        mine = d.site_xpos[self._my_palm]
        top = d.xpos[self._object_body][2]
        for site, hand, _ in self._palms:
            normal_z = -d.xmat[hand, 7]          # the right palm faces the hand's -y
            p = d.site_xpos[site]
            if normal_z >= np.cos(np.pi / 4) and p[2] < top and \
                    np.linalg.norm(p - mine) <= self.ready_radius:
                return True
        return False

    def _update_release(self, env):
        if self.release is None or self.released:
            return
        if self.release == "on_hold":
            w = env.world
            m, d = w.model, w.data
            self.ready_steps = self.ready_steps + 1 if self.open_hand_ready(d) else 0
            parts, self.load = self.carried(m, d)
            held = parts >= self.hold_parts and self.load >= self.hold_load
            if held and self.touched_at is None:
                self.touched_at = float(d.time)
            self.held_steps = self.held_steps + 1 if held else 0
            if self.held_steps >= self._hold_steps:
                self.released = True
                self.target_angles = self._after_angles
                return
            presenting = self.ready_steps >= self._ready_steps or held
            self.tip = float(np.clip(self.tip + (self._tip_step if presenting
                                                 else -self._tip_step), 0.0, 1.0))
            self.target_angles = self._hold_angles + self.tip * (self._tip_angles
                                                                 - self._hold_angles)
            return
        if self._since_touch < 0 and self._touched(env.world.data):
            self._since_touch = 0
            self.touched_at = float(env.world.data.time)
        if self._since_touch >= 0:
            if self._since_touch >= self._delay_steps:
                self.released = True
                self.target_angles = self._after_angles
            self._since_touch += 1

    @property
    def closing(self) -> bool:
        """Whether the fingers are being closed now (``grip`` and not yet released)."""
        return self.grip and not self.released

    def torques(self, env) -> np.ndarray:
        """The joint torques the partner wants now (PD + compensation), one per motor."""
        d = env.world.data
        q = d.qpos[self._qadr]
        qd = d.qvel[self._dadr]
        tau = self._kp * (self.target_angles - q) - self._kd * qd
        tau += d.qfrc_bias[self._dadr] - d.qfrc_spring[self._dadr]
        return tau

    def act(self, env, agent, observation):
        self._update_release(env)
        tau = self.torques(env)
        closing = self.closing
        grip = self._gripping
        if self._muscle:
            act = self._act
            q = env.world.data.qpos[self._qadr]
            n_full, p_full = act.isometric_torque(q, 1.0)
            n_rest, p_rest = act.isometric_torque(q, 0.0)
            need = tau - (n_rest + p_rest)
            neg = np.clip(need / np.minimum(n_full - n_rest, -1e-9), 0.0, 1.0)
            pos = np.clip(need / np.maximum(p_full - p_rest, 1e-9), 0.0, 1.0)
            if closing:
                g = self._strength
                pos = np.where(grip & (self._flex > 0), g, pos)
                neg = np.where(grip & (self._flex > 0), 0.0, neg)
                neg = np.where(grip & (self._flex < 0), g, neg)
                pos = np.where(grip & (self._flex < 0), 0.0, pos)
            u = np.concatenate([neg, pos])
        else:
            u = np.clip(np.where(tau >= 0, tau / self._tpos, tau / self._tneg), -1.0, 1.0)
            if closing:
                u = np.where(grip, self._flex * self._strength, u)
        return motor_action(env.action_space(agent), u)
