"""``mimo-social calibrate fmax | vmax | speed``: the muscle model's per-axis parameters (paper
Sec. IV-B), and what the model costs.

**fmax** (maximum isometric force). One infant, hip fixed, gravity off, every joint held at its
calibration angle (0, the anatomical pose; the joints are held by equality constraints, the
motors stay). All negative muscles are fully activated for ``steps`` physics steps, then all
muscles rest for ``steps``, then all positive muscles are fully activated for ``steps``. The peak
motor torque in the second half of each active phase is the *achieved* torque of that direction;
``fmax <- fmax * target / achieved`` with the Table I torque as the target (the spring-damper
motor's ``gear * |forcerange|``), averaged over left and right twins, 3 iterations. The command
prints target vs achieved per axis; ``--write`` stores the result in
``body/data/<hands>_muscles.csv`` (the joint tables read it).

**vmax** (maximum contraction speed). One infant floating freely, gravity off. Each muscle gets
bang-bang controls (0 or 1 with equal chance) re-drawn every 2 s for an episode of 30 s; the
fastest virtual lengthening speed ``max |dL/dt|`` of each axis (left and right averaged) moves
vmax by a learning rate: ``vmax += lr (max|dL/dt| - vmax)``, ``lr`` = 0.1 decaying by 0.7 every
50 episodes. At the end every vmax is scaled by one common factor so the knee keeps its
reference value (the paper scales to a literature knee value; the published knee vmax, 1.45,
stands in for it here). The table shows the shipped value, the last episode's peak speed and the
new value per axis.

**speed**: the muscle model's own cost per physics step per infant and the physics-only speed of
one infant, each hand version (:func:`measure_speed`).

From Python: :func:`calibrate_fmax`, :func:`measure_fmax` (one measurement run, used by the
tests), :func:`calibrate_vmax`, :func:`measure_speed`; the command is
:mod:`mimo_social.cli.calibrate`.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import mujoco
import numpy as np

from ..core.random_actions import smooth_random_actions

__all__ = ["StaticScene", "static_scene", "measure_fmax", "calibrate_fmax", "calibrate_vmax",
           "floating_scene", "write_parameters", "measure_speed", "fmax_table", "vmax_table",
           "HAND_CHOICES", "hand_versions"]

HOLD_ANGLE = 0.0          # rad, clipped into each joint's range
PHASE_STEPS = 500         # physics steps per phase (negative, rest, positive)
ITERATIONS = 3
REFERENCE_JOINT = "right_knee"
HAND_CHOICES = ("mitten", "five_fingers", "both")


@dataclass
class StaticScene:
    model: mujoco.MjModel
    data: mujoco.MjData
    joints: list            # JointSpec of every motor, actuator order
    actuator_ids: np.ndarray
    hold: np.ndarray        # held angle of each motor's joint (rad)


def _physics(gravity=(0.0, 0.0, 0.0)):
    from ..core.config import PhysicsConfig
    return PhysicsConfig(gravity=gravity)


def static_scene(hands: str = "mitten") -> StaticScene:
    """One infant, hip fixed, gravity off, contacts off, every joint held at :data:`HOLD_ANGLE`
    by a joint equality (coupled trunk joints follow their driver), every motor present."""
    from ..body.builder import build_infant
    from ..core.world import World

    build = build_infant(hands, base="fixed")
    spec = build.spec
    World.set_physics_options(spec, _physics())
    # held limbs overlap in the zero pose (arms through the hips): contacts would fight the holds
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    by = {j.name: j for j in build.tables.joints}
    hold = {}
    for name in build.joints:
        j = by[name]
        if j.coupled_to:
            continue
        lo, hi = np.deg2rad(j.range_deg)
        hold[name] = float(np.clip(HOLD_ANGLE, lo, hi))
        spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=name,
                          data=np.r_[hold[name], np.zeros(11)])
    model = spec.compile()
    data = mujoco.MjData(model)
    for name, q in hold.items():
        data.qpos[model.joint(name).qposadr[0]] = q
    mujoco.mj_forward(model, data)
    ids = np.array([model.actuator(a).id for a in build.actuators], dtype=np.intp)
    joints = [by[n] for n in build.actuated]
    return StaticScene(model, data, joints, ids, np.array([hold[n] for n in build.actuated]))


def measure_fmax(scene: StaticScene, fmax_neg=None, fmax_pos=None, steps: int = PHASE_STEPS):
    """One static run (negative phase, rest, positive phase). Returns the peak torques
    (negative direction as a positive number, positive direction) per motor."""
    from ..body.actuation.muscle import Muscle

    m, d = scene.model, scene.data
    mujoco.mj_resetData(m, d)
    for k, j in enumerate(scene.joints):
        d.qpos[m.joint(j.name).qposadr[0]] = scene.hold[k]
    mujoco.mj_forward(m, d)
    act = Muscle(scene.joints, scene.actuator_ids, fmax_neg=fmax_neg, fmax_pos=fmax_pos)
    act.reset(m, d)
    n = len(scene.joints)
    peak_neg = np.zeros(n)
    peak_pos = np.zeros(n)
    u = np.zeros(2 * n)
    for phase, sl in ((0, slice(0, n)), (1, None), (2, slice(n, 2 * n))):
        u[:] = 0.0
        if sl is not None:
            u[sl] = 1.0
        act.apply(m, d, u)
        for step in range(steps):
            act.substep(m, d)
            mujoco.mj_step(m, d)
            if step >= steps // 2:
                f = d.actuator_force[scene.actuator_ids]
                if phase == 0:
                    np.maximum(peak_neg, -f, out=peak_neg)
                elif phase == 2:
                    np.maximum(peak_pos, f, out=peak_pos)
    return peak_neg, peak_pos


def _mirror_average(names: list[str], values: np.ndarray) -> np.ndarray:
    """Average each right_* value with its left_* twin (the published calibration does)."""
    out = values.copy()
    index = {n: k for k, n in enumerate(names)}
    for n, k in index.items():
        if n.startswith("right_"):
            other = index.get("left_" + n[len("right_"):])
            if other is not None:
                out[k] = out[other] = 0.5 * (values[k] + values[other])
    return out


def calibrate_fmax(hands: str = "mitten", iterations: int = ITERATIONS, steps: int = PHASE_STEPS,
                   start=None, progress=None) -> dict:
    """Iterate ``fmax <- fmax * target / achieved``; returns the parameters and the last check."""
    from ..body.actuation.muscle import muscle_parameters

    scene = static_scene(hands)
    names = [j.name for j in scene.joints]
    vmax, fn, fp = muscle_parameters(scene.joints)
    if start is not None:
        fn, fp = np.array(start[0], float), np.array(start[1], float)
    target_neg = np.array([j.torque_neg for j in scene.joints])
    target_pos = np.array([j.torque_pos for j in scene.joints])
    for it in range(iterations):
        got_neg, got_pos = measure_fmax(scene, fn, fp, steps)
        fn = _mirror_average(names, fn * target_neg / got_neg)
        fp = _mirror_average(names, fp * target_pos / got_pos)
        if progress:
            progress(it + 1, iterations)
    got_neg, got_pos = measure_fmax(scene, fn, fp, steps)
    return {"names": names, "vmax": vmax, "fmax_neg": fn, "fmax_pos": fp,
            "target_neg": target_neg, "target_pos": target_pos,
            "achieved_neg": got_neg, "achieved_pos": got_pos}


def fmax_table(result: dict) -> str:
    rows = [f"{'axis':28s} {'target-':>9s} {'achieved-':>10s} {'err-':>7s} {'target+':>9s} "
            f"{'achieved+':>10s} {'err+':>7s} {'fmax-':>9s} {'fmax+':>9s}"]
    for k, name in enumerate(result["names"]):
        tn, an = result["target_neg"][k], result["achieved_neg"][k]
        tp, ap = result["target_pos"][k], result["achieved_pos"][k]
        rows.append(f"{name:28s} {tn:9.4f} {an:10.4f} {100 * (an / tn - 1):+6.2f}% {tp:9.4f} "
                    f"{ap:10.4f} {100 * (ap / tp - 1):+6.2f}% {result['fmax_neg'][k]:9.4g} "
                    f"{result['fmax_pos'][k]:9.4g}")
    err = np.abs(np.r_[result["achieved_neg"] / result["target_neg"],
                       result["achieved_pos"] / result["target_pos"]] - 1)
    rows.append(f"{len(result['names'])} axes, worst error {100 * err.max():.2f} %, "
                f"{int((err <= 0.05).sum())}/{err.size} directions within 5 %")
    return "\n".join(rows)


# -- vmax -------------------------------------------------------------------------------------------
def floating_scene(hands: str = "mitten"):
    """One infant floating freely, gravity off, no floor. Returns (model, data, joints, ids,
    start): ``start`` is the qpos of the standing posture's joint angles (no limb inside
    another), where every episode starts."""
    from ..body.builder import build_infant
    from ..body.postures import POSTURES
    from ..core.world import World

    build = build_infant(hands, base="free")
    spec = build.spec
    World.set_physics_options(spec, _physics())
    model = spec.compile()
    by = {j.name: j for j in build.tables.joints}
    pose = POSTURES["standing"]["joints"]
    start = model.qpos0.copy()
    for name in build.joints:
        j = by[name]
        lo, hi = j.range_deg
        start[model.joint(name).qposadr[0]] = np.deg2rad(
            np.clip(pose.get(name, j.springref_deg), lo, hi))
    data = mujoco.MjData(model)
    ids = np.array([model.actuator(a).id for a in build.actuators], dtype=np.intp)
    return model, data, [by[n] for n in build.actuated], ids, start


def calibrate_vmax(hands: str = "mitten", episodes: int = 30, seconds: float = 30.0,
                   resample_seconds: float = 2.0, lr: float = 0.1, decay: float = 0.7,
                   decay_every: int = 50, frame_skip: int = 2, seed: int = 0,
                   scale_to_reference: bool = True, progress=None) -> dict:
    from ..body.actuation.muscle import Muscle, muscle_parameters

    model, data, joints, ids, start = floating_scene(hands)
    names = [j.name for j in joints]
    shipped, fn, fp = muscle_parameters(joints)
    vmax = shipped.copy()
    act = Muscle(joints, ids, vmax=vmax, fmax_neg=fn, fmax_pos=fp)
    rng = np.random.default_rng(seed)
    dt = model.opt.timestep
    control_steps = max(1, int(round(seconds / (dt * frame_skip))))
    every = max(1, int(round(resample_seconds / (dt * frame_skip))))
    moment = np.abs(act.moment[0])
    n = len(joints)
    peak = np.zeros(n)
    unstable = 0
    for ep in range(episodes):
        rate = lr * decay ** (ep // decay_every)
        mujoco.mj_resetData(model, data)
        data.qpos[:] = start
        mujoco.mj_forward(model, data)
        act.set_parameters(vmax=vmax)
        act.reset(model, data)
        peak = np.zeros(n)
        warnings = int(data.warning.number.sum())
        for k in range(control_steps):
            if k % every == 0:
                act.apply(model, data, (rng.random(2 * n) < 0.5).astype(float))
            for _ in range(frame_skip):
                act.substep(model, data)
                mujoco.mj_step(model, data)
                np.maximum(peak, moment * np.abs(data.qvel[act.dof_adr]), out=peak)
        if int(data.warning.number.sum()) > warnings:
            unstable += 1
            continue  # a diverged episode says nothing about speeds
        peak = _mirror_average(names, peak)
        vmax = vmax + rate * (peak - vmax)
        if progress:
            progress(ep + 1, episodes)
    raw = vmax.copy()
    factor = 1.0
    if scale_to_reference and REFERENCE_JOINT in names:
        k = names.index(REFERENCE_JOINT)
        factor = shipped[k] / raw[k]
    return {"names": names, "shipped": shipped, "peak": peak, "raw": raw, "vmax": raw * factor,
            "factor": factor, "fmax_neg": fn, "fmax_pos": fp, "unstable_episodes": unstable}


def vmax_table(result: dict) -> str:
    rows = [f"{'axis':28s} {'shipped':>9s} {'peak |dL/dt|':>13s} {'new (raw)':>10s} "
            f"{'new (scaled)':>13s} {'new/shipped':>12s}"]
    for k, name in enumerate(result["names"]):
        rows.append(f"{name:28s} {result['shipped'][k]:9.4f} {result['peak'][k]:13.4f} "
                    f"{result['raw'][k]:10.4f} {result['vmax'][k]:13.4f} "
                    f"{result['vmax'][k] / result['shipped'][k]:12.3f}")
    rows.append(f"common scale factor (knee -> {REFERENCE_JOINT} reference): {result['factor']:.4f}; "
                f"diverged episodes skipped: {result['unstable_episodes']}")
    return "\n".join(rows)


# -- speed ------------------------------------------------------------------------------------------
def measure_speed(hands: str = "mitten", seconds: float = 20.0, seed: int = 0,
                  episode_seconds: float = 10.0) -> dict:
    """The issue's two figures for one infant standing in free play:

    - ``physics_real_per_sim``: real s per simulated s of a bare ``mj_step`` loop (the bench's
      ``physics_only`` method: the bench's smooth random actions written into ``data.ctrl`` as
      spring-damper torques; the infant is put back in its initial pose every
      ``episode_seconds``);
    - ``muscle_ms_per_step``: the muscle model's own cost, ms per physics step per infant (the
      time inside ``Muscle.substep``), with the same actions split into the two muscles of each
      axis (``u < 0`` drives the negative muscle, ``u > 0`` the positive one), and
      ``muscle_real_per_sim`` the real s per simulated s of that loop (physics + muscles).
    """
    import time

    from ..envs import free_play_v0

    out = {"hands": hands, "seconds": seconds}
    for kind in ("spring_damper", "muscle"):
        env = free_play_v0.parallel_env(n_agents=1, hands=hands, actuation=kind,
                                        expressions=False)
        env.reset(seed=seed)
        w = env.world
        m, d = w.model, w.data
        act = env.actuation[0]
        n_axes = len(act.joints)
        steps = max(1, int(round(seconds / env.dt)))
        every = max(1, int(round(episode_seconds / env.dt)))
        motors, _ = smooth_random_actions(steps, n_axes, seed, dt=env.dt)
        motors = motors.astype(np.float64)
        if kind == "spring_damper":
            controls = np.array([act.torque(u) for u in motors])
        else:
            controls = np.concatenate([np.maximum(-motors, 0.0), np.maximum(motors, 0.0)], axis=1)
        skip, step, clock = env.frame_skip, mujoco.mj_step, time.perf_counter
        ids = act.actuator_ids
        inside = 0.0
        total = 0.0
        for k in range(steps):
            if k % every == 0:
                w.reset()
                act.reset(m, d)
            t0 = clock()
            if kind == "spring_damper":
                d.ctrl[ids] = controls[k]
                for _ in range(skip):
                    step(m, d)
            else:
                act.apply(m, d, controls[k])
                for _ in range(skip):
                    t1 = clock()
                    act.substep(m, d)
                    inside += clock() - t1
                    step(m, d)
            total += clock() - t0
        sim = steps * env.dt
        if kind == "spring_damper":
            out["physics_real_per_sim"] = total / sim
        else:
            out["muscle_real_per_sim"] = total / sim
            out["muscle_ms_per_step"] = 1e3 * inside / (steps * skip)
            out["muscle_axes"] = n_axes
        env.close()
    return out


# -- the parameter file ----------------------------------------------------------------------------
def _data_file(hands: str) -> Path:
    return Path(str(resources.files("mimo_social.body").joinpath("data", f"{hands}_muscles.csv")))


def write_parameters(hands: str, updates: dict, path: Path | None = None) -> Path:
    """Merge ``joint -> (vmax, fmax_neg, fmax_pos)`` (right side and midline; left joints use
    their right twin) into ``body/data/<hands>_muscles.csv``."""
    from ..body.tables import load_body

    path = Path(path) if path is not None else _data_file(hands)
    rows = {}
    if path.is_file():
        with path.open() as f:
            rows = {r["joint"]: (float(r["vmax"]), float(r["fmax_neg"]), float(r["fmax_pos"]))
                    for r in csv.DictReader(f)}
    rows.update({k: v for k, v in updates.items() if not k.startswith("left_")})
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["joint", "vmax", "fmax_neg", "fmax_pos"])
        for name, (v, fn, fp) in rows.items():
            w.writerow([name, f"{v:.6g}", f"{fn:.6g}", f"{fp:.6g}"])
    load_body.cache_clear()
    return path


def hand_versions(hands: str) -> tuple[str, ...]:
    """The body versions of a ``--hands`` choice (``"both"``: mitten and five fingers)."""
    return ("mitten", "five_fingers") if hands == "both" else (hands,)
