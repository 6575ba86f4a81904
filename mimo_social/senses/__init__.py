"""The senses: each is built for one agent from the compiled world and reads MjData."""

from .proprioception import Proprioception
from .vestibular import Vestibular

__all__ = ["Proprioception", "Vestibular"]
