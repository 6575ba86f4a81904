"""Kinematics on the compiled world for tasks and partners: look-at angles of head and eyes,
inverse kinematics of a site and the geoms of a hand (an agent's line of sight:
:mod:`mimo_social.body.sight`).

:class:`LookAt` is the one computation of the angles that point an agent's head and eyes at a
world point; :class:`Gaze` (tasks: sets them on the state) and
:class:`~mimo_social.partners.gaze.GazeAtTarget` (partners: drives the joints toward them with
the agent's motors) both use it.
"""

from __future__ import annotations

from typing import Sequence

import mujoco
import numpy as np

from ..body.joint_groups import GAZE_JOINTS

__all__ = ["LookAt", "Gaze", "reach_sites", "hand_geoms", "geoms_collide"]


class LookAt:
    """The joint angles that point agent ``i``'s head and eyes at a world point.

    The head turns (swivel, then tilt) to face the target from the neck; each eye then turns
    (horizontal, then vertical) to look at it from its own centre. The sideways head tilt and
    the eyes' torsion stay at 0. ``joints``: the agent's joint indices (into ``joint_names``)
    to use, by default every head and eye joint it has. ``__call__`` returns their angles (rad,
    within range) in the order of ``self.joints``.
    """

    def __init__(self, world, i: int, joints: Sequence[int] | None = None):
        m = world.model
        a = world.agents[i]
        names = list(a.joint_names)
        if joints is None:
            joints = [names.index(n) for n in GAZE_JOINTS if n in names]
        self.joints = np.asarray(joints, dtype=np.intp)
        self.qpos = a.qpos_adr[self.joints]
        self.dof = a.dof_adr[self.joints]
        self.lo, self.hi = a.joint_range[self.joints, 0], a.joint_range[self.joints, 1]
        slot = {names[k]: n for n, k in enumerate(self.joints)}
        self.swivel, self.tilt = slot.get("head_swivel"), slot.get("head_tilt")
        self.head_body = int(m.site_bodyid[a.head_site])
        self.eyes = [(int(m.cam_bodyid[cam]), sign, slot.get(f"{side}_eye_horizontal"),
                      slot.get(f"{side}_eye_vertical"))
                     for side, sign, cam in (("right", -1.0, a.eye_cameras[0]),
                                             ("left", 1.0, a.eye_cameras[1]))]

    def __call__(self, model, data, kind: str, obj: int) -> np.ndarray:
        """Angles that fixate body ``obj`` (``kind="body"``) or site ``obj`` (``"site"``).

        Computed on ``data``: its angles of these joints are overwritten (pass a scratch copy
        to keep a state)."""
        data.qpos[self.qpos] = 0.0
        mujoco.mj_kinematics(model, data)
        target = (data.xpos if kind == "body" else data.site_xpos)[obj].copy()
        return self.point(model, data, target, zeroed=True)

    def point(self, model, data, target, zeroed: bool = False) -> np.ndarray:
        """Angles that fixate the world point ``target``, computed on ``data`` like
        :meth:`__call__` (its angles of these joints are overwritten; ``zeroed``: they are
        already 0 and the kinematics up to date)."""
        d = data
        if not zeroed:
            d.qpos[self.qpos] = 0.0
            mujoco.mj_kinematics(model, d)
        target = np.asarray(target, float)
        q = np.zeros(len(self.joints))
        hb = self.head_body
        if self.swivel is not None:
            v = d.xmat[hb].reshape(3, 3).T @ (target - d.xpos[hb])
            q[self.swivel] = np.arctan2(v[1], v[0])
            if self.tilt is not None:
                q[self.tilt] = -np.arctan2(v[2], np.hypot(v[0], v[1]))
            np.clip(q, self.lo, self.hi, out=q)
            d.qpos[self.qpos] = q
            mujoco.mj_kinematics(model, d)
        R = d.xmat[hb].reshape(3, 3)
        for body, sign, horizontal, vertical in self.eyes:
            v = R.T @ (target - d.xpos[body])
            if horizontal is not None:
                q[horizontal] = sign * np.arctan2(v[1], v[0])
            if vertical is not None:
                q[vertical] = np.arctan2(v[2], np.hypot(v[0], v[1]))
        return np.clip(q, self.lo, self.hi)


class Gaze:
    """Turns one agent's head and eyes to fixate a world point by setting their joint angles.

    The joints are the agent's gaze joints (``AgentSetup.gaze_joints``); the angles come from
    :class:`LookAt`, so the joint angles of head and eyes together tell where the target is, as
    in the paper's reach and catch tasks. Addresses are resolved once; a call costs three
    ``mj_kinematics``.
    """

    def __init__(self, world, i: int):
        a = world.agents[i]
        self.agent = a
        self.look = LookAt(world, i, a.gaze_idx)

    def __call__(self, model, data, kind: str, obj: int) -> None:
        """Fixate body ``obj`` (``kind="body"``) or site ``obj`` (``kind="site"``)."""
        look = self.look
        if not len(look.joints):
            return
        data.qpos[look.qpos] = look(model, data, kind, obj)
        data.qvel[look.dof] = 0.0
        mujoco.mj_kinematics(model, data)


def reach_sites(model, data, qpos_adr, dof_adr, lo, hi, site: int, target, iters: int = 60):
    """Damped least squares: move the joints at ``qpos_adr``/``dof_adr`` (limits lo, hi) so that
    ``site`` comes to ``target`` (world); ``data.qpos`` is changed in place. Returns the
    remaining distance (m)."""
    jacp = np.zeros((3, model.nv))
    for _ in range(iters):
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        err = np.asarray(target) - data.site_xpos[site]
        if np.linalg.norm(err) < 1e-4:
            break
        mujoco.mj_jacSite(model, data, jacp, None, site)
        J = jacp[:, dof_adr]
        step = J.T @ np.linalg.solve(J @ J.T + 1e-4 * np.eye(3), err)
        data.qpos[qpos_adr] = np.clip(data.qpos[qpos_adr] + step, lo, hi)
    mujoco.mj_kinematics(model, data)
    return float(np.linalg.norm(np.asarray(target) - data.site_xpos[site]))


def hand_geoms(world, i: int, side: int = 0) -> np.ndarray:
    """Geoms of agent i's hand (``side`` 0: right, 1: left): the body holding the palm site and
    every body below it (the mitten's fingers, or the five fingers' segments)."""
    m = world.model
    a = world.agents[i]
    hand = int(m.site_bodyid[a.palm_sites[side]])
    inside = np.zeros(m.nbody, bool)
    inside[hand] = True
    for b in sorted(a.body_ids.tolist()):  # MuJoCo numbers a parent before its children
        if inside[m.body_parentid[b]]:
            inside[b] = True
    return a.geom_ids[inside[m.geom_bodyid[a.geom_ids]]]


def geoms_collide(model, g1: int, g2: int) -> bool:
    """Whether MuJoCo's collision filter lets geoms ``g1`` and ``g2`` touch: not on a parent and
    its child body, and one's ``contype`` matching the other's ``conaffinity``."""
    b1, b2 = int(model.geom_bodyid[g1]), int(model.geom_bodyid[g2])
    if model.body_parentid[b1] == b2 or model.body_parentid[b2] == b1:
        return False
    return bool((model.geom_contype[g1] & model.geom_conaffinity[g2])
                or (model.geom_contype[g2] & model.geom_conaffinity[g1]))
