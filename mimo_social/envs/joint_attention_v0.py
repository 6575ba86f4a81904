"""`joint_attention_v0`: gaze following as a PettingZoo env (see :mod:`.tasks.joint_attention`).

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns
a :class:`~mimo_social.core.env.MimoParallelEnv` with two learners (both see, both get the
shared reward); ``env(...)`` the AEC version; ``scripted_env(partner=None, **kwargs)`` a
one-learner env (``infant_0`` learns) whose partner ``infant_1`` is driven by a scripted
:class:`~mimo_social.partners.Partner`, by default
:class:`~mimo_social.partners.gaze.GazeAtTarget` looking at the toys (the task option
``scripted_partner`` is set: the partner has no eyes and no reward).
"""

from ..tasks.joint_attention import JointAttention
from ._factory import make_aec, make_parallel, with_options

__all__ = ["parallel_env", "env", "scripted_env", "JointAttention"]


def parallel_env(**kwargs):
    return make_parallel(JointAttention, **kwargs)


def env(**kwargs):
    return make_aec(JointAttention, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ..partners import ScriptedPartners
    from ..partners.gaze import GazeAtTarget
    options = with_options(JointAttention, kwargs.pop("task_options", None), scripted_partner=True)
    return ScriptedPartners(parallel_env(task_options=options, **kwargs),
                            {"infant_1": partner or GazeAtTarget()})
