"""Scripted partners: reusable policies that act for an agent through its action space, and
:class:`ScriptedPartners`, the ParallelEnv wrapper that leaves only the learners."""

from .base import Partner, Still, zero_action
from .contingent import ContingentCaregiver
from .cues import Cues, learner_cues
from .expression import ExpressionShow
from .gaze import GazeAtTarget
from .hand_offer import HandOffer
from .replay import ReplayCaregiver, load_stream, save_stream
from .wrapper import ScriptedPartners

__all__ = ["Partner", "Still", "zero_action", "ScriptedPartners", "ExpressionShow",
           "GazeAtTarget", "HandOffer", "ContingentCaregiver", "Cues", "learner_cues",
           "ReplayCaregiver", "load_stream", "save_stream"]
