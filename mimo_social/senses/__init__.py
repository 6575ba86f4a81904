"""The senses: each is built for one agent from the compiled world and reads MjData.

:data:`SENSES` is the registry the config parser and the env read (:mod:`.base` says what a
sense and a shared system are). A new sense is its file (the sense, its config dataclass and a
``SENSE = SenseEntry(...)``), one line below, and one field of the same name in
:class:`mimo_social.core.config.AgentConfig`.
"""

from . import audition, faces, proprioception, touch, vestibular, vision
from .audition import AuditionConfig
from .base import Sense, SenseEntry, SharedSystem
from .faces import FacesConfig
from .proprioception import Proprioception, ProprioceptionConfig
from .touch import TouchConfig
from .vestibular import Vestibular, VestibularConfig
from .vision import VisionConfig

#: sense name -> its entry, in the order the env builds them (and fills the observation)
SENSES: dict[str, SenseEntry] = {entry.name: entry for entry in (
    proprioception.SENSE,
    vestibular.SENSE,
    touch.SENSE,
    vision.SENSE,
    audition.SENSE,
    faces.SENSE,
)}

__all__ = ["SENSES", "Sense", "SenseEntry", "SharedSystem", "Proprioception", "Vestibular",
           "ProprioceptionConfig", "VestibularConfig", "TouchConfig", "VisionConfig",
           "AuditionConfig", "FacesConfig"]
