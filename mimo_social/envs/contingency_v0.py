# `contingency_v0`: the contingency task (mimo_social.tasks.contingency) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.contingency import *  # noqa: F401,F403
from ..tasks.contingency import __all__, __doc__  # noqa: F401
