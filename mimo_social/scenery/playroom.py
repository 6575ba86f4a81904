"""The play room: a 4 x 4 m room with a soft foam mat, infant-scale furniture and toys.

:func:`add_playroom` puts it in an ``MjSpec`` around a centre (the world puts it where the
task's agents are: the middle of the room stays free for them). The layout is data
(:data:`LAYOUT`): furniture along the walls, toys on the shelf, the table and the mat.

* floor: oak boards at z = -``MAT_THICKNESS`` (a plane); the foam mat (a box, 3.2 x 3.2 m) lies
  on it, its top at z = 0, where the tasks' agents stand, sit or kneel. The mat is soft: its
  contacts mix its ``solref`` time constant (0.04 s) with the bodies' (0.005 s) and give under a
  load over a wider ``solimp`` range;
* walls 2.4 m high with wallpaper, a ceiling (drawn, not colliding), a window;
* furniture (:mod:`.furniture`): a crib with rails, a low table, a toy shelf and a sofa for the
  caregiver, all world-body geoms named ``playroom/<piece>/<part>``;
* toys (:mod:`.toys`): free bodies ``playroom/<toy>``; those on the mat lie 0.55-0.7 m to the
  side of the room's centre line (the line the tasks put their agents on), and any that would
  start within :data:`TOY_CLEARANCE` of an agent or a task's prop is put on its spare place on the
  furniture instead (:func:`mimo_social.scenery.clearance.clear_toys`).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from .furniture import PIECES, place, shelf_boards, table_top
from .meshes import add_box_mesh
from .textures import add_texture
from .toys import TOYS, add_toy, rest_height

__all__ = ["ROOM_HALF", "WALL_HEIGHT", "MAT_THICKNESS", "MAT_HALF", "LAYOUT", "ToySpot",
           "Room", "add_playroom", "TOY_CLEARANCE", "inside_camera"]

ROOM_HALF = 2.0          # m, from the centre to the inner face of each wall
WALL_HEIGHT = 2.4
WALL_THICKNESS = 0.1
MAT_THICKNESS = 0.02     # m: the mat's top is z = 0, the boards' floor z = -0.02
MAT_HALF = 1.6
#: contacts of the mat: soft foam (mixed with the other geom's own solref / solimp)
MAT_CONTACT = {"solref": [0.04, 1.0], "solimp": [0.85, 0.95, 0.006, 0.5, 2.0],
               "friction": [0.9, 0.005, 0.0001]}
#: contacts of the furniture: wood
FURNITURE_CONTACT = {"friction": [0.6, 0.005, 0.0001]}
#: a toy whose place on the mat comes closer than this (m, bounding spheres) to an agent or a
#: task's prop at the start goes to its spare place
TOY_CLEARANCE = 0.1

_SHELF_Y = ROOM_HALF - 0.17
_SHELF_X = 0.75
_TABLE = (ROOM_HALF - 0.42, 0.45)


@dataclass(frozen=True)
class ToySpot:
    """Where a toy starts: ``pos`` (x, y in the room's frame; z of the surface it rests on),
    its yaw, and a ``spare`` place (on furniture) when ``pos`` is taken."""

    toy: str
    pos: tuple[float, float, float]
    yaw: float = 0.0
    spare: tuple[float, float, float] | None = None


def _on_shelf(board: int, x: float) -> tuple[float, float, float]:
    return (_SHELF_X + x, _SHELF_Y - 0.01, shelf_boards()[board] - MAT_THICKNESS)


def _on_table(x: float, y: float) -> tuple[float, float, float]:
    return (_TABLE[0] + x, _TABLE[1] + y, table_top() - MAT_THICKNESS)


#: the room's contents: furniture (kind, x, y, yaw in degrees; the piece's front faces -y turned
#: by yaw) and toys (:class:`ToySpot`), in the room's frame (origin at the centre, on the mat)
LAYOUT = {
    "furniture": (
        ("crib", "crib", -0.85, ROOM_HALF - 0.40, 0.0),
        ("shelf", "shelf", _SHELF_X, _SHELF_Y, 0.0),
        ("window", "window", _SHELF_X, ROOM_HALF, 0.0),
        ("table", "low_table", *_TABLE, 90.0),
        ("sofa", "sofa", -ROOM_HALF + 0.44, -1.15, -90.0),
    ),
    "toys": (
        ToySpot("ball_red", (0.05, 0.62, 0.0), spare=_on_shelf(0, -0.3)),
        ToySpot("block_green", (-0.30, -0.60, 0.0), 20.0, spare=_on_shelf(1, -0.35)),
        ToySpot("teddy", (0.35, -0.68, 0.0), 120.0, spare=(-0.85, ROOM_HALF - 0.40, 0.37 - MAT_THICKNESS)),
        ToySpot("rattle", (-0.35, 0.66, 0.0), -30.0, spare=_on_table(-0.1, 0.2)),
        ToySpot("block_red", _on_shelf(1, -0.2)),
        ToySpot("block_yellow", _on_shelf(1, 0.25)),
        ToySpot("ball_blue", _on_shelf(2, 0.3)),
        ToySpot("block_blue", _on_table(-0.1, 0.05), 15.0),
        ToySpot("cup", _on_table(0.05, -0.2)),
    ),
}


@dataclass(frozen=True)
class Room:
    """What :func:`add_playroom` put in the spec: the room's centre (world x, y), its toys'
    body names, each toy's spare position (world), and the names of the furniture's geoms."""

    centre: tuple[float, float]
    toys: tuple[str, ...]
    spares: dict
    furniture: tuple[str, ...]


def _materials(spec) -> dict[str, str]:
    repeat = {"wood_boards": (0.8, 0.8), "foam_mat": (0.8, 0.8), "wallpaper": (2.0, 2.0),
              "wood_light": (3.0, 3.0), "wood_white": (3.0, 3.0), "wood_red": (3.0, 3.0),
              "fabric_blue": (6.0, 6.0), "fabric_sage": (6.0, 6.0)}
    return {name: add_texture(spec, name, repeat=r) for name, r in repeat.items()}


def add_playroom(spec: mujoco.MjSpec, centre=(0.0, 0.0), sleep: bool = False,
                 layout: dict = LAYOUT) -> Room:
    """Put the play room in ``spec`` with its centre at world ``centre`` (x, y); ``sleep``:
    its toys may sleep while they rest (the caller turns ``mjENBL_SLEEP`` on)."""
    cx, cy = float(centre[0]), float(centre[1])
    mats = _materials(spec)
    wb = spec.worldbody
    floor_z = -MAT_THICKNESS
    mat = wb.add_geom(name="playroom/mat", type=mujoco.mjtGeom.mjGEOM_BOX,
                      pos=[cx, cy, -MAT_THICKNESS / 2],
                      size=[MAT_HALF, MAT_HALF, MAT_THICKNESS / 2], material=mats["foam_mat"])
    for k, v in MAT_CONTACT.items():
        setattr(mat, k, v)
    furniture = []
    for name, kind, x, y, yaw in layout["furniture"]:
        furniture += place(spec, name, PIECES[kind](), (cx + x, cy + y, floor_z), yaw, mats,
                           FURNITURE_CONTACT)
    _add_shell(spec, (cx, cy), mats)
    toys, spares = [], {}
    for spot in layout["toys"]:
        toy = TOYS[spot.toy]
        z = spot.pos[2] + rest_height(toy) + 0.001
        body = add_toy(spec, toy, (cx + spot.pos[0], cy + spot.pos[1], z), spot.yaw, sleep)
        toys.append(body)
        if spot.spare is not None:
            sx, sy, sz = spot.spare
            spares[body] = (cx + sx, cy + sy, sz + rest_height(toy) + 0.001)
    _add_lights(spec, (cx, cy))
    return Room((cx, cy), tuple(toys), spares, tuple(furniture))


def _add_shell(spec, centre, mats) -> None:
    """The boards' floor, the walls (drawn as one mesh, colliding as four invisible boxes)
    and the ceiling (drawn only)."""
    wb = spec.worldbody
    cx, cy = centre
    floor_z = -MAT_THICKNESS
    wb.add_geom(name="playroom/floor", type=mujoco.mjtGeom.mjGEOM_PLANE,
                pos=[cx, cy, floor_z], size=[ROOM_HALF, ROOM_HALF, 0.1],
                material=mats["wood_boards"], condim=3)
    h, t = WALL_HEIGHT / 2, WALL_THICKNESS / 2
    L = ROOM_HALF + WALL_THICKNESS
    boxes = []
    for name, pos, size in (("north", (0, ROOM_HALF + t), (L, t)),
                            ("south", (0, -ROOM_HALF - t), (L, t)),
                            ("east", (ROOM_HALF + t, 0), (t, L)),
                            ("west", (-ROOM_HALF - t, 0), (t, L))):
        centre = (cx + pos[0], cy + pos[1], floor_z + h)
        wb.add_geom(name=f"playroom/wall_{name}", type=mujoco.mjtGeom.mjGEOM_BOX,
                    pos=list(centre), size=[size[0], size[1], h], group=3)
        boxes.append((centre, np.eye(3), (size[0], size[1], h)))
    add_box_mesh(spec, "playroom/walls", boxes, material=mats["wallpaper"])
    # lit from below by nothing but the ambient light: a little emission keeps it white
    spec.add_material(name="playroom/ceiling", rgba=[0.98, 0.97, 0.94, 1.0], emission=0.35,
                      specular=0.0)
    ceiling = wb.add_geom(name="playroom/ceiling", type=mujoco.mjtGeom.mjGEOM_BOX,
                          pos=[cx, cy, floor_z + WALL_HEIGHT + t], size=[L, L, t],
                          material="playroom/ceiling")
    ceiling.contype = ceiling.conaffinity = 0


def _add_lights(spec, centre) -> None:
    """Two directional lights from the window's side and from above, as the floor scene has
    (directional lights keep the eyes' renderer cheap: no per-vertex falloff), and a brighter
    ambient light: the walls are lit from every side."""
    for direction, diffuse in (((0.3, -0.5, -1.0), 0.50), ((-0.4, 0.2, -1.0), 0.40)):
        spec.worldbody.add_light(pos=[centre[0], centre[1], WALL_HEIGHT - 0.1], dir=direction,
                                 diffuse=[diffuse, diffuse * 0.97, diffuse * 0.92],
                                 castshadow=False, type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
    spec.visual.headlight.ambient = [0.42, 0.42, 0.42]
    # the free cameras (the env's scene camera) stand inside the room, closer to the agents
    # than on the floor: a wider view (vertical, degrees; MuJoCo's default 45)
    spec.visual.global_.fovy = 55.0
    spec.visual.headlight.diffuse = [0.22, 0.22, 0.22]


def inside_camera(room_centre, lookat, distance: float, azimuth: float, elevation: float,
                  margin: float = 0.25) -> float:
    """The largest distance (at most ``distance``) at which a free camera looking at
    ``lookat`` from ``azimuth`` / ``elevation`` (degrees, MuJoCo's convention) stays inside the
    room, ``margin`` from the walls and the ceiling."""
    az, el = np.deg2rad(azimuth), np.deg2rad(elevation)
    back = -np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    lim = ROOM_HALF - margin
    best = distance
    for k in range(2):
        if abs(back[k]) > 1e-9:
            wall = room_centre[k] + np.sign(back[k]) * lim
            best = min(best, (wall - lookat[k]) / back[k])
    if back[2] > 1e-9:
        best = min(best, (WALL_HEIGHT - MAT_THICKNESS - margin - lookat[2]) / back[2])
    return float(max(best, 0.3))
