# `social_touch_v0`: the social touch task (mimo_social.tasks.social_touch) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.social_touch import *  # noqa: F401,F403
from ..tasks.social_touch import __all__, __doc__  # noqa: F401
