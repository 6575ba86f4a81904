# `standup_v0`: the standup task (mimo_social.tasks.standup) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.standup import *  # noqa: F401,F403
from ..tasks.standup import __all__, __doc__  # noqa: F401
