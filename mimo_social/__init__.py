"""mimo_social: several MIMo infants (and caregivers) in one MuJoCo world.

Importing the package chooses a headless OpenGL backend when none is set
(:mod:`mimo_social.render.gl`) and registers every Gymnasium id of the catalogue
(:mod:`mimo_social.envs.catalog`). The envs (PettingZoo module, Gymnasium id, kind):

"""

from .render.gl import choose_gl_backend as _choose_gl_backend

_choose_gl_backend()

from .envs.catalog import describe as _describe, register_envs as _register_envs  # noqa: E402

_register_envs()
if __doc__:  # None under python -OO
    __doc__ += _describe() + "\n"

__version__ = "0.1.0"
