"""`free_play_v0`: the free play task as a PettingZoo env (see :mod:`.tasks.free_play` for the table).

``parallel_env(n_agents=..., task_options={...}, physics={...}, per_agent=[...], **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv`; ``env(...)`` the AEC version.
"""

from ..tasks.free_play import FreePlay
from ._factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "FreePlay"]


def parallel_env(**kwargs):
    return make_parallel(FreePlay, **kwargs)


def env(**kwargs):
    return make_aec(FreePlay, **kwargs)
