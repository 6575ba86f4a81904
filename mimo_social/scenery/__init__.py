"""Scenes the world can be built in besides the bare floor: the play room (``scene="playroom"``).

:mod:`.textures` draws the room's textures with numpy, :mod:`.furniture` and :mod:`.toys` hold
the furniture and the toys as data, and :mod:`.playroom` puts them in an ``MjSpec``
(:func:`~.playroom.add_playroom`). docs/playroom.md describes the room.
"""

from .clearance import check_scene_clear, clear_toys
from .playroom import LAYOUT, Room, add_playroom, inside_camera

__all__ = ["SCENES", "LAYOUT", "Room", "add_playroom", "clear_toys", "check_scene_clear",
           "inside_camera"]

#: the scenes a world can be built in (``scene=`` of the envs): the bare floor (default) and the
#: play room
SCENES = ("floor", "playroom")
