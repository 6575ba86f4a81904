"""Actuation models behind one interface (see :mod:`.base`)."""

from .base import Actuation
from .spring_damper import SpringDamper

MODELS = {"spring_damper": SpringDamper}

__all__ = ["Actuation", "SpringDamper", "MODELS"]
