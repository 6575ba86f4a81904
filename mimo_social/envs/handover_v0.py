"""`handover_v0`: the handover task as a PettingZoo env (see :mod:`.tasks.handover` for the table).

``parallel_env(n_agents=2, task_options={...}, physics={...}, per_agent=[...], **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv`; ``env(...)`` the AEC version;
``scripted_env(partner=None, **kwargs)`` a one-learner env: the receiver ``infant_0`` learns and
the giver ``infant_1`` is the task's scripted giver (:func:`~mimo_social.tasks.handover.scripted_giver`:
a :class:`~mimo_social.partners.hand_offer.HandOffer` offering at the ``offer_target`` task
option that tips the ball into the receiver's open hand and lets go only once that hand carries
it) unless another partner is given.
"""

from ..tasks.handover import Handover, scripted_giver
from ._factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "scripted_env", "Handover", "scripted_giver"]


def parallel_env(**kwargs):
    return make_parallel(Handover, **kwargs)


def env(**kwargs):
    return make_aec(Handover, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ..partners import ScriptedPartners
    penv = parallel_env(**kwargs)
    if partner is None:
        partner = scripted_giver(penv.task.options)
    return ScriptedPartners(penv, {"infant_1": partner})
