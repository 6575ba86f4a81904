"""``GazeAtTarget``: a scripted partner that turns its head and eyes to one target after another.

Every ``hold_s`` seconds (a time drawn uniformly from the range) it picks another target at
random (never the same twice in a row) and turns to it with its own motors: a PD law with
compensation of gravity, springs and any force the task applies drives its head (swivel, tilt;
sideways tilt to 0) and eye joints (horizontal, vertical; torsion to 0) from their current angles to
the angles that look at the target. Those angles come from
:class:`~mimo_social.core.kinematics.LookAt`, the geometry that the tasks'
:class:`~mimo_social.core.kinematics.Gaze` sets directly (the head turns, swivel then tilt, to face
the target from the neck; each eye then turns, horizontal then vertical, to look at it from its own
centre), computed on a private copy of the state: the partner never writes the world's ``qpos``, so
its head turn is physical (it takes about 0.3 s) and visible to whoever watches it.

How much of a gaze shift the head makes: ``head_share`` (a share ``s`` in [0, 1], or a range
``(lo, hi)`` drawn from anew at every shift; ``None``: the task's ``partner_head_share`` range
where it has one, else 1). The head turns ``s`` of the way (swivel and tilt) and the eyes the
rest, from where the head then points; the head always makes up what the eyes cannot reach
(``EYE_REACH_DEG`` from straight ahead, less where an eye would pass its range: its horizontal
and vertical turns add up). ``s = 1``: the head faces the target and the eyes only
correct for their offset; ``s = 0``: the eyes turn alone as far as they reach (adults move
mostly their eyes for small gaze shifts and add the head for large ones).

Targets: by default the task's toys (``env.task.toy_bodies``, a list of body ids), else a list
of body or site names of the world. ``target`` is the index of the current one. The agent needs
the spring-damper actuation (the PD law computes torques) and motors on its head and eye joints.
"""

from __future__ import annotations

from typing import Sequence

import mujoco
import numpy as np
from gymnasium import spaces

from ..core.kinematics import LookAt
from ..util.checks import ConfigError, check_number, check_numbers, show
from .base import Partner, agent_index, require_motors
from .expression import hold_range

__all__ = ["GazeAtTarget", "look_angles", "head_share_range"]

EYE_REACH_DEG = 40.0   # the eyes turn at most this far from straight ahead (their range: 45-47)
NEEDED = ("head_swivel", "head_tilt", "right_eye_horizontal", "right_eye_vertical",
          "left_eye_horizontal", "left_eye_vertical")


def _angles(look: LookAt, model, data, scratch, kind: str, obj: int) -> np.ndarray:
    """``look``'s angles for the state in ``data``, computed on ``scratch`` (a private MjData)."""
    scratch.qpos[:] = data.qpos
    return look(model, scratch, kind, obj)


def look_angles(env, agent: str, kind: str, obj: int) -> dict[str, float]:
    """Head and eye angles (rad) that make ``agent`` look at body/site ``obj``, by joint name
    (a convenience for inspection; :class:`GazeAtTarget` keeps its geometry between steps)."""
    i = env.possible_agents.index(agent)
    geo = LookAt(env.world, i)
    scratch = mujoco.MjData(env.world.model)
    q = _angles(geo, env.world.model, env.world.data, scratch, kind, obj)
    names = env.world.agents[i].joint_names
    return {names[k]: float(v) for k, v in zip(geo.joints, q)}


def head_share_range(value, who: str = "GazeAtTarget") -> tuple[float, float] | None:
    """``None``, a share in [0, 1] or a ``(lo, hi)`` range of shares, as a range (or None)."""
    if value is None:
        return None
    allowed = "None, a number in [0, 1] or a (lo, hi) range with 0 <= lo <= hi <= 1"
    if isinstance(value, (int, float, np.number)) and not isinstance(value, (bool, np.bool_)):
        share = check_number(who, "head_share", value, 0.0, 1.0)
        return share, share
    lo, hi = check_numbers(who, "head_share", value, 2, 0.0, 1.0, allowed)
    if lo > hi:
        raise ConfigError(f"{who}: head_share={show(value)} not allowed; allowed: {allowed}")
    return lo, hi


