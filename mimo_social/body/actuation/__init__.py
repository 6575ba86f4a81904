"""Actuation models behind one interface (see :mod:`.base`): spring-damper, muscles, positional.

``MODELS`` maps the ``actuation=`` config value to the class; the env builds one object per agent.
"""

from .base import Actuation
from .muscle import Muscle
from .positional import Positional, positional_controls
from .spring_damper import SpringDamper

MODELS = {"spring_damper": SpringDamper, "muscle": Muscle, "positional": Positional}

__all__ = ["Actuation", "SpringDamper", "Muscle", "Positional", "positional_controls", "MODELS"]
