"""``mimo_social.replay`` moved to ``mimo_social.recording`` when the package was laid out in layers
(docs/architecture.md). This alias keeps code written for the old path working, with a
DeprecationWarning; it will be removed in a later version."""

import warnings

from .recording import *  # noqa: F401,F403
from .recording import __all__  # noqa: F401

warnings.warn("mimo_social.replay moved to mimo_social.recording; import it from there (this alias will be "
              "removed)", DeprecationWarning, stacklevel=2)
