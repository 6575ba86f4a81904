"""Furniture of the play room at infant scale, as lists of boxes (data), and their placement.

Each piece is drawn in its own frame: origin on the floor at the middle of its footprint, x
along its width, y from its back (+y) to its front (-y), z up. :func:`place` turns it by a yaw
and puts every part into the world body as a geom ``playroom/<piece>/<part>``: furniture does
not move. A part is ``contact`` (it collides: what a body or a toy rests on or bumps into) or
visual only; a visual part that many small ones make (crib slats) is backed by one invisible
contact panel, so a crib side costs the collision detector one box, not fifteen. :func:`place`
draws every piece as one mesh per material (:mod:`.meshes`) and makes its colliding parts
invisible boxes (group 3: neither drawn by the eyes nor recorded).

Sizes (half sizes in the parts below; sources for typical dimensions):

* crib: 1.40 x 0.76 m outside, rails 0.95 m high, mattress top 0.37 m, slats 8.5 cm apart
  (full-size cribs take a 132 x 71 cm mattress; slat gaps must be under 6 cm, 16 CFR 1219);
* low table: 0.70 x 0.50 m top, 0.45 m high (toddler tables are 40-50 cm high);
* shelf: 1.10 x 0.32 m, 0.85 m high, three boards (a low toy shelf a toddler reaches into);
* sofa for the caregiver: 1.60 x 0.85 m, seat 0.43 m high, back 0.85 m.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from .meshes import add_box_mesh

__all__ = ["Part", "crib", "low_table", "shelf", "sofa", "window", "PIECES", "place",
           "shelf_boards", "table_top"]


@dataclass(frozen=True)
class Part:
    """One box of a piece: centre and half sizes (m) in the piece's frame."""

    name: str
    centre: tuple[float, float, float]
    half: tuple[float, float, float]
    material: str
    contact: bool = True
    visible: bool = True
    rgba: tuple[float, float, float, float] | None = None


def crib(material="wood_white", mattress="fabric_sage") -> list[Part]:
    w, d, h = 0.70, 0.38, 0.95          # half width, half depth, rail height
    post, base, top = 0.03, 0.25, 0.93
    parts = [Part(f"post_{i}", (sx * (w - post), sy * (d - post), h / 2), (post, post, h / 2),
                  material) for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1)))]
    for side, (cx, cy, hx, hy) in {"front": (0, -d + post, w - 2 * post, 0.015),
                                   "back": (0, d - post, w - 2 * post, 0.015),
                                   "left": (-w + post, 0, 0.015, d - 2 * post),
                                   "right": (w - post, 0, 0.015, d - 2 * post)}.items():
        parts.append(Part(f"{side}_top", (cx, cy, top), (hx, hy, 0.02), material))
        parts.append(Part(f"{side}_bottom", (cx, cy, base), (hx, hy, 0.03), material,
                          contact=False))
        # the slats: drawn, not colliding; one invisible panel collides for them
        length = 2 * (hx if hx > hy else hy)
        n = int(length / 0.085)
        for k in range(n):
            t = -length / 2 + (k + 0.5) * length / n
            c = (cx + t, cy) if hx > hy else (cx, cy + t)
            parts.append(Part(f"{side}_slat_{k}", (*c, (top + base) / 2), (0.011, 0.011,
                              (top - base) / 2), material, contact=False))
        parts.append(Part(f"{side}_panel", (cx, cy, (top + base) / 2),
                          (hx, hy, (top - base) / 2), material, visible=False))
    parts.append(Part("mattress", (0, 0, 0.31), (w - 2 * post, d - 2 * post, 0.06), mattress))
    return parts


def table_top(height=0.45) -> float:
    """The height of the low table's top surface (m)."""
    return height


def low_table(material="wood_light", legs="wood_red", height=0.45) -> list[Part]:
    w, d, t = 0.35, 0.25, 0.015
    parts = [Part("top", (0, 0, height - t), (w, d, t), material)]
    for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
        parts.append(Part(f"leg_{i}", (sx * (w - 0.04), sy * (d - 0.04), (height - 2 * t) / 2),
                          (0.02, 0.02, (height - 2 * t) / 2), legs))
    return parts


#: heights (m) of the shelf's boards' top surfaces
SHELF_BOARDS = (0.07, 0.36, 0.62, 0.85)


def shelf_boards() -> tuple[float, ...]:
    return SHELF_BOARDS


