"""Flat (Box) views of the environments, for learners that want one array in and one array out.

``FlattenParallel(env)``
    A PettingZoo ``ParallelEnv`` around any ParallelEnv of this package. Each agent's observation
    becomes one float32 ``Box``: the entries of its ``Dict`` observation flattened and concatenated
    in the order of the ``Dict`` space (``proprioception`` then ``vestibular`` ...), eye images
    (``uint8``) scaled to [0, 1]. Each agent's action becomes one float32 ``Box``:

    * motors only (``expressions=False``): the motor ``Box`` itself, ``[-1, 1]^n``;
    * a face-only agent (no motors, e.g. the mirror task's learner): ``Discrete(7)``, the
      expression id;
    * with expressions: ``n`` motor values followed by 7 expression *logits* in ``[-1, 1]``; the
      expression played is ``argmax(logits)`` (ties go to the lowest id, so "neutral" wins when
      all logits are equal, e.g. all clipped to the same bound).

    Spaces are built once: ``observation_space(agent)`` / ``action_space(agent)`` return the same
    object every call. ``reset(seed=...)`` passes the seed to the wrapped env; ``render``,
    ``close``, ``state`` and ``state_space`` are the wrapped env's, other public attributes are
    looked up on it. The wrapper pickles (the wrapped env drops its renderer when pickled).

``FlatObservationWrapper`` / ``FlatActionWrapper`` / ``ExpressionActionWrapper``
    The same flat observations and actions for a Gymnasium env (one agent);
    :func:`mimo_social.train.envs.make_sb3_single` puts them around an env for SB3.
"""

from __future__ import annotations

from typing import Any, Mapping

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

__all__ = ["ParallelWrapper", "FlattenParallel", "FlatActionWrapper", "FlatObservationWrapper",
           "ExpressionActionWrapper", "is_expression_only", "flat_action_space",
           "flat_observation_space"]

LOGIT_LOW, LOGIT_HIGH = -1.0, 1.0


# -- observations -------------------------------------------------------------------------------
class _ObsFlattener:
    """Turns one agent's observation (a ``Dict``, a ``Box`` or another space) into a float32 vector.

    Images (``uint8`` Boxes, e.g. the eyes) are scaled to [0, 1]: learners' networks expect
    inputs of order one, and raw 0-255 pixels saturate their first layer.
    """

    def __init__(self, space: spaces.Space):
        self.source = space
        if isinstance(space, spaces.Dict):
            self.parts = list(space.spaces.items())
        else:
            self.parts = [(None, space)]
        lows, highs = [], []
        self._scale = []
        for _, sub in self.parts:
            flat = spaces.flatten_space(sub)
            if not isinstance(flat, spaces.Box):
                raise TypeError(f"cannot flatten observation space {sub} to a Box")
            image = isinstance(sub, spaces.Box) and sub.dtype == np.uint8
            scale = np.float32(1.0 / 255.0) if image else None
            self._scale.append(scale)
            lo = np.asarray(flat.low, dtype=np.float32).ravel()
            hi = np.asarray(flat.high, dtype=np.float32).ravel()
            lows.append(lo * scale if image else lo)
            highs.append(hi * scale if image else hi)
        self.space = spaces.Box(np.concatenate(lows), np.concatenate(highs), dtype=np.float32)
        self._box = [isinstance(sub, spaces.Box) for _, sub in self.parts]

    def __call__(self, obs) -> np.ndarray:
        chunks = []
        for (key, sub), is_box, scale in zip(self.parts, self._box, self._scale):
            value = obs if key is None else obs[key]
            if is_box:
                v = np.asarray(value, dtype=np.float32).ravel()
                chunks.append(v * scale if scale is not None else v)
            else:
                chunks.append(np.asarray(spaces.flatten(sub, value), dtype=np.float32).ravel())
        return np.concatenate(chunks)


class FlatObservationWrapper(gym.ObservationWrapper):
    """A Gymnasium env's observation as the float32 Box of :class:`FlattenParallel` (the parts
    of a ``Dict`` in order, images scaled to [0, 1])."""

    def __init__(self, env: gym.Env):
        super().__init__(env)
        self._flatten = _ObsFlattener(env.observation_space)
        self.observation_space = self._flatten.space

    def observation(self, observation):
        return self._flatten(observation)


