"""`reach_v0`: the reach task as a PettingZoo env (see :mod:`.tasks.reach` for the table).

``parallel_env(n_agents=..., task_options={...}, physics={...}, per_agent=[...], **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv`; ``env(...)`` the AEC version.
"""

from ..tasks.reach import Reach
from ._factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "Reach"]


def parallel_env(**kwargs):
    return make_parallel(Reach, **kwargs)


def env(**kwargs):
    return make_aec(Reach, **kwargs)
