"""What a scripted partner is: a policy for one agent that acts through that agent's actions.

A partner sees the whole env (it is scripted, so it may read the world's state, for example
where a toy lies) but it moves its infant only through the action space, exactly as a learner
would: any scripted partner can be swapped for a learner, or for another partner, without
changing the task.
"""

from __future__ import annotations

import inspect
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence

import numpy as np
from gymnasium import spaces

from ..util.checks import ConfigError, check_number, show

if TYPE_CHECKING:  # pragma: no cover
    from ..core.env import MimoParallelEnv

__all__ = ["Partner", "Still", "zero_action", "agent_index", "require_motors", "require_prop",
           "pd_gains", "motor_action", "torque_controls", "follow_waypoints", "servo_waypoints",
           "check_angles", "check_variants", "TorqueMotors", "agent_motors", "torque_motors",
           "push_torques"]


def zero_action(space: spaces.Space):
    """The resting action of an agent: zero motor commands (muscles: no activation) and, when
    the agent has expressions, the neutral face (id 0)."""
    if isinstance(space, spaces.Dict):
        return {k: zero_action(s) for k, s in space.spaces.items()}
    if isinstance(space, spaces.Discrete):
        return int(space.start)
    if isinstance(space, spaces.Box):
        return np.clip(np.zeros(space.shape, space.dtype), space.low, space.high)
    raise TypeError(f"no resting action for space {space}")


def check_angles(who: str, name: str, value, joints: Sequence[str] | None = None,
                 limit: float = 360.0) -> dict[str, float]:
    """A partner's joint-angle setting: a mapping joint name -> degrees (each a finite number
    within +-``limit``; ``joints``: the names allowed, None: any string), as a dict of floats;
    else a ConfigError naming the setting."""
    allowed = f"a mapping of {'joint names' if joints is None else list(joints)} to degrees"
    if not isinstance(value, Mapping):
        raise ConfigError(f"{who}: {name}={show(value)} not allowed; allowed: {allowed}")
    bad = [k for k in value if not isinstance(k, str) or (joints is not None and k not in joints)]
    if bad:
        raise ConfigError(f"{who}: {name} joints {bad} unknown; allowed: {allowed}")
    return {k: check_number(who, f"{name}[{k!r}]", v, -limit, limit) for k, v in value.items()}


def check_variants(who: str, value, plan: Callable, default: Sequence[Mapping],
                   extra: Sequence[str] = ()) -> list[dict]:
    """A planner's ``variants`` setting: None (``default``) or a non-empty list of mappings
    whose keys are keyword arguments of ``plan`` (or ``extra``), as a list of dicts; else a
    ConfigError naming ``variants``."""
    if value is None:
        return [dict(v) for v in default]
    keys = sorted({p.name for p in inspect.signature(plan).parameters.values()
                   if p.default is not inspect.Parameter.empty} | set(extra))
    allowed = f"None or a non-empty list of mappings with keys from {keys}"
    if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, Sequence) \
            or not len(value) or not all(isinstance(v, Mapping) for v in value):
        raise ConfigError(f"{who}: variants={show(value)} not allowed; allowed: {allowed}")
    bad = sorted({str(k) for v in value for k in v if k not in keys})
    if bad:
        raise ConfigError(f"{who}: variants name unknown plan settings {bad}; allowed: {allowed}")
    return [dict(v) for v in value]


def motor_action(space: spaces.Space, motors) -> Any:
    """An action of ``space`` that sends the motor commands ``motors`` (float32): the array
    itself for a Box action, or the resting action with its ``"motors"`` entry set for a Dict
    one (the face stays neutral)."""
    u = np.asarray(motors, dtype=np.float32)
    action = zero_action(space)
    if isinstance(action, dict):
        action["motors"] = u
        return action
    return u


def agent_index(env, agent: str) -> int:
    """The index of ``agent`` in the env (its world's tables are ``env.world.agents[i]``)."""
    return env.possible_agents.index(agent)