def flat_observation_space(space: spaces.Space) -> spaces.Box:
    """The float32 ``Box`` that :class:`FlattenParallel` gives for an observation space."""
    return _ObsFlattener(space).space


# -- actions ------------------------------------------------------------------------------------
class _ActionDecoder:
    """Maps a flat float32 action onto an agent's action space of this package.

    Supported: a ``Box`` (returned reshaped), or ``Dict({"motors": Box, "expression": Discrete})``
    (the Box holds the motors then one logit per expression; with no motors at all, the action
    is the ``Discrete`` expression id itself).
    """

    def __init__(self, space: spaces.Space):
        self.source = space
        self.discrete = is_expression_only(space)
        if self.discrete:  # a face-only agent: its action is the expression id itself
            expression = space["expression"]
            self.n_motors, self.n_expressions = 0, int(expression.n)
            self.expression_start = int(expression.start)
            self._motors = np.zeros(space["motors"].shape, space["motors"].dtype)
            self.space = spaces.Discrete(expression.n, start=expression.start)
            return
        if isinstance(space, spaces.Box):
            self.n_motors = int(np.prod(space.shape))
            self.n_expressions = 0
            self.motor_shape = space.shape
            low, high = space.low.ravel(), space.high.ravel()
        elif (isinstance(space, spaces.Dict) and set(space.spaces) == {"motors", "expression"}
              and isinstance(space["motors"], spaces.Box)
              and isinstance(space["expression"], spaces.Discrete)):
            motors, expression = space["motors"], space["expression"]
            self.n_motors = int(np.prod(motors.shape))
            self.n_expressions = int(expression.n)
            self.expression_start = int(expression.start)
            self.motor_shape = motors.shape
            low = np.concatenate([motors.low.ravel(),
                                  np.full(self.n_expressions, LOGIT_LOW)])
            high = np.concatenate([motors.high.ravel(),
                                   np.full(self.n_expressions, LOGIT_HIGH)])
        else:
            raise TypeError(f"cannot flatten action space {space}; supported: a Box of motors, or "
                            "Dict(motors=Box, expression=Discrete)")
        self.space = spaces.Box(np.asarray(low, np.float32), np.asarray(high, np.float32),
                                dtype=np.float32)

    def __call__(self, action, who: str = "agent"):
        if self.discrete:
            e = np.asarray(action)
            if e.size != 1 or not np.isfinite(e).all():
                raise ValueError(f"{who}: a face-only agent's action is one expression id, got "
                                 f"{action!r}")
            return {"motors": self._motors, "expression": np.int64(int(e.ravel()[0]))}
        a = np.asarray(action, dtype=np.float32)
        if a.shape != self.space.shape:
            layout = (f"{self.n_motors} motors + {self.n_expressions} expression logits"
                      if self.n_expressions else f"{self.n_motors} motors")
            raise ValueError(f"{who}: flat action has shape {a.shape}; expected "
                             f"{self.space.shape} ({layout})")
        motors = a[:self.n_motors].reshape(self.motor_shape)
        if not self.n_expressions:
            return motors
        logits = a[self.n_motors:]
        if not np.isfinite(logits).all():
            raise ValueError(f"{who}: expression logits must be finite, got {logits}")
        return {"motors": motors,
                "expression": np.int64(self.expression_start + int(np.argmax(logits)))}


def flat_action_space(space: spaces.Space) -> spaces.Space:
    """The float32 ``Box`` (``Discrete`` for a face-only agent) that :class:`FlattenParallel`
    accepts for an action space."""
    return _ActionDecoder(space).space


# -- the PettingZoo wrapper ---------------------------------------------------------------------
class ParallelWrapper(ParallelEnv):
    """Base of this package's ParallelEnv wrappers: holds ``env``, and passes ``unwrapped``,
    ``metadata``, ``render_mode``, ``render``, ``close``, ``state``, ``state_space`` and every
    other public attribute it does not define itself on to it."""

    def __init__(self, env: ParallelEnv):
        if not isinstance(env, ParallelEnv):
            raise TypeError(f"{type(self).__name__} wraps a pettingzoo ParallelEnv, got "
                            f"{type(env).__name__}")
        self.env = env
        self.metadata = dict(getattr(env, "metadata", {}))
        self.render_mode = getattr(env, "render_mode", None)

    @property
    def unwrapped(self):
        return self.env.unwrapped

    def render(self):
        return self.env.render()

    def close(self):
        return self.env.close()

    def state(self):
        return self.env.state()

    def state_space(self, *args, **kwargs):
        space = self.env.state_space
        return space(*args, **kwargs) if callable(space) else space

    def __getattr__(self, name: str):
        # only public names, and never before __init__/__setstate__ has set ``env`` (pickling)
        env = self.__dict__.get("env")
        if env is None or name.startswith("_"):
            raise AttributeError(f"{type(self).__name__} has no attribute {name!r}")
        return getattr(env, name)

    def __str__(self):
        return f"{type(self).__name__}<{self.env}>"


