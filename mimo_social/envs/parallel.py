"""``mimo_social.envs.parallel`` moved to ``mimo_social.core.env`` when the package was laid out in layers
(docs/architecture.md). This alias keeps code written for the old path working, with a
DeprecationWarning; it will be removed in a later version."""

import warnings

from ..core.env import *  # noqa: F401,F403
from ..core.env import __all__  # noqa: F401

warnings.warn("mimo_social.envs.parallel moved to mimo_social.core.env; import it from there (this alias will be "
              "removed)", DeprecationWarning, stacklevel=2)