def require_motors(who: str, agent: str, tables, joints, why: str) -> None:
    """A ValueError naming the partner, the agent and the joints it lacks motors on, unless
    every joint of ``joints`` is actuated in the agent's action (``tables``: its world index
    tables); ``why`` says what the partner needs them for."""
    missing = [n for n in joints if n not in tables.actuated_names]
    if missing:
        raise ValueError(f"{who}: {agent} does not actuate {missing}; {why}")


def require_prop(who: str, world, prop: str) -> int:
    """The body id of the prop named ``prop``, or a ValueError naming the props of the world."""
    if prop not in world.prop_bodies:
        raise ValueError(f"{who}: prop {prop!r} is not in this env; props: "
                         f"{sorted(world.prop_bodies)}")
    return world.prop_bodies[prop]


def pd_gains(model, data, dof_adr, frequency: float, damping: float,
             extra_inertia=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness and damping of a PD loop per joint, from each joint's own inertia (the diagonal
    of the joint-space mass matrix at the current pose, plus ``extra_inertia``, e.g. a held
    ball): ``kp = I w^2``, ``kd = 2 zeta I w`` with ``w = 2 pi frequency`` and ``zeta =
    damping``, so each joint alone would settle like a mass-spring-damper at ``frequency``."""
    import mujoco
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    inertia = np.diag(M)[np.asarray(dof_adr)] + extra_inertia
    omega = 2 * np.pi * frequency
    return inertia * omega ** 2, inertia * 2 * damping * omega


def follow_waypoints(data, waypoints, state: list, hold_steps: int, tolerance: float, qpos_adr,
                     dof_adr, kp, kd, torque_neg, torque_pos) -> np.ndarray:
    """One step of a PD walk through joint-angle ``waypoints``: the spring-damper motor commands
    (in [-1, 1]) toward the current waypoint, with gravity and passive-spring compensation.
    ``state`` = [waypoint index, steps spent at it, target angles] is advanced in place: to the
    next waypoint after ``hold_steps`` steps or once every joint is within ``tolerance`` (rad)."""
    q = data.qpos[qpos_adr]
    _advance(waypoints, state, q, hold_steps, tolerance)
    tau = kp * (state[2] - q) - kd * data.qvel[dof_adr]
    tau += data.qfrc_bias[dof_adr] - data.qfrc_spring[dof_adr]
    return np.clip(np.where(tau >= 0, tau / torque_pos, tau / torque_neg), -1.0, 1.0)


def _advance(waypoints, state: list, q, hold_steps: int, tolerance: float) -> None:
    """The walk's state (see :func:`follow_waypoints`) advanced by one step at angles ``q``."""
    state[1] += 1
    if state[0] < len(waypoints) - 1 and (
            state[1] >= hold_steps or np.max(np.abs(state[2] - q)) < tolerance):
        state[0] += 1
        state[1] = 0
        state[2] = waypoints[state[0]]


def servo_waypoints(data, waypoints, state: list, hold_steps: int, tolerance: float, qpos_adr,
                    dof_adr, servo_kp, lo, hi) -> np.ndarray:
    """:func:`follow_waypoints` for positional actuation: the controls (in [-1, 1] of each
    joint's range) whose target angle is the current waypoint plus the gravity / Coriolis
    torque over the servo's stiffness ``servo_kp`` (the servo cancels the passive spring
    itself), so the joint comes to rest on the waypoint under load; ``state`` advances as
    there."""
    _advance(waypoints, state, data.qpos[qpos_adr], hold_steps, tolerance)
    target = state[2] + data.qfrc_bias[dof_adr] / servo_kp
    return np.clip(2.0 * (target - lo) / (hi - lo) - 1.0, -1.0, 1.0)


