"""`imitation_v0`: imitation of actions as a PettingZoo env (see :mod:`.tasks.imitation`).

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns
a :class:`~mimo_social.core.env.MimoParallelEnv` with two learners (``infant_1`` demonstrates
the action of its ``instruction``, ``infant_0`` reproduces it); ``env(...)`` the AEC version;
``scripted_env(partner=None, **kwargs)`` a one-learner env (``infant_0`` learns) whose
demonstrator ``infant_1`` (the kneeling adult caregiver by default) is driven by a scripted
:class:`~mimo_social.partners.Partner`, by default
:class:`~mimo_social.partners.demonstrator.Demonstrator` (the task option ``scripted_partner``
is set: the demonstrator has no eyes and no reward).
"""

from ..tasks.imitation import Imitation
from ._factory import make_aec, make_parallel, with_options

__all__ = ["parallel_env", "env", "scripted_env", "Imitation"]


def parallel_env(**kwargs):
    return make_parallel(Imitation, **kwargs)


def env(**kwargs):
    return make_aec(Imitation, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ..partners import ScriptedPartners
    from ..partners.demonstrator import Demonstrator
    options = with_options(Imitation, kwargs.pop("task_options", None), scripted_partner=True)
    return ScriptedPartners(parallel_env(task_options=options, **kwargs),
                            {"infant_1": partner if partner is not None else Demonstrator()})
