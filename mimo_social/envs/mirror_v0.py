# `mirror_v0`: the mirror task (mimo_social.tasks.mirror) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.mirror import *  # noqa: F401,F403
from ..tasks.mirror import __all__, __doc__  # noqa: F401