class TorqueMotors:
    """An agent's motors as a scripted controller reads them: the agent's ``index`` and world
    index ``tables``, the actuation model ``act``, the motors' joint ``names``, their
    ``qpos_adr`` / ``dof_adr`` and joint limits ``lo`` / ``hi`` (rad)."""

    def __init__(self, act, names, qpos_adr, dof_adr, lo, hi, index=None, tables=None):
        self.act, self.names = act, list(names)
        self.qpos_adr, self.dof_adr, self.lo, self.hi = qpos_adr, dof_adr, lo, hi
        self.index, self.tables = index, tables


def agent_motors(who: str, env, agent: str, joints=(), why: str = "") -> TorqueMotors:
    """``agent``'s motors (:class:`TorqueMotors`) for scripted controller ``who``, after
    :func:`require_motors` (``joints``, ``why``): a ValueError naming both when a joint it
    needs has no motor."""
    i = agent_index(env, agent)
    a = env.world.agents[i]
    require_motors(who, agent, a, joints, why)
    jk = a.actuated_joint_idx
    return TorqueMotors(env.actuation[i], a.actuated_names, a.qpos_adr[jk], a.dof_adr[jk],
                        a.joint_range[jk, 0], a.joint_range[jk, 1], i, a)


def torque_motors(who: str, env, agent: str) -> TorqueMotors:
    """``agent``'s torque motors (:class:`TorqueMotors`) for scripted controller ``who``; a
    ValueError naming both for an agent on muscles (its controls are not torques)."""
    motors = agent_motors(who, env, agent)
    if motors.act.name == "muscle":
        raise ValueError(f"{who}: {agent} has actuation='muscle'; allowed: 'spring_damper' (it "
                         "drives torque motors)")
    return motors


def push_torques(model, data, jac: np.ndarray, dof_adr, pushes) -> np.ndarray:
    """The joint torques that make each body of ``pushes`` (``(body id, world force (3,))``)
    push with that force, ``J^T f`` over the ``dof_adr`` joints (``jac``: a (3, nv) scratch)."""
    import mujoco
    tau = np.zeros(len(dof_adr))
    for body, force in pushes:
        mujoco.mj_jacBody(model, data, jac, None, body)
        tau += jac[:, dof_adr].T @ force
    return tau


class Partner:
    """Base class of scripted partners.

    ``reset(env, agent, rng)`` is called after every env reset (``env`` is the
    :class:`~mimo_social.core.env.MimoParallelEnv`, ``agent`` the partner's name, ``rng``
    a generator seeded from the reset seed); ``act(env, agent, observation)`` returns the
    agent's action for the next step, in ``env.action_space(agent)``.
    """

    def reset(self, env: "MimoParallelEnv", agent: str, rng: np.random.Generator) -> None:
        self.rng = rng

    def act(self, env: "MimoParallelEnv", agent: str, observation) -> Any:
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class Still(Partner):
    """Does nothing: zero motor commands and a neutral face (a passive partner)."""

    def act(self, env, agent, observation):
        return zero_action(env.action_space(agent))


def torque_controls(act, q, tau) -> np.ndarray:
    """The controls with which actuation model ``act`` exerts the joint torques ``tau`` (one per
    motor) at joint angles ``q`` (rad), statically. Muscles: the agonist's activation on top of
    the passive forces, from the isometric force-length curve (antagonist off), clipped to
    [0, 1], in the ``2 n`` control layout (negative muscles, then positive ones); spring-damper
    motors: ``tau / T_max`` in the pushing direction, clipped to [-1, 1]."""
    tau = np.asarray(tau, float)
    if act.name == "muscle":
        n_full, p_full = act.isometric_torque(q, 1.0)
        n_rest, p_rest = act.isometric_torque(q, 0.0)
        need = tau - (n_rest + p_rest)
        neg = np.clip(need / np.minimum(n_full - n_rest, -1e-9), 0.0, 1.0)
        pos = np.clip(need / np.maximum(p_full - p_rest, 1e-9), 0.0, 1.0)
        return np.concatenate([neg, pos])
    return np.clip(np.where(tau >= 0, tau / act.torque_pos, tau / act.torque_neg), -1.0, 1.0)
