"""`social_touch_v0`: the social touch task as a PettingZoo env (see :mod:`.tasks.social_touch`).

``parallel_env(task_options={...}, physics={...}, per_agent=[...], **agent_settings)`` returns a
:class:`~mimo_social.core.env.MimoParallelEnv` with the toucher ``infant_0`` and the touched
infant ``infant_1`` (both learners); ``env(...)`` the AEC version; ``scripted_env(partner=None,
**kwargs)`` a one-learner env in which ``infant_0`` learns to touch and ``infant_1`` is driven by
a scripted :class:`~mimo_social.partners.Partner` (default :class:`~mimo_social.partners.Still`:
it sits still and feels).

The toucher's skin covers its right arm by default, the touched infant's its whole body;
``touch=...`` (all agents) or ``per_agent=[{...}, {"touch": ...}]`` change that, as long as the
toucher's right hand and the touched infant's target parts keep their skin.
"""

from ..tasks import social_touch as _task
from ..tasks.social_touch import DEFAULT_TARGETS, SocialTouch
from ._factory import make_aec, make_parallel

__doc__ = (__doc__ or "") + "\nThe task:\n" + (_task.__doc__ or "")

__all__ = ["parallel_env", "env", "scripted_env", "SocialTouch", "DEFAULT_TARGETS"]


def parallel_env(**kwargs):
    return make_parallel(SocialTouch, **kwargs)


def env(**kwargs):
    return make_aec(SocialTouch, **kwargs)


def scripted_env(partner=None, **kwargs):
    from ..partners import ScriptedPartners, Still
    return ScriptedPartners(parallel_env(**kwargs),
                            {"infant_1": partner if partner is not None else Still()})
