"""`catch_v0`: the catch task as a one-agent PettingZoo env (see :mod:`.tasks.catch` for the table).

``parallel_env(task_options={...}, physics={...}, max_steps=..., render_mode=..., **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv` with the one agent ``infant_0``;
``env(...)`` the AEC version. The Gymnasium id is ``mimo_social/Catch-v0``.
"""

from ..tasks import catch as _task
from ..tasks.catch import Catch
from ._factory import make_aec, make_parallel

__doc__ = (__doc__ or "") + "\nThe task:\n" + (_task.__doc__ or "")

__all__ = ["parallel_env", "env", "Catch"]


def parallel_env(**kwargs):
    return make_parallel(Catch, **kwargs)


def env(**kwargs):
    return make_aec(Catch, **kwargs)