class FlattenParallel(ParallelWrapper):
    """Box observations and Box actions for every agent of a ParallelEnv (see module docstring)."""

    def __init__(self, env: ParallelEnv):
        super().__init__(env)
        self.possible_agents = list(env.possible_agents)
        self._obs = {a: _ObsFlattener(env.observation_space(a)) for a in self.possible_agents}
        self._act = {a: _ActionDecoder(env.action_space(a)) for a in self.possible_agents}
        self._obs_spaces = {a: f.space for a, f in self._obs.items()}
        self._act_spaces = {a: d.space for a, d in self._act.items()}

    # the live agents are always the wrapped env's
    @property
    def agents(self):
        return self.env.agents

    def observation_space(self, agent):
        try:
            return self._obs_spaces[agent]
        except KeyError:
            raise KeyError(f"unknown agent {agent!r}; agents of this env: "
                           f"{self.possible_agents}") from None

    def action_space(self, agent):
        try:
            return self._act_spaces[agent]
        except KeyError:
            raise KeyError(f"unknown agent {agent!r}; agents of this env: "
                           f"{self.possible_agents}") from None

    def _flat_obs(self, obs: Mapping[str, Any]) -> dict:
        return {a: (self._obs[a](o) if a in self._obs else o) for a, o in obs.items()}

    def reset(self, seed: int | None = None, options: dict | None = None):
        obs, infos = self.env.reset(seed=seed, options=options)
        return self._flat_obs(obs), infos

    def step(self, actions: Mapping[str, Any]):
        if not isinstance(actions, Mapping):
            raise ValueError(f"actions must be a dict agent -> action, got {type(actions).__name__}")
        # unknown agents are passed on untouched: the wrapped env names them in its error
        decoded = {a: (self._act[a](act, a) if a in self._act else act)
                   for a, act in actions.items()}
        obs, rewards, terminations, truncations, infos = self.env.step(decoded)
        return self._flat_obs(obs), rewards, terminations, truncations, infos


# -- the Gymnasium side -------------------------------------------------------------------------
class FlatActionWrapper(gym.ActionWrapper):
    """A Gymnasium env with a ``Dict(motors, expression)`` action takes the flat Box instead."""

    def __init__(self, env: gym.Env):
        super().__init__(env)
        self._decoder = _ActionDecoder(env.action_space)
        self.action_space = self._decoder.space

    def action(self, action):
        return self._decoder(action, "action")


class ExpressionActionWrapper(gym.ActionWrapper):
    """An agent whose only action is its face (``Dict(motors=Box((0,)), expression=Discrete(7))``,
    e.g. the mirror task's learner) takes the expression id itself: a ``Discrete(7)`` action,
    which PPO / A2C learn as a categorical choice (better than argmax over Box logits)."""

    def __init__(self, env: gym.Env):
        super().__init__(env)
        space = env.action_space
        if not is_expression_only(space):
            raise TypeError(f"ExpressionActionWrapper needs Dict(motors=Box of size 0, "
                            f"expression=Discrete), got {space}")
        self._motors = np.zeros(space["motors"].shape, space["motors"].dtype)
        self.action_space = spaces.Discrete(space["expression"].n, start=space["expression"].start)

    def action(self, action):
        return {"motors": self._motors, "expression": int(action)}


def is_expression_only(space: spaces.Space) -> bool:
    """True for ``Dict(motors=Box with no values, expression=Discrete)``."""
    return (isinstance(space, spaces.Dict) and set(space.spaces) == {"motors", "expression"}
            and isinstance(space["motors"], spaces.Box) and space["motors"].shape
            and int(np.prod(space["motors"].shape)) == 0
            and isinstance(space["expression"], spaces.Discrete))
