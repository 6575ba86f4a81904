"""`high_five_v0`: the high five task as a PettingZoo env (see :mod:`.tasks.high_five` for the table).

``parallel_env(n_agents=..., task_options={...}, physics={...}, per_agent=[...], **agent_settings)``
returns a :class:`~mimo_social.envs.parallel.MimoParallelEnv`; ``env(...)`` the AEC version.
"""

from ._factory import make_aec, make_parallel
from .tasks.high_five import HighFive

__all__ = ["parallel_env", "env", "HighFive"]


def parallel_env(**kwargs):
    return make_parallel(HighFive, **kwargs)


def env(**kwargs):
    return make_aec(HighFive, **kwargs)