def shelf(material="wood_light", back="wood_white") -> list[Part]:
    w, d, t = 0.55, 0.16, 0.012
    top = SHELF_BOARDS[-1]
    parts = [Part("left", (-w + t, 0, top / 2), (t, d, top / 2), material),
             Part("right", (w - t, 0, top / 2), (t, d, top / 2), material),
             Part("back", (0, d - 0.006, top / 2), (w - 2 * t, 0.006, top / 2), back)]
    for k, z in enumerate(SHELF_BOARDS):
        parts.append(Part(f"board_{k}", (0, 0, z - t), (w - 2 * t, d, t), material))
    parts.append(Part("divider", (0, 0, (SHELF_BOARDS[0] + SHELF_BOARDS[1]) / 2),
                      (t, d, (SHELF_BOARDS[1] - SHELF_BOARDS[0]) / 2 - t), material))
    return parts


def sofa(material="fabric_blue", feet="wood_light") -> list[Part]:
    w, d = 0.80, 0.425
    parts = [Part("base", (0, 0, 0.22), (w, d, 0.12), material),
             Part("seat", (0, -0.05, 0.385), (w - 0.16, d - 0.07, 0.05), material),
             Part("back", (0, d - 0.1, 0.58), (w, 0.1, 0.27), material),
             Part("arm_left", (-w + 0.08, 0, 0.46), (0.08, d, 0.12), material),
             Part("arm_right", (w - 0.08, 0, 0.46), (0.08, d, 0.12), material)]
    for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
        parts.append(Part(f"foot_{i}", (sx * (w - 0.06), sy * (d - 0.06), 0.05),
                          (0.03, 0.03, 0.05), feet, contact=False))
    return parts


def window(width=1.0, height=0.9, sill=1.0) -> list[Part]:
    """A window on a wall (visual only): a white frame round a pale sky-blue pane, its back
    against the wall at y = 0, facing -y."""
    w, h, f = width / 2, height / 2, 0.04
    z = sill + h
    frame = "wood_white"
    return [Part("pane", (0, -0.005, z), (w, 0.005, h), frame, contact=False,
                 rgba=(0.70, 0.86, 0.98, 1.0)),
            Part("frame_top", (0, -0.02, z + h), (w + f, 0.02, f), frame, contact=False),
            Part("frame_bottom", (0, -0.03, z - h), (w + f, 0.03, f), frame, contact=False),
            Part("frame_left", (-w, -0.02, z), (f, 0.02, h), frame, contact=False),
            Part("frame_right", (w, -0.02, z), (f, 0.02, h), frame, contact=False),
            Part("frame_mid", (0, -0.015, z), (0.015, 0.015, h), frame, contact=False)]


#: kind -> the function drawing that piece
PIECES = {"crib": crib, "low_table": low_table, "shelf": shelf, "sofa": sofa, "window": window}


def _yaw_rot(yaw_deg: float) -> np.ndarray:
    c, s = np.cos(np.deg2rad(yaw_deg)), np.sin(np.deg2rad(yaw_deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def place(spec: mujoco.MjSpec, name: str, parts: list[Part], origin, yaw_deg: float,
          materials: dict[str, str], contact: dict) -> list[str]:
    """A piece in the world body at ``origin`` (x, y, z of the piece's frame) turned by
    ``yaw_deg`` about z: its visible parts merged into one mesh per material
    (``playroom/<name>/<material>``, :mod:`.meshes`: one geom for the eyes to draw, not
    dozens), its colliding parts as invisible boxes ``playroom/<name>/<part>`` (group 3) with
    the geom attributes ``contact`` (friction, solref ...). ``materials``: texture name ->
    material name. Returns the geom names."""
    R = _yaw_rot(yaw_deg)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, R.ravel())
    names, visible = [], {}
    for p in parts:
        centre = np.asarray(origin, float) + R @ np.asarray(p.centre, float)
        if p.contact:
            g = spec.worldbody.add_geom(name=f"playroom/{name}/{p.name}",
                                        type=mujoco.mjtGeom.mjGEOM_BOX, size=list(p.half),
                                        pos=list(centre), quat=list(quat), group=3)
            for k, v in contact.items():
                setattr(g, k, v)
            names.append(g.name)
        if p.visible:
            key = p.material if p.rgba is None else tuple(p.rgba)
            visible.setdefault(key, []).append((centre, R, p.half))
    for k, (key, boxes) in enumerate(visible.items()):
        plain = isinstance(key, tuple)
        g = add_box_mesh(spec, f"playroom/{name}/{f'colour_{k}' if plain else key}", boxes,
                         material=None if plain else materials[key],
                         rgba=key if plain else None)
        names.append(g.name)
    return names
