"""`mirror_v0`: facial mimicry as a PettingZoo env (see :mod:`.tasks.mirror` for the table).

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns
a :class:`~mimo_social.core.env.MimoParallelEnv` with two learners (both see, both are
rewarded for matching); ``env(...)`` the AEC version; ``scripted_env(partner=None, **kwargs)``
a one-learner env (``infant_0`` learns) whose partner ``infant_1`` is driven by a scripted
:class:`~mimo_social.partners.Partner`, by default
:class:`~mimo_social.partners.expression.ExpressionShow` (the task option ``scripted_partner``
is set: the partner has no eyes and no reward).
"""

from ..tasks.mirror import Mirror
from ._factory import make_aec, make_parallel, with_options

__all__ = ["parallel_env", "env", "scripted_env", "Mirror"]


def parallel_env(**kwargs):
    return make_parallel(Mirror, **kwargs)


def env(**kwargs):
    return make_aec(Mirror, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ..partners import ScriptedPartners
    from ..partners.expression import ExpressionShow
    options = with_options(Mirror, kwargs.pop("task_options", None), scripted_partner=True)
    return ScriptedPartners(parallel_env(task_options=options, **kwargs),
                            {"infant_1": partner or ExpressionShow()})
