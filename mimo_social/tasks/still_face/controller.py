"""``StillFaceInfantController``: the scripted infant of the still-face paradigm (a baseline).

reads:
    the phase of the coming step from the task (``env.task.phase_at(env.steps)``: a scripted
    controller may read the env's state; a learner sees only the caregiver's face and movements),
    the caregiver's face centre (its ``head_centre`` site) and its own body (at reset)
interaction and reunion:
    smiles (``engaged_face``, "happy"), renewing its smile every ``bid_every_s`` (1 s) of these
    phases with one step of a neutral face (a new smile onset: a bid that a contingent caregiver
    answers; ``ContingentCaregiver`` smiles back for ``duration_s`` (1 s) after ``delay_s`` (0.5 s)
    per onset, so a smile held without renewal is answered once), and looks at the caregiver's face:
    :class:`~mimo_social.partners.gaze.GazeAtTarget`'s PD law on its own head and eye motors (head
    turned fully toward the face, the eyes correcting); its arms held by a PD at the angles they had
    at reset
held gaze:
    with the task option ``gaze_free`` off the task holds its head and eyes on the caregiver's
    face; it then only smiles, sobers and (with free arms) touches itself
still face:
    a neutral face (``still_face``), looks away at its own right hand, and with ``self_touch``
    (None: where its arms have motors, the task's ``arms_free``; True needs them) brings both
    hands to its chest, pressed together (self-comforting, Tronick et al. 1978): PD on its
    shoulder and elbow motors toward angles found at reset by damped least squares (both palm
    centres to a point 1.2 chest radii in front of the upper body's centre, i.e. inside the chest,
    so the hands press on it and on each other)
arm PD:
    per joint, gains from its own inertia (``pd_gains``: natural frequency ``arm_frequency`` 3 Hz,
    damping ratio 1), plus gravity / Coriolis and passive-spring compensation; torque over the
    joint's limit gives the control
acts:
    only through its own motors (head, eyes, shoulders, elbows) and its face; it writes no state. It
    needs the spring-damper actuation and the task's free arms (``arms_free``) for the self-touch

Measured on ``still_face_v0.scripted_env()``: see the task's table.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ...core.kinematics import reach_sites
from ...expressions.faces import EXPRESSIONS
from ...util.checks import ConfigError, check_bool, check_number, show
from ...partners.base import agent_index, motor_action, pd_gains
from ...partners.gaze import NEEDED as GAZE_MOTORS, GazeAtTarget
from .task import StillFace

__all__ = ["StillFaceInfantController"]

ARM = ("right_shoulder_horizontal", "right_shoulder_abduction", "right_shoulder_rotation",
       "right_elbow")
#: the hands' target in front of the chest centre, in chest radii (forward, up)
CHEST_TARGET = (1.2, 0.4)


def _face(who: str, name: str, value) -> int:
    if isinstance(value, str) and value in EXPRESSIONS:
        return EXPRESSIONS.index(value)
    raise ConfigError(f"{who}: {name}={show(value)} not allowed; allowed: one of "
                      f"{list(EXPRESSIONS)}")


class StillFaceInfantController(GazeAtTarget):
    """The scripted infant of ``still_face_v0`` (see the module table). ``caregiver``: the
    caregiver's name (None: the other agent); ``engaged_face``, ``still_face``: the faces shown
    in the interactive phases and in the still phase; ``self_touch``: hands to the chest in the
    still phase; ``bid_every_s``: how often (s) it renews its smile in the interactive phases
    (0: never); ``omega``, ``zeta``: the gaze PD law; ``arm_frequency``: the arm PD's natural
    frequency (Hz)."""

    def __init__(self, caregiver: str | None = None, engaged_face: str = "happy",
                 still_face: str = "neutral", self_touch: bool | None = None,
                 bid_every_s: float = 1.0, omega: float = 15.0,
                 zeta: float = 1.0, arm_frequency: float = 3.0):
        super().__init__(targets=None, hold_s=(1.0, 1.0), omega=omega, zeta=zeta,
                         head_share=1.0)
        who = "StillFaceInfantController"
        if caregiver is not None and (not isinstance(caregiver, str) or not caregiver):
            raise ConfigError(f"{who}: caregiver={show(caregiver)} not allowed; allowed: None "
                              "(the other agent) or an agent's name")
        self.caregiver = caregiver
        self.engaged_face = _face(who, "engaged_face", engaged_face)
        self.still_face = _face(who, "still_face", still_face)
        self.self_touch = None if self_touch is None else check_bool(who, "self_touch",
                                                                     self_touch)
        self.arm_frequency = check_number(who, "arm_frequency", arm_frequency, 0.1, 20.0)
        self.bid_every_s = check_number(who, "bid_every_s", bid_every_s, 0.0, 60.0)

    def __repr__(self):
        return (f"StillFaceInfantController(caregiver={self.caregiver!r}, engaged_face="
                f"{EXPRESSIONS[self.engaged_face]!r}, still_face="
                f"{EXPRESSIONS[self.still_face]!r}, self_touch={self.self_touch}, "
                f"bid_every_s={self.bid_every_s})")

    def reset(self, env, agent, rng):
        who = "StillFaceInfantController"
        if not isinstance(env.task, StillFace):
            raise ValueError(f"{who} reads the still-face phase (task.phase_at); the task "
                             f"{env.task.name!r} has none")
        agents = list(env.possible_agents)
        i = agent_index(env, agent)
        if self.caregiver is None:
            j = 1 - i if len(agents) == 2 else None
            if j is None:
                raise ValueError(f"{who}: {len(agents)} agents; name the caregiver "
                                 f"(caregiver=...), one of {agents}")
        elif self.caregiver in agents and self.caregiver != agent:
            j = agents.index(self.caregiver)
        else:
            raise ValueError(f"{who}: caregiver={self.caregiver!r}; allowed: "
                             f"{[a for a in agents if a != agent]}")
        # targets: the caregiver's face (0) and the infant's own right hand (1)
        w = env.world
        a = w.agents[i]
        motor_of = {n: k for k, n in enumerate(a.actuated_names)}
        # a held gaze (task option gaze_free off): the task aims it at the face; no look-at law
        self._looks = set(GAZE_MOTORS) <= set(motor_of)
        self._n_motors = len(motor_of)
        if self._looks:
            self.targets = (f"{agents[j]}/head_centre", f"{agent}/right_hand")
            super().reset(env, agent, rng)
            self.targets = None
        m, d = w.model, w.data
        arm = ARM + tuple(n.replace("right", "left") for n in ARM)
        missing = [n for n in arm if n not in motor_of]
        self._touches = not missing if self.self_touch is None else self.self_touch
        if self._touches and missing:
            raise ValueError(f"{who}: {agent} does not actuate {missing}; the self-touch "
                             "moves its arms (task option arms_free=True), or self_touch=False")
        arm = tuple(n for n in arm if n in motor_of)
        k = [list(a.joint_names).index(n) for n in arm]
        self._arm_motors = np.array([motor_of[n] for n in arm], dtype=np.intp)
        self._arm_qpos, self._arm_dof = a.qpos_adr[k], a.dof_adr[k]
        self._arm_rest = d.qpos[self._arm_qpos].copy()
        self._kp, self._kd = pd_gains(m, d, self._arm_dof, self.arm_frequency, 1.0)
        act = env.actuation[i]
        self._arm_tp = np.asarray(act.torque_pos, float)[self._arm_motors]
        self._arm_tn = np.asarray(act.torque_neg, float)[self._arm_motors]
        self._arm_touch = self._arm_rest.copy()
        self._bid = max(1, int(round(self.bid_every_s / env.dt))) if self.bid_every_s else 0
        self._engaged = 0               # interactive steps so far (the bid clock)
        if self._touches and len(k):
            self._arm_touch = self._hands_to_chest(w, i, a)

    def _hands_to_chest(self, w, i, a) -> np.ndarray:
        m = w.model
        sc = mujoco.MjData(m)
        sc.qpos[:] = w.data.qpos
        mujoco.mj_kinematics(m, sc)
        chest = m.body(f"{w.names[i]}/upper_body").id
        radius = max(float(m.geom_size[g, 0]) for g in a.geom_ids if m.geom_bodyid[g] == chest)
        R = sc.xmat[chest].reshape(3, 3)
        fwd, up = CHEST_TARGET
        target = sc.xpos[chest] + radius * (fwd * R[:, 0] + up * R[:, 2])
        for side in range(2):
            jnt = [list(a.joint_names).index(x) for x in
                   (ARM if side == 0 else tuple(x.replace("right", "left") for x in ARM))]
            reach_sites(m, sc, a.qpos_adr[jnt], a.dof_adr[jnt], a.joint_range[jnt, 0],
                        a.joint_range[jnt, 1], int(a.palm_sites[side]), target, iters=200)
        return sc.qpos[self._arm_qpos].copy()

    def act(self, env, agent, observation):
        if getattr(self, "_arm_qpos", None) is None:
            raise RuntimeError("StillFaceInfantController.act() before reset(); reset the env "
                               "first")
        still = env.task.phase_at(env.steps) == 1
        self.target = 1 if still else 0
        self._left = 1 << 30            # never switch on its own: the phase decides
        action = super().act(env, agent, observation) if self._looks else \
            motor_action(env.action_space(agent), np.zeros(self._n_motors, np.float32))
        d = env.world.data
        goal = self._arm_touch if still and self._touches else self._arm_rest
        tau = (self._kp * (goal - d.qpos[self._arm_qpos]) - self._kd * d.qvel[self._arm_dof]
               + d.qfrc_bias[self._arm_dof] - d.qfrc_spring[self._arm_dof])
        u = np.clip(tau / np.where(tau >= 0, self._arm_tp, self._arm_tn), -1.0, 1.0)
        motors = action["motors"] if isinstance(action, dict) else action
        motors[self._arm_motors] = u
        face = self.still_face if still else self.engaged_face
        if not still:
            if self._bid and self._engaged and self._engaged % self._bid == 0:
                face = self.still_face if self.still_face != self.engaged_face else 0
            self._engaged += 1
        if isinstance(action, dict):
            action["expression"] = np.int64(face)
            return action
        return motors
