"""``mimo_social.envs.vector`` moved to ``mimo_social.train.vector`` when the package was laid out in layers
(docs/architecture.md). This alias keeps code written for the old path working, with a
DeprecationWarning; it will be removed in a later version."""

import warnings

from ..train.vector import *  # noqa: F401,F403
from ..train.vector import __all__  # noqa: F401

warnings.warn("mimo_social.envs.vector moved to mimo_social.train.vector; import it from there (this alias will be "
              "removed)", DeprecationWarning, stacklevel=2)
