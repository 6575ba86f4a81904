"""Scripted controllers that solve the one-agent tasks: oracle baselines and demonstrations.

Each is a :class:`~mimo_social.partners.Partner` for the task's only agent: it may read the
world's state (where the ball is), but it moves the infant only through the agent's own action
space, exactly as a learner would (no ``qpos`` writes). The catalogue names each task's
controller (``entry.controller``); ``mimo-social baselines TASK`` measures it beside random,
zero-action and trained policies.
"""

from .catch import CatchController
from .reach import ReachController
from .selfbody import SelfBodyController
from .standup import StandupController

__all__ = ["CatchController", "ReachController", "SelfBodyController", "StandupController"]
