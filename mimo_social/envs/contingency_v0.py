"""`contingency_v0`: live, replayed and non-contingent caregivers as a PettingZoo env (see
:mod:`.tasks.contingency` for the table).

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns
a :class:`~mimo_social.core.env.MimoParallelEnv` with two learners (the caregiver ``infant_1``
an adult learner by default; condition "live" only); ``env(...)`` the AEC version;
``scripted_env(partner=None, stream=None, **kwargs)`` a one-learner env (``infant_0`` learns)
whose caregiver ``infant_1`` is driven by
:class:`~mimo_social.tasks.contingency.ContingencyCaregiver` (live, replay of the last live
episode or of ``stream``, non-contingent, as the task's condition says), or by ``partner``.
"""

from ..tasks.contingency import Contingency
from ._factory import make_aec, make_parallel, with_options

__all__ = ["parallel_env", "env", "scripted_env", "Contingency"]


def parallel_env(**kwargs):
    return make_parallel(Contingency, **kwargs)


def env(**kwargs):
    return make_aec(Contingency, **kwargs)


def scripted_env(partner=None, stream=None, **kwargs):
    from ..partners import ScriptedPartners
    from ..tasks.contingency import ContingencyCaregiver
    options = with_options(Contingency, kwargs.pop("task_options", None), scripted_partner=True)
    return ScriptedPartners(parallel_env(task_options=options, **kwargs),
                            {"infant_1": partner or ContingencyCaregiver(stream=stream)})
