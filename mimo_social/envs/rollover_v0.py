# `rollover_v0`: the rollover task (mimo_social.tasks.rollover) as a PettingZoo env, version 0;
# its docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.rollover import *  # noqa: F401,F403
from ..tasks.rollover import __all__, __doc__  # noqa: F401
