# `high_five_v0`: the high five task (mimo_social.tasks.high_five) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.high_five import *  # noqa: F401,F403
from ..tasks.high_five import __all__, __doc__  # noqa: F401
