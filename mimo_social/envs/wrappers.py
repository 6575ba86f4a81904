"""``mimo_social.envs.wrappers`` moved to ``mimo_social.core.wrappers (make_sb3_single: mimo_social.train.envs)`` when the package was laid out in layers
(docs/architecture.md). This alias keeps code written for the old path working, with a
DeprecationWarning; it will be removed in a later version."""

import warnings

from ..core.wrappers import *  # noqa: F401,F403
from ..core.wrappers import __all__ as _core
from ..train.envs import make_sb3_single  # noqa: F401

__all__ = [*_core, "make_sb3_single"]

warnings.warn("mimo_social.envs.wrappers moved to mimo_social.core.wrappers; import it from there (this alias will be "
              "removed)", DeprecationWarning, stacklevel=2)
