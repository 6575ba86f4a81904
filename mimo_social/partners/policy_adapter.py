"""Any policy as a learner of the episode loop: :func:`as_learner`.

A paradigm's measures run a policy for seeded episodes (``act(env, agent, obs)``, optional
``reset(env, agent, rng)``, as :func:`mimo_social.core.episodes.run_episodes` takes it). Researchers
hand in a scripted partner, a function of the observation or a trained SB3 model;
:func:`as_learner` makes each of them such a policy, mapping the agent's observation and action
spaces onto the model's (as is, flat, or images channel-first) where they differ. Used by the
still-face and contingency measures (``measures.effects``).
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from ..core.wrappers import ActionDecoder, ImageDict, ObsFlattener, image_keys
from ..util.checks import show

__all__ = ["as_learner"]


def _shapes(space):
    """A space's shape, or a Dict's key -> shape."""
    parts = getattr(space, "spaces", None)
    return {k: _shapes(v) for k, v in parts.items()} if isinstance(parts, Mapping) \
        else space.shape


class _Model:
    """An SB3 model (``predict``) as a policy of the env's agent: the observation as the model
    takes it (as is, flat, or images channel-first with :class:`ImageDict`), its action mapped
    onto the agent's action space (as is, or :class:`ActionDecoder`'s flat layout)."""

    def __init__(self, model, deterministic: bool):
        self.model, self.deterministic = model, bool(deterministic)
        self.name = type(model).__name__

    def reset(self, env, agent, rng) -> None:
        seen, space = self.model.observation_space, env.observation_space(agent)
        self._observe = None
        if seen != space:
            keys = image_keys(space)
            if keys and keys[0] in getattr(seen, "spaces", {}):   # images channel-first
                stack = seen[keys[0]].shape[0] // max(1, space[keys[0]].shape[-1])
                self._observe = ImageDict(space, max(1, stack))
            else:
                self._observe = ObsFlattener(space)
            if _shapes(self._observe.space) != _shapes(seen):
                raise ValueError(f"as_learner: the model observes {_shapes(seen)}, {agent} gets "
                                 f"{_shapes(space)}; allowed: a model trained on this env's "
                                 "observation, as is, flat or with its images channel-first")
        acts, own = self.model.action_space, env.action_space(agent)
        self._decode = None if acts == own else ActionDecoder(own)
        if self._decode is not None and self._decode.space.shape != acts.shape:
            raise ValueError(f"as_learner: the model acts in {acts}, {agent} in {own}; allowed: "
                             f"a model acting in {own} or in {self._decode.space}")
        self._state, self._first = None, True
        if not self.deterministic and callable(getattr(self.model, "set_random_seed", None)):
            self.model.set_random_seed(int(rng.integers(2 ** 31)))

    def act(self, env, agent, obs):
        if self._observe is not None:
            obs = self._observe(obs, self._first) if isinstance(self._observe, ImageDict) \
                else self._observe(obs)
        action, self._state = self.model.predict(obs, state=self._state,
                                                 episode_start=np.array([self._first]),
                                                 deterministic=self.deterministic)
        self._first = False
        return action if self._decode is None else self._decode(action, agent)


class _Function:
    """A function of the observation that returns the agent's action."""

    def __init__(self, fn):
        self.fn, self.name = fn, getattr(fn, "__name__", type(fn).__name__)

    def act(self, env, agent, obs):
        return self.fn(obs)


def as_learner(policy, deterministic: bool = True):
    """``policy`` as a policy of the episode loop (``act(env, agent, obs)``, optional
    ``reset``): a scripted partner or any object with ``act`` as it is; an SB3 model (an object
    with ``predict``) acting on the agent's observation (``deterministic``: the mode of its
    action distribution, else sampled, seeded per episode), its observation and action mapped
    from the env's as the model needs; a function ``obs -> action`` (an action of the agent's
    action space)."""
    if callable(getattr(policy, "act", None)):
        return policy
    if callable(getattr(policy, "predict", None)):
        return _Model(policy, deterministic)
    if callable(policy):
        return _Function(policy)
    raise ValueError(f"policy={show(policy)} not allowed; allowed: an object with act(env, agent, "
                     "obs) (a scripted partner), an SB3 model (predict) or a function obs -> "
                     "action")
