# `imitation_v0`: the imitation task (mimo_social.tasks.imitation) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.imitation import *  # noqa: F401,F403
from ..tasks.imitation import __all__, __doc__  # noqa: F401
