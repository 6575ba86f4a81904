"""`high_five_v0`: the high five task as a PettingZoo env (see :mod:`.tasks.high_five` for the table).

``parallel_env(n_agents=..., task_options={...}, physics={...}, per_agent=[...], **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv`; ``env(...)`` the AEC version;
``scripted_env(partner=None, **kwargs)`` a one-learner env (``infant_0`` learns) whose partner
``infant_1`` is driven by a scripted :class:`~mimo_social.partners.Partner` (by default one that
offers its right hand: :func:`default_partner`).

Every agent has the touch sense on its right hand by default (the skin that senses the high
five); ``touch=True`` gives the whole skin, ``touch=hand_touch(density=...)`` the right hand at
another density.
"""

from ..tasks import high_five as _task
from ..tasks.high_five import HighFive, hand_touch
from ._factory import make_aec, make_parallel

__doc__ = (__doc__ or "") + "\nThe task:\n" + (_task.__doc__ or "")

__all__ = ["parallel_env", "env", "scripted_env", "default_partner", "HighFive", "hand_touch"]


def parallel_env(**kwargs):
    return make_parallel(HighFive, **kwargs)


def env(**kwargs):
    return make_aec(HighFive, **kwargs)


def default_partner():
    """The scripted partner of :func:`scripted_env`: ``HandOffer(grip=False, release=None)``,
    which brings its right hand to an offer position in front of its body, fingers open, and
    holds it there."""
    from ..partners.hand_offer import HandOffer
    return HandOffer(grip=False, release=None)


def scripted_env(partner=None, **kwargs):
    from ..partners import ScriptedPartners
    return ScriptedPartners(parallel_env(**kwargs),
                            {"infant_1": partner if partner is not None else default_partner()})
