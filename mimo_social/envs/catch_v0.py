# `catch_v0`: the catch task (mimo_social.tasks.catch) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.catch import *  # noqa: F401,F403
from ..tasks.catch import __all__, __doc__  # noqa: F401
