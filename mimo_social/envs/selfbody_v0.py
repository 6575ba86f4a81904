# `selfbody_v0`: the selfbody task (mimo_social.tasks.selfbody) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.selfbody import *  # noqa: F401,F403
from ..tasks.selfbody import __all__, __doc__  # noqa: F401
