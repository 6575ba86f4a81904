"""`high_five_v0`: the high five task as a PettingZoo env (see :mod:`.tasks.high_five` for the table).

``parallel_env(n_agents=..., task_options={...}, physics={...}, per_agent=[...], **agent_settings)``
returns a :class:`~mimo_social.envs.parallel.MimoParallelEnv`; ``env(...)`` the AEC version;
``scripted_env(partner=None, **kwargs)`` a one-learner env (``infant_0`` learns) whose partner
``infant_1`` is driven by a scripted :class:`~mimo_social.partners.Partner`.
"""

from ._factory import make_aec, make_parallel
from .tasks.high_five import HighFive

__all__ = ["parallel_env", "env", "scripted_env", "HighFive"]


def parallel_env(**kwargs):
    return make_parallel(HighFive, **kwargs)


def env(**kwargs):
    return make_aec(HighFive, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ..partners import ScriptedPartners, Still
    return ScriptedPartners(parallel_env(**kwargs), {"infant_1": partner or Still()})
