# `reach_v0`: the reach task (mimo_social.tasks.reach) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.reach import *  # noqa: F401,F403
from ..tasks.reach import __all__, __doc__  # noqa: F401
