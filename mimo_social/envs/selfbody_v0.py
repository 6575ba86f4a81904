"""`selfbody_v0`: the selfbody task as a one-agent PettingZoo env (see :mod:`.tasks.selfbody` for the table).

``parallel_env(task_options={...}, physics={...}, max_steps=..., render_mode=..., **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv` with the one agent ``infant_0``;
``env(...)`` the AEC version. The Gymnasium id is ``mimo_social/SelfBody-v0``.
"""

from ..tasks import selfbody as _task
from ..tasks.selfbody import SelfBody
from ._factory import make_aec, make_parallel

__doc__ = (__doc__ or "") + "\nThe task:\n" + (_task.__doc__ or "")

__all__ = ["parallel_env", "env", "SelfBody"]


def parallel_env(**kwargs):
    return make_parallel(SelfBody, **kwargs)


def env(**kwargs):
    return make_aec(SelfBody, **kwargs)
