# `turn_taking_v0`: the vocal turn-taking task (mimo_social.tasks.turn_taking) as a PettingZoo env,
# version 0; its docstring is the task's table. A new version of the task is a new module beside it.
from ..tasks.turn_taking import *  # noqa: F401,F403
from ..tasks.turn_taking import __all__, __doc__  # noqa: F401