class GazeAtTarget(Partner):
    """Looks at one target after another (see the module docstring).

    ``targets``: ``None`` (the task's toys, ``env.task.toy_bodies``) or a list of body/site
    names; ``hold_s``: ``(min, max)`` seconds on each target; ``omega`` (rad/s) and ``zeta``:
    the PD law's natural frequency and damping ratio (per joint, scaled by its inertia);
    ``head_share``: the share of each turn the head makes (see the module docstring).
    ``share`` is the current shift's share.
    """

    def __init__(self, targets: Sequence[str] | None = None, hold_s=(1.5, 3.0),
                 omega: float = 15.0, zeta: float = 1.0, head_share=None):
        self.hold_s = hold_range(hold_s, "GazeAtTarget")
        self.head_share = head_share_range(head_share)
        self.share = 1.0
        if targets is not None:
            if isinstance(targets, str) or not isinstance(targets, Sequence) or not targets \
                    or not all(isinstance(t, str) for t in targets):
                raise ConfigError(f"GazeAtTarget: targets={show(targets)} not allowed; allowed: "
                                  "None (the task's toys) or a non-empty list of body or site "
                                  "names")
        self.targets = None if targets is None else tuple(targets)
        self.omega = check_number("GazeAtTarget", "omega", omega, 0.01, 1000.0)
        self.zeta = check_number("GazeAtTarget", "zeta", zeta, 0.01, 1000.0)
        self.target: int | None = None
        self._left = 0

    # -- set up ------------------------------------------------------------------------------
    def _resolve_targets(self, env) -> list[tuple[str, int]]:
        m = env.world.model
        if self.targets is None:
            toys = getattr(env.task, "toy_bodies", None)
            if toys is None or not len(toys):
                raise ValueError(f"GazeAtTarget: the task {env.task.name!r} has no toys "
                                 "(task.toy_bodies); pass targets=[body or site names]")
            return [("body", int(b)) for b in toys]
        out = []
        for name in self.targets:
            for kind, table in (("body", mujoco.mjtObj.mjOBJ_BODY),
                                ("site", mujoco.mjtObj.mjOBJ_SITE)):
                k = mujoco.mj_name2id(m, table, name)
                if k >= 0:
                    out.append((kind, k))
                    break
            else:
                raise ValueError(f"GazeAtTarget: target {name!r} is neither a body nor a site of "
                                 "the world (prefix an agent's parts with its name, e.g. "
                                 "'infant_0/head')")
        return out

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        i = agent_index(env, agent)
        cfg = env.agent_configs[i]
        if cfg.actuation != "spring_damper":
            raise ValueError(f"GazeAtTarget drives torque motors: {agent} has actuation="
                             f"{cfg.actuation!r}; allowed: 'spring_damper'")
        a = env.world.agents[i]
        require_motors("GazeAtTarget", agent, a, NEEDED, "it turns its head and eyes with its "
                       "own motors (the task must leave them actuated)")
        self._found = self._resolve_targets(env)
        self._geo = LookAt(env.world, i)
        self._scratch = mujoco.MjData(env.world.model)
        act = env.actuation[i]
        names = list(a.joint_names)
        motor_of = {n: k for k, n in enumerate(a.actuated_names)}
        joint_names = [names[k] for k in self._geo.joints]
        keep = [n for n, j in enumerate(joint_names) if j in motor_of]
        self._pick = np.array(keep, dtype=np.intp)              # geometry slots with a motor
        self._motors = np.array([motor_of[joint_names[n]] for n in keep], dtype=np.intp)
        joints = self._geo.joints[self._pick]
        self._qpos = a.qpos_adr[joints]
        self._dof = a.dof_adr[joints]
        m = env.world.model
        # the diagonal of the mass matrix: the last entry of each row of MjData.M (CSR, lower)
        self._mdiag = (m.M_rowadr[self._dof] + m.M_rownnz[self._dof] - 1).astype(np.intp)
        self._t_pos = np.asarray(act.torque_pos, float)[self._motors]
        self._t_neg = np.asarray(act.torque_neg, float)[self._motors]
        self._n_motors = act.n_controls
        space = env.action_space(agent)
        self._dict = isinstance(space, spaces.Dict)
        self._dt = float(env.dt)
        task_share = getattr(env.task, "partner_head_share", None)
        self._shares = self.head_share or head_share_range(task_share, "the task's "
                                                           "partner_head_share") or (1.0, 1.0)
        g = self._geo
        self._head_slots = [k for k in (g.swivel, g.tilt) if k is not None]
        self._reach = np.deg2rad(EYE_REACH_DEG)
        self.target = int(rng.integers(len(self._found)))
        self._left = self._hold_steps()
        self._draw_share()

    def _draw_share(self) -> None:
        lo, hi = self._shares
        self.share = float(self.rng.uniform(lo, hi)) if hi > lo else lo

    def _hold_steps(self) -> int:
        return max(1, int(round(self.rng.uniform(*self.hold_s) / self._dt)))

    # -- acting ------------------------------------------------------------------------------
    def desired_angles(self, env) -> np.ndarray:
        """Angles (rad) of the head and eye joints with motors that look at the current target."""
        kind, obj = self._found[self.target]
        w = env.world
        if self.__dict__.get("_scratch") is None:   # dropped when pickled
            self._scratch = mujoco.MjData(w.model)
        q = _angles(self._geo, w.model, w.data, self._scratch, kind, obj)
        if self.share < 1.0 and self._head_slots:
            q = self._share_turn(w.model, q, kind, obj)
        return q[self._pick]

    def _share_turn(self, model, q: np.ndarray, kind: str, obj: int) -> np.ndarray:
        """``q`` (the head facing the target) with the head turned ``share`` of the way and the
        eyes aimed from there; where an eye would then pass its range, the head turns further
        (the eyes' reach shrinks by 5-degree steps down to 0: the full head turn)."""
        g, d = self._geo, self._scratch
        full = q.copy()
        eyes = [k for _, _, h, v in g.eyes for k in (h, v) if k is not None]
        lo, hi = g.lo[eyes] + 1e-3, g.hi[eyes] - 1e-3
        for reach in np.arange(self._reach, -1e-9, -np.deg2rad(5.0)):
            q = full.copy()
            for k in self._head_slots:
                q[k] = full[k] - np.clip((1.0 - self.share) * full[k], -reach, reach)
            d.qpos[g.qpos] = q
            mujoco.mj_kinematics(model, d)
            target = (d.xpos if kind == "body" else d.site_xpos)[obj]
            R = d.xmat[g.head_body].reshape(3, 3)
            for body, sign, horizontal, vertical in g.eyes:
                v = R.T @ (target - d.xpos[body])
                if horizontal is not None:
                    q[horizontal] = sign * np.arctan2(v[1], v[0])
                if vertical is not None:
                    q[vertical] = np.arctan2(v[2], np.hypot(v[0], v[1]))
            if np.all((q[eyes] >= lo) & (q[eyes] <= hi)):
                break
        return np.clip(q, g.lo, g.hi)

    def act(self, env, agent, observation):
        if self.target is None:
            raise RuntimeError("GazeAtTarget.act() before reset(); reset the env first")
        if self._left <= 0 and len(self._found) > 1:
            others = [k for k in range(len(self._found)) if k != self.target]
            self.target = int(self.rng.choice(others))
            self._left = self._hold_steps()
            self._draw_share()
        self._left -= 1
        d = env.world.data
        err = self.desired_angles(env) - d.qpos[self._qpos]
        vel = d.qvel[self._dof]
        inertia = d.M[self._mdiag]
        w, z = self.omega, self.zeta
        torque = (inertia * (w * w * err - 2.0 * z * w * vel)
                  + d.qfrc_bias[self._dof] - d.qfrc_passive[self._dof] - d.qfrc_applied[self._dof])
        u = np.zeros(self._n_motors, np.float32)
        u[self._motors] = np.clip(torque / np.where(torque >= 0, self._t_pos, self._t_neg), -1, 1)
        return {"motors": u, "expression": np.int64(0)} if self._dict else u

    def __getstate__(self):
        state = self.__dict__.copy()
        state.pop("_scratch", None)   # MjData is rebuilt at the next reset
        return state

    def __repr__(self) -> str:
        return (f"GazeAtTarget(targets={self.targets}, hold_s={self.hold_s}, "
                f"head_share={self.head_share})")
