"""Keeping the play room's things and the agents apart at the start.

:func:`clear_toys` moves a toy whose place on the mat an agent or a task's prop takes to its
spare place on the furniture; :func:`check_scene_clear` refuses an agent placed inside a wall
or a piece of furniture (a ConfigError naming it). Both read a world's compiled model (duck
typed: ``model``, ``data``, ``room``, ``geom_agent``, ``agent_setups``, ``names``).
"""

from __future__ import annotations

import numpy as np

from ..util.checks import ConfigError
from .playroom import TOY_CLEARANCE, Room

__all__ = ["clear_toys", "check_scene_clear", "ROOM_OVERLAP_DEPTH"]


def clear_toys(model, data, room: Room, other_geoms: np.ndarray, qpos: np.ndarray) -> list[str]:
    """Move every toy of ``room`` whose start comes within :data:`TOY_CLEARANCE` (bounding
    spheres) of one of ``other_geoms`` (the agents' and the task's props' geoms; ``data``'s
    kinematics up to date) to its spare place: written into ``qpos`` (the world's initial
    one). Returns the toys moved."""
    if not len(other_geoms):
        return []
    moved = []
    pos, rb = data.geom_xpos[other_geoms], model.geom_rbound[other_geoms]
    for body in room.toys:
        if body not in room.spares:
            continue
        b = model.body(body).id
        geoms = np.flatnonzero(model.geom_bodyid == b)
        gap = (np.linalg.norm(data.geom_xpos[geoms][:, None] - pos[None], axis=2)
               - model.geom_rbound[geoms][:, None] - rb[None])
        if gap.min() < TOY_CLEARANCE:
            q = int(model.jnt_qposadr[model.body_jntadr[b]])
            qpos[q:q + 3] = room.spares[body]
            moved.append(body)
    return moved


#: how deep (m) an agent or a task's prop may start in the play room's walls or furniture
ROOM_OVERLAP_DEPTH = 0.005


def check_scene_clear(world) -> None:
    """In the play room, a ConfigError naming the agent, where it stands and the piece of
    furniture or wall when it starts inside one (deeper than :data:`ROOM_OVERLAP_DEPTH`);
    nothing on the floor. (A task's props are left out: tasks place them at reset.) Reads a
    scratch copy of the state."""
    if world.room is None:
        return
    m = world.model
    d = world.scratch_contacts()
    n = d.ncon
    names = [m.geom(g).name for g in range(m.ngeom)]
    fixed = np.array([m.geom_bodyid[g] == 0 and names[g].startswith("playroom/")
                      and names[g] not in ("playroom/floor", "playroom/mat")
                      for g in range(m.ngeom)])
    c = d.contact
    for k in np.argsort(c.dist[:n]):
        g1, g2 = int(c.geom1[k]), int(c.geom2[k])
        if -c.dist[k] <= ROOM_OVERLAP_DEPTH or fixed[g1] == fixed[g2]:
            continue
        room, other = (g1, g2) if fixed[g1] else (g2, g1)
        i = int(world.geom_agent[other])
        if i < 0:
            continue
        s = world.agent_setups[i]
        who = f"agent {world.names[i]} (placed at ({s.position[0]:.2f}, {s.position[1]:.2f}) m)"
        cx, cy = world.room.centre
        raise ConfigError(
            f"scene='playroom': {who} starts inside the room's {names[room][len('playroom/'):]!r}"
            f" ({100 * -c.dist[k]:.1f} cm deep); the room is centred at ({cx:.2f}, {cy:.2f}) m, "
            "its furniture along the walls 1.2-2 m from the centre: place the agents closer "
            "together (their position settings) or use scene='floor'")
