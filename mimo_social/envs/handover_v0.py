# `handover_v0`: the handover task (mimo_social.tasks.handover) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.handover import *  # noqa: F401,F403
from ..tasks.handover import __all__, __doc__  # noqa: F401
