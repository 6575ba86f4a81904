"""mimo_social: several MIMo infants in one MuJoCo world.

PettingZoo envs in :mod:`mimo_social.envs` (``free_play_v0``, ``high_five_v0``, ``mirror_v0``,
``joint_attention_v0``, ``social_touch_v0``, ``handover_v0`` and the one-agent ``reach_v0``,
``standup_v0``, ``selfbody_v0``, ``catch_v0``), scripted partners in
:mod:`mimo_social.partners`. Importing the package chooses a headless OpenGL backend when none is
set (see :mod:`mimo_social.rendering`) and registers the Gymnasium ids ``mimo_social/Reach-v0``,
``mimo_social/Standup-v0``, ``mimo_social/SelfBody-v0`` and ``mimo_social/Catch-v0``.
"""

from .rendering import choose_gl_backend as _choose_gl_backend

_choose_gl_backend()

from .envs.registration import register_envs as _register_envs  # noqa: E402

_register_envs()

__version__ = "0.1.0"
