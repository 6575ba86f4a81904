"""``mimo-social compliance``: a ball dropped on the outstretched arm (paper Sec. IV-C, Fig. 4).

One infant stands with its hip fixed in the world, the right arm stretched out sideways
(shoulder abduction 90 deg, elbow straight, wrist flexed by -0.25 rad). Every joint but the right
shoulder's abduction is held (frozen); the shoulder is held up against gravity by its own
actuator only, with a constant control chosen so the arm rests at 90 deg before the impact:

- spring-damper: the one motor control that balances gravity and the joint spring;
- muscles, at three co-contraction levels: the negative (adductor) muscle at a fixed activation
  (``CO_CONTRACTION``), the positive (abductor) one at the activation that balances it, gravity
  and the retained 5 % spring. Activations start at these values, so the arm is steady.

A ball (``BALL_RADIUS``, ``BALL_MASS``) falls from ``DROP_HEIGHT`` above the forearm. The shoulder
angle and the actuation torque (actuator plus the joint's passive spring-damper) are recorded for
``SECONDS``; for the spring-damper model the motor torque alone is drawn dashed (it stays
constant). Higher co-contraction makes the arm stiffer: it deflects less.

From Python: :func:`run_compliance` (the data) and :func:`plot_compliance` (the figure);
the command is :mod:`mimo_social.cli.compliance`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

__all__ = ["CO_CONTRACTION", "SECONDS", "Trial", "run_trial", "run_compliance",
           "plot_compliance"]

SHOULDER = "right_shoulder_abduction"
ARM_POSE_DEG = {SHOULDER: 90.0, "right_shoulder_horizontal": 0.0, "right_shoulder_rotation": 0.0,
                "right_elbow": 0.0, "right_wrist_flexion": np.rad2deg(-0.25),
                "right_wrist_rotation": 0.0, "right_wrist_ulnar": 0.0}
CO_CONTRACTION = (0.0, 0.25, 0.6)   # activation of the negative muscle: low, medium, high
BALL_RADIUS = 0.035
BALL_MASS = 0.15
DROP_HEIGHT = 0.25                  # m between the ball's bottom and the forearm's top
SECONDS = 2.0


@dataclass
class Trial:
    label: str
    model: str                       # "spring_damper" | "muscle"
    controls: np.ndarray             # the constant control vector
    time: np.ndarray = field(default=None)
    angle_deg: np.ndarray = field(default=None)
    torque: np.ndarray = field(default=None)        # actuator + passive spring-damper (Nm)
    motor_torque: np.ndarray = field(default=None)  # actuator only (Nm)
    impact_time: float = float("nan")

    @property
    def deflection_deg(self) -> float:
        """Largest drop of the shoulder angle below its value at the impact."""
        if not np.isfinite(self.impact_time):
            return 0.0
        k = int(np.searchsorted(self.time, self.impact_time))
        return float(self.angle_deg[k] - self.angle_deg[k:].min())


def _world(hands: str, actuation: str):
    from ..body.tables import load_body
    from ..core.config import AgentConfig, PhysicsConfig
    from ..body.joint_groups import held_posture
    from ..core.world import AgentSetup, Prop, World

    tables = load_body(hands)
    frozen = held_posture(tables, keep=(SHOULDER,), angles=ARM_POSE_DEG)
    cfg = AgentConfig(hands=hands, actuation=actuation, expressions=False)
    setup = AgentSetup(cfg, frozen=frozen, base="fixed", actuated=(SHOULDER,))
    ball = Prop("ball", "sphere", (BALL_RADIUS,), (0.0, 0.0, 2.0), BALL_MASS, (0.9, 0.3, 0.2, 1.0))
    return World([setup], [ball], PhysicsConfig())


def _balance(world, act, kind: str, level: float) -> np.ndarray:
    """The constant control that holds the arm still at its pose."""
    m, d = world.model, world.data
    a = world.agents[0]
    k = a.joint_names.index(SHOULDER)
    dof, qadr = a.dof_adr[k], a.qpos_adr[k]
    act.reset(m, d)                       # binds the model (muscles: 5 % springs, wide ranges)
    d.qvel[:] = 0.0
    mujoco.mj_forward(m, d)
    need = float(d.qfrc_bias[dof] - d.qfrc_passive[dof])   # torque the actuator must give
    if kind == "spring_damper":
        u = need / (act.torque_pos[0] if need >= 0 else act.torque_neg[0])
        if abs(u) > 1:
            raise RuntimeError(f"the shoulder motor cannot hold the arm (needs {need:.2f} Nm)")
        return np.array([u])
    q = d.qpos[qadr]
    from ..body.actuation.muscle import force_length, force_passive
    L = act.moment[:, 0] * q + act.offset[:, 0]
    gain = act.gain[:, 0]                                    # torque per unit force F
    t_neg = gain[0] * (force_length(L[0]) * level + force_passive(L[0]))
    a_pos = (need - t_neg - gain[1] * force_passive(L[1])) / (gain[1] * force_length(L[1]))
    if not 0.0 <= a_pos <= 1.0:
        raise RuntimeError(f"co-contraction {level}: the abductor would need activation {a_pos:.2f}")
    return np.array([level, float(a_pos)])


def run_trial(kind: str, level: float = 0.0, hands: str = "mitten",
              seconds: float = SECONDS) -> Trial:
    """One drop: ``kind`` ``"spring_damper"`` or ``"muscle"`` (with ``level`` co-contraction)."""
    from ..body.actuation import MODELS

    world = _world(hands, kind)
    m, d = world.model, world.data
    a = world.agents[0]
    by = {j.name: j for j in world.tables[0].joints}
    act = MODELS[kind]([by[n] for n in a.actuated_names], a.actuator_ids)
    world.reset()
    k = a.joint_names.index(SHOULDER)
    dof, qadr = a.dof_adr[k], a.qpos_adr[k]
    d.qpos[qadr] = np.deg2rad(ARM_POSE_DEG[SHOULDER])   # the posture's shoulder is not frozen
    mujoco.mj_forward(m, d)
    u = _balance(world, act, kind, level)
    act.reset(m, d)
    act.apply(m, d, u)
    if kind == "muscle":
        act.activation[:] = u.reshape(act.activation.shape)   # already holding: steady start
    # the ball above the middle of the forearm
    arm_geom = m.geom(f"{a.name}/right_lower_arm").id
    top = d.geom_xpos[arm_geom].copy()
    top[2] += m.geom_size[arm_geom, 0] + BALL_RADIUS + DROP_HEIGHT
    bq = world.prop_qpos["ball"]
    d.qpos[bq:bq + 3] = top
    d.qpos[bq + 3:bq + 7] = (1, 0, 0, 0)
    mujoco.mj_forward(m, d)
    ball = m.geom("ball").id
    arm = set(a.geom_ids.tolist())
    n = int(round(seconds / m.opt.timestep))
    t = np.empty(n)
    angle = np.empty(n)
    torque = np.empty(n)
    motor = np.empty(n)
    impact = float("nan")
    for i in range(n):
        act.substep(m, d)
        mujoco.mj_step(m, d)
        mujoco.mj_forward(m, d)            # forces and contacts of the new state
        t[i] = d.time
        angle[i] = np.rad2deg(d.qpos[qadr])
        motor[i] = d.qfrc_actuator[dof]
        torque[i] = d.qfrc_actuator[dof] + d.qfrc_passive[dof]
        if not np.isfinite(impact):
            for c in d.contact[: d.ncon]:
                if (c.geom1 == ball and c.geom2 in arm) or (c.geom2 == ball and c.geom1 in arm):
                    impact = float(d.time)
                    break
    label = ("spring-damper" if kind == "spring_damper"
             else f"muscles, co-contraction {level:g}")
    return Trial(label, kind, u, t, angle, torque, motor, impact)


def run_compliance(levels=CO_CONTRACTION, hands: str = "mitten",
                   seconds: float = SECONDS) -> list[Trial]:
    """The muscle model at each co-contraction level, then the spring-damper model."""
    trials = [run_trial("muscle", lv, hands, seconds) for lv in levels]
    trials.append(run_trial("spring_damper", 0.0, hands, seconds))
    return trials


def plot_compliance(trials: list[Trial], out: str | Path) -> Path:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True)
    colours = plt.cm.viridis(np.linspace(0.15, 0.8, sum(t.model == "muscle" for t in trials)))
    ci = 0
    for tr in trials:
        if tr.model == "muscle":
            colour, style = colours[ci], "-"
            ci += 1
        else:
            colour, style = "tab:red", "-"
        label = f"{tr.label} (deflection {tr.deflection_deg:.1f}°)"
        ax1.plot(tr.time, tr.angle_deg, style, color=colour, label=label)
        ax2.plot(tr.time, tr.torque, style, color=colour, label=tr.label + ": net actuation")
        if tr.model == "spring_damper":
            ax2.plot(tr.time, tr.motor_torque, "--", color=colour,
                     label=tr.label + ": motor alone")
    impacts = [tr.impact_time for tr in trials if np.isfinite(tr.impact_time)]
    for ax in (ax1, ax2):
        if impacts:
            ax.axvline(float(np.mean(impacts)), color="0.4", lw=0.8, ls=":")
        ax.grid(alpha=0.3)
    ax1.set_ylabel("shoulder abduction (deg)")
    ax2.set_ylabel("shoulder torque (Nm)")
    ax2.set_xlabel("time (s)")
    ax1.set_title("Ball dropped on the outstretched arm (dotted line: impact)")
    ax1.legend(fontsize=8, loc="lower right")
    ax2.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
