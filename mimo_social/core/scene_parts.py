"""The parts of a World's scene that are not agents: the floor, the lights and the props, each
added to a model spec before it compiles (``Prop``: what a prop is)."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

__all__ = ["Prop", "add_floor", "add_lights", "add_prop"]


@dataclass(frozen=True)
class Prop:
    """A simple object in the scene (free to move unless ``fixed``)."""

    name: str
    shape: str = "sphere"            # sphere | box | capsule | cylinder
    size: tuple[float, ...] = (0.025,)
    pos: tuple[float, float, float] = (0.0, 0.0, 0.5)
    mass: float = 0.1
    rgba: tuple[float, float, float, float] = (0.9, 0.2, 0.2, 1.0)
    fixed: bool = False
    # bodies held to this prop by a weld equality, with their agent prefix
    # ("infant_0/right_hand"); each is held at its pose relative to the prop in the world's
    # initial pose, and :meth:`World.hold_welds` re-anchors them to the current one
    welds: tuple[str, ...] = ()


def add_floor(spec) -> None:
    """A checkered floor plane (10 m x 10 m) at z = 0."""
    tex = spec.add_texture(name="floor_checker", type=mujoco.mjtTexture.mjTEXTURE_2D,
                           builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER, width=256, height=256,
                           rgb1=[0.82, 0.78, 0.70], rgb2=[0.74, 0.70, 0.62])
    mat = spec.add_material(name="floor", texrepeat=[8, 8], reflectance=0.0)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = tex.name
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE,
                            size=[10, 10, 0.1], material="floor", condim=3)


def add_lights(spec) -> None:
    """Two directional lights without shadows and a soft headlight (the scene without a room)."""
    for pos, direction in (((0, -2, 3), (0, 0.5, -1)), ((2, 2, 3), (-0.5, -0.5, -1))):
        spec.worldbody.add_light(pos=pos, dir=direction, diffuse=[0.55, 0.55, 0.55],
                                 castshadow=False, type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
    spec.visual.headlight.diffuse = [0.25, 0.25, 0.25]


def add_prop(spec, p: Prop):
    """A prop's body (free unless ``fixed``), its geom and its welds; returns the body."""
    shapes = {"sphere": mujoco.mjtGeom.mjGEOM_SPHERE, "box": mujoco.mjtGeom.mjGEOM_BOX,
              "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
              "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER}
    if p.shape not in shapes:
        raise ValueError(f"prop {p.name}: shape {p.shape!r}; allowed: {list(shapes)}")
    body = spec.worldbody.add_body(name=p.name, pos=p.pos)
    if not p.fixed:
        body.add_freejoint(name=f"{p.name}_free")
    size = np.zeros(3)
    size[: len(p.size)] = p.size
    body.add_geom(name=p.name, type=shapes[p.shape], size=size, mass=p.mass, rgba=p.rgba,
                  condim=3)
    for other in p.welds:
        if spec.body(other) is None:
            raise ValueError(f"prop {p.name}: cannot weld unknown body {other!r}")
        eq = spec.add_equality(type=mujoco.mjtEq.mjEQ_WELD, objtype=mujoco.mjtObj.mjOBJ_BODY,
                               name=f"{p.name}__{other}", name1=other, name2=p.name)
        data = np.array(eq.data)
        data[:3] = 0.0  # the anchor: the prop's origin
        eq.data = data
    return body
