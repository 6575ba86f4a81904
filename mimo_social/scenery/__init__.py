"""Scenes the world can be built in besides the bare floor: the play room (``scene="playroom"``).

:mod:`.textures` draws the room's textures with numpy, :mod:`.furniture` and :mod:`.toys` hold
the furniture and the toys as data, and :mod:`.playroom` puts them in an ``MjSpec``
(:func:`~.playroom.add_playroom`). docs/playroom.md describes the room.
"""

from .playroom import LAYOUT, Room, add_playroom, clear_toys, inside_camera

__all__ = ["SCENES", "LAYOUT", "Room", "add_playroom", "clear_toys", "inside_camera"]

#: the scenes a world can be built in (``scene=`` of the envs): the bare floor (default) and the
#: play room
SCENES = ("floor", "playroom")
