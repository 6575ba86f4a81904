"""``mimo_social.envs.single`` moved to ``mimo_social.core.gym_adapter`` when the package was laid out in layers
(docs/architecture.md). This alias keeps code written for the old path working, with a
DeprecationWarning; it will be removed in a later version."""

import warnings

from ..core.gym_adapter import SingleAgentEnv  # noqa: F401

__all__ = ["SingleAgentEnv"]

warnings.warn("mimo_social.envs.single moved to mimo_social.core.gym_adapter; import it from there (this alias will be "
              "removed)", DeprecationWarning, stacklevel=2)
