"""Actuation models behind one interface (see :mod:`.base`).

``MODELS`` maps the ``actuation=`` config value to the class; the env builds one object per agent.
"""

from .base import Actuation
from .muscle import Muscle
from .spring_damper import SpringDamper

MODELS = {"spring_damper": SpringDamper, "muscle": Muscle}

__all__ = ["Actuation", "SpringDamper", "Muscle", "MODELS"]
