# `still_face_v0`: the still face task (mimo_social.tasks.still_face) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.still_face import *  # noqa: F401,F403
from ..tasks.still_face import __all__, __doc__  # noqa: F401
