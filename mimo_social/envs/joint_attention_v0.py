# `joint_attention_v0`: the joint attention task (mimo_social.tasks.joint_attention) as a PettingZoo env, version 0; its
# docstring is the task's table. A new version of the task is a new module beside this one.
from ..tasks.joint_attention import *  # noqa: F401,F403
from ..tasks.joint_attention import __all__, __doc__  # noqa: F401
