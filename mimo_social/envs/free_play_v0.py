# `free_play_v0`: the free play task (mimo_social.tasks.free_play) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.free_play import *  # noqa: F401,F403
from ..tasks.free_play import __all__, __doc__  # noqa: F401
