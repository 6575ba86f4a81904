"""Scripted controllers that solve the tasks: oracle baselines and demonstrations.

Each is a :class:`~mimo_social.partners.Partner` for the task's learner (the only agent of a
one-agent task; ``infant_0`` of a social task's scripted form, beside its scripted partner): it
may read the world's state (where the ball, the target part or the partner's hand is, which toy
the partner's eyes point at), but it moves the infant only through the agent's own action
space, exactly as a learner would (no ``qpos`` writes). The catalogue names each task's
controller (``entry.controller``); ``mimo-social baselines TASK`` measures it beside random,
zero-action and trained policies.
"""

from .catch import CatchController
from .contingency import ContingencyDetectorController
from .gaze_follow import GazeFollowController
from .high_five import HighFiveController
from .imitation import ImitationController
from .mirror import MirrorController
from .reach import ReachController
from .receive import ReceiveController
from .selfbody import SelfBodyController
from .standup import StandupController
from .still_face import StillFaceInfantController
from .touch import SocialTouchController

__all__ = ["CatchController", "GazeFollowController", "HighFiveController", "ImitationController",
           "MirrorController", "ReachController", "ReceiveController", "SelfBodyController",
           "SocialTouchController", "StandupController", "StillFaceInfantController",
           "ContingencyDetectorController"]
