"""mimo_social: several MIMo infants in one MuJoCo world.

Importing the package chooses a headless OpenGL backend when none is set (see
:mod:`mimo_social.rendering`) and registers the Gymnasium ids ``mimo_social/Reach-v0``.
"""

from .rendering import choose_gl_backend as _choose_gl_backend

_choose_gl_backend()

from .envs.registration import register_envs as _register_envs  # noqa: E402

_register_envs()

__version__ = "0.1.0"
