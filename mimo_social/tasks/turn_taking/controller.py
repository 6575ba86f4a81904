"""``TurnTakingInfantController``: the scripted infant of the turn-taking paradigm.

reads:
    each step, from the world: whether the caregiver's sound (``env.sounds``, as the last step
    left it) is not silence; nothing else
acts:
    through its own ``"voice"`` and ``"loudness"`` (0.5): the rule of
    :class:`~mimo_social.tasks.turn_taking.infant.VocalInfant` (a base rate of vocalising, a
    pause for an answer after each vocalisation, silence while the caregiver speaks; answers
    within ``window_s`` raise its rate and its share of babble over coo, unanswered ones let
    them decay to the base values); its head and eye motors (if any) rest
expected pattern:
    more vocalisations per minute and a larger share of speech-like ones (babble) with the
    contingent caregiver than with the non-contingent or replayed one (the task's table)

It writes no state; its randomness comes from the generator given at reset.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from ...partners.base import Partner, agent_index, zero_action
from .infant import VocalInfant

__all__ = ["TurnTakingInfantController"]


class TurnTakingInfantController(Partner):
    """A vocalising infant that learns from answers (see the module docstring); keyword
    settings are :class:`VocalInfant`'s (``dt`` comes from the env); ``loudness`` in [0, 1]."""

    def __init__(self, loudness: float = 0.5, **rule):
        from ...util.checks import check_number
        self.loudness = check_number("TurnTakingInfantController", "loudness", loudness, 0, 1)
        self.rule = VocalInfant(**rule)
        self._action = None

    def __repr__(self):
        return f"TurnTakingInfantController({self.rule!r})"

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        space = env.action_space(agent)
        if not (isinstance(space, spaces.Dict) and "voice" in space.spaces):
            raise ValueError(f"TurnTakingInfantController acts through the voice, but {agent}'s "
                             f"action space has none ({space}); build the env with voice=True")
        me = agent_index(env, agent)
        self._other = 1 - me if len(env.possible_agents) == 2 else None
        if self._other is None:
            raise ValueError("TurnTakingInfantController: needs a pair (infant and caregiver)")
        self._action = zero_action(space)
        self._loud = np.array([self.loudness], np.float32)
        self.rule.reset(rng, float(env.dt))

    def act(self, env, agent, observation):
        if self._action is None:
            raise RuntimeError("TurnTakingInfantController.act() before reset(); reset the "
                               "env first")
        kind = self.rule.step(bool(env.sounds[self._other, 0] != 0))
        action = dict(self._action)
        action["voice"] = np.int64(kind)
        action["loudness"] = self._loud.copy()
        return action
