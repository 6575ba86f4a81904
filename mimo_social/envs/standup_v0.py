"""`standup_v0`: the standup task as a one-agent PettingZoo env (see :mod:`.tasks.standup` for the table).

``parallel_env(task_options={...}, physics={...}, max_steps=..., render_mode=..., **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv` with the one agent ``infant_0``;
``env(...)`` the AEC version. The Gymnasium id is ``mimo_social/Standup-v0``.
"""

from ..tasks import standup as _task
from ..tasks.standup import Standup
from ._factory import make_aec, make_parallel

__doc__ = (__doc__ or "") + "\nThe task:\n" + (_task.__doc__ or "")

__all__ = ["parallel_env", "env", "Standup"]


def parallel_env(**kwargs):
    return make_parallel(Standup, **kwargs)


def env(**kwargs):
    return make_aec(Standup, **kwargs)
