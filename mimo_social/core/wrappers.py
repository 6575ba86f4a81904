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
      all logits are equal, e.g. all clipped to the same bound);
    * with the voice on: then 6 voice logits in ``[-1, 1]`` (``argmax``: the sound, ties to
      "silence") and the loudness in ``[0, 1]`` (clipped to it).

    Motor values beyond the Box are clipped to it in float64 (a finite 1e39 is 1, not inf);
    an action that is not numbers (a string, a ragged list, a dict, None, bools), NaN/inf
    expression logits or a face-only agent's expression that is not one integer raise a
    ValueError naming the agent, the field, the value and what is allowed.

    Spaces are built once: ``observation_space(agent)`` / ``action_space(agent)`` return the same
    object every call. ``reset(seed=...)`` passes the seed to the wrapped env; ``render``,
    ``close``, ``state`` and ``state_space`` are the wrapped env's, other public attributes are
    looked up on it. The wrapper pickles (the wrapped env drops its renderer when pickled).

``NumericInfos(env)``
    Every agent's infos as the same fixed set of float numbers at reset and at every step (the
    keys the env, its senses and its task declare in ``info_spec``): what TorchRL's
    ``PettingZooWrapper`` needs to turn infos into tensors.

``FlatObservationWrapper`` / ``FlatActionWrapper`` / ``ExpressionActionWrapper``
    The same flat observations and actions for a Gymnasium env (one agent);
    :func:`mimo_social.train.envs.make_sb3_single` puts them around an env for SB3.

``DictObservationWrapper(env, frame_stack=1)``
    For a Gymnasium env whose ``Dict`` observation holds images (the eyes): each image key stays
    a ``uint8`` image, channel-first ``(C * frame_stack, H, W)`` (what SB3's
    ``MultiInputPolicy`` takes as an image without transposing it), the last ``frame_stack``
    frames stacked along the channels, oldest first (``reset`` fills them with its frame); every
    other key, nested dicts included, becomes ONE float32 Box ``"vector"`` (the
    :class:`ObsFlattener` of those keys; left out when it has no entries).
"""

from __future__ import annotations

from typing import Any, Mapping

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from .action_decoder import (LOGIT_HIGH, LOGIT_LOW, ActionDecoder, flat_action_space,
                             is_expression_only, is_voice_only)
from .infos import INFO_KINDS, InfoEncoder
from ..util.names import reject_old_names

__all__ = ["ParallelWrapper", "FlattenParallel", "NumericInfos", "INFO_KINDS", "FlatActionWrapper",
           "FlatObservationWrapper", "ExpressionActionWrapper", "is_expression_only",
           "flat_action_space", "flat_observation_space", "ObsFlattener", "ActionDecoder",
           "DictObservationWrapper", "ImageDict", "image_keys", "is_image_box", "VECTOR_KEY",
           "is_voice_only", "LOGIT_LOW", "LOGIT_HIGH"]



# -- observations -------------------------------------------------------------------------------
class ObsFlattener:
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
        empty = np.zeros(0, np.float32)   # an agent that observes nothing (an empty Dict)
        self.space = spaces.Box(np.concatenate(lows or [empty]),
                                np.concatenate(highs or [empty]), dtype=np.float32)
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
        return np.concatenate(chunks) if chunks else np.zeros(0, np.float32)


class FlatObservationWrapper(gym.ObservationWrapper):
    """A Gymnasium env's observation as the float32 Box of :class:`FlattenParallel` (the parts
    of a ``Dict`` in order, images scaled to [0, 1])."""

    def __init__(self, env: gym.Env):
        super().__init__(env)
        self._flatten = ObsFlattener(env.observation_space)
        self.observation_space = self._flatten.space

    def observation(self, observation):
        return self._flatten(observation)


def flat_observation_space(space: spaces.Space) -> spaces.Box:
    """The float32 ``Box`` that :class:`FlattenParallel` gives for an observation space."""
    return ObsFlattener(space).space


#: the key of :class:`DictObservationWrapper`'s observation that holds every non-image part
VECTOR_KEY = "vector"


def is_image_box(space: spaces.Space) -> bool:
    """True for a ``uint8`` Box of bounds 0..255 shaped ``(H, W)`` or ``(H, W, C)``, C in 1..4
    (what the eyes give: ``(H, W, 3)``)."""
    if not (isinstance(space, spaces.Box) and space.dtype == np.uint8):
        return False
    shape = space.shape
    if not (len(shape) == 2 or (len(shape) == 3 and 1 <= shape[2] <= 4)) or min(shape) < 1:
        return False
    return bool(np.all(space.low == 0) and np.all(space.high == 255))


def image_keys(space: spaces.Space) -> tuple[str, ...]:
    """The top-level keys of a ``Dict`` observation space that hold images
    (:func:`is_image_box`); ``()`` for any other space."""
    if not isinstance(space, spaces.Dict):
        return ()
    return tuple(k for k, sub in space.spaces.items() if is_image_box(sub))


class ImageDict:
    """One agent's ``Dict`` observation with images as the ``Dict`` SB3's ``MultiInputPolicy``
    takes (see the module docstring): image keys channel-first ``uint8`` ``(C * frame_stack,
    H, W)``, the rest one float32 Box under :data:`VECTOR_KEY`; ``space`` is that Dict.
    ``self(obs, first)``: the observation (``first``: an episode's first, which fills every
    stacked slot with its frame; later ones drop the oldest frame, the newest goes last).

    ``frame_stack`` (>= 1): how many frames of each image key are stacked along the channels,
    oldest first. ``C * frame_stack`` may not exceed ``min(H, W)``: SB3 takes the smallest axis
    of an image for its channels.
    """

    def __init__(self, space: spaces.Space, frame_stack: int = 1):
        self.image_keys = image_keys(space)
        if not self.image_keys:
            raise TypeError(f"an image Dict needs a Dict observation with an image "
                            f"(a uint8 Box (H, W) or (H, W, C<=4), bounds 0..255), got {space}")
        if (isinstance(frame_stack, bool) or not isinstance(frame_stack, (int, np.integer))
                or frame_stack < 1):
            raise ValueError(f"frame_stack = {frame_stack!r} not allowed; allowed: an integer "
                             ">= 1 (1: no stacking)")
        self.frame_stack = k = int(frame_stack)
        out: dict[str, spaces.Space] = {}
        self._channels: dict[str, int] = {}
        for key in self.image_keys:
            shape = space[key].shape
            h, w = shape[:2]
            c = shape[2] if len(shape) == 3 else 1
            if c * k > min(h, w):
                raise ValueError(f"frame_stack = {k} not allowed for image {key!r} of shape "
                                 f"{shape}: {c} x {k} channels exceed its smaller side "
                                 f"{min(h, w)}; allowed: frame_stack <= {min(h, w) // c}")
            self._channels[key] = c
            out[key] = spaces.Box(0, 255, (c * k, h, w), np.uint8)
        rest = {key: sub for key, sub in space.spaces.items() if key not in self._channels}
        self._vector = ObsFlattener(spaces.Dict(rest)) if rest else None
        if self._vector is not None and self._vector.space.shape[0] > 0:
            if VECTOR_KEY in out:
                raise ValueError(f"an image key is named {VECTOR_KEY!r}, the key of the "
                                 "non-image parts")
            out[VECTOR_KEY] = self._vector.space
        else:
            self._vector = None
        self.space = spaces.Dict(out)
        self._frames = {key: np.zeros(out[key].shape, np.uint8) for key in self.image_keys}

    def __call__(self, obs: Mapping[str, Any], first: bool) -> dict[str, np.ndarray]:
        out = {}
        for key, c in self._channels.items():
            img = np.asarray(obs[key], dtype=np.uint8)
            chw = img.transpose(2, 0, 1) if img.ndim == 3 else img[None]
            frames = self._frames[key]
            if first:
                frames.reshape(self.frame_stack, *chw.shape)[:] = chw
            else:  # drop the oldest frame, the newest goes last
                frames[:-c] = frames[c:]
                frames[-c:] = chw
            out[key] = frames.copy()
        if self._vector is not None:
            out[VECTOR_KEY] = self._vector(obs)
        return out


class DictObservationWrapper(gym.Wrapper):
    """A Gymnasium env's ``Dict`` observation with images as :class:`ImageDict` gives it (the
    ``Dict`` SB3's ``MultiInputPolicy`` takes), ``frame_stack`` frames of each image."""

    def __init__(self, env: gym.Env, frame_stack: int = 1):
        super().__init__(env)
        self._images = ImageDict(env.observation_space, frame_stack)
        self.image_keys = self._images.image_keys
        self.frame_stack = self._images.frame_stack
        self.observation_space = self._images.space

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        obs, info = self.env.reset(seed=seed, options=options)
        return self._images(obs, True), info

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        return self._images(obs, False), reward, terminated, truncated, info


# -- actions ------------------------------------------------------------------------------------
# -- the PettingZoo wrapper ---------------------------------------------------------------------
class ParallelWrapper(ParallelEnv):
    """Base of this package's ParallelEnv wrappers: holds ``env``, and passes ``unwrapped``,
    ``metadata``, ``render_mode``, the live ``agents``, the spaces, ``render``, ``close``,
    ``state``, ``state_space`` and every other public attribute it does not define itself on to
    it."""

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

    # the live agents and the spaces are the wrapped env's unless a wrapper changes them
    @property
    def agents(self):
        return self.env.agents

    def observation_space(self, agent):
        return self.env.observation_space(agent)

    def action_space(self, agent):
        return self.env.action_space(agent)

    def render(self, *args):
        # RLlib's ParallelPettingZooEnv passes a mode (see MimoParallelEnv.render)
        return self.env.render(*args)

    def close(self):
        return self.env.close()

    def state(self):
        return self.env.state()

    @property
    def state_space(self):
        return self.env.state_space

    def __getattr__(self, name: str):
        # only public names, and never before __init__/__setstate__ has set ``env`` (pickling)
        env = self.__dict__.get("env")
        if env is None or name.startswith("_"):
            raise AttributeError(f"{type(self).__name__} has no attribute {name!r}")
        return getattr(env, name)

    def __str__(self):
        return f"{type(self).__name__}<{self.env}>"


class FlattenParallel(ParallelWrapper):
    """Box observations and Box actions for every agent of a ParallelEnv (see module docstring).

    ``keep_images``: an agent whose observation has images gets the :class:`ImageDict` of it
    instead (images channel-first, ``frame_stack`` frames, the rest one flat ``"vector"``: what
    SB3's ``MultiInputPolicy`` takes); agents without images keep the flat Box."""

    def __init__(self, env: ParallelEnv, keep_images: bool = False, frame_stack: int = 1):
        super().__init__(env)
        self.possible_agents = list(env.possible_agents)
        self._obs = {a: (ImageDict(env.observation_space(a), frame_stack)
                         if keep_images and image_keys(env.observation_space(a))
                         else ObsFlattener(env.observation_space(a)))
                     for a in self.possible_agents}
        self._act = {a: ActionDecoder(env.action_space(a)) for a in self.possible_agents}
        self._obs_spaces = {a: f.space for a, f in self._obs.items()}
        self._act_spaces = {a: d.space for a, d in self._act.items()}

    def observation_space(self, agent):
        try:
            return self._obs_spaces[agent]
        except KeyError:
            reject_old_names(agent, self.possible_agents)
            raise KeyError(f"unknown agent {agent!r}; agents of this env: "
                           f"{self.possible_agents}") from None

    def action_space(self, agent):
        try:
            return self._act_spaces[agent]
        except KeyError:
            reject_old_names(agent, self.possible_agents)
            raise KeyError(f"unknown agent {agent!r}; agents of this env: "
                           f"{self.possible_agents}") from None

    def _flat_obs(self, obs: Mapping[str, Any], first: bool = False) -> dict:
        out = {}
        for a, o in obs.items():
            f = self._obs.get(a)
            out[a] = o if f is None else f(o, first) if isinstance(f, ImageDict) else f(o)
        return out

    def reset(self, seed: int | None = None, options: dict | None = None):
        obs, infos = self.env.reset(seed=seed, options=options)
        return self._flat_obs(obs, first=True), infos

    def step(self, actions: Mapping[str, Any]):
        if not isinstance(actions, Mapping):
            raise ValueError(f"actions must be a dict agent -> action, got {type(actions).__name__}")
        # unknown agents are passed on untouched: the wrapped env names them in its error
        decoded = {a: (self._act[a](act, a) if a in self._act else act)
                   for a, act in actions.items()}
        obs, rewards, terminations, truncations, infos = self.env.step(decoded)
        return self._flat_obs(obs), rewards, terminations, truncations, infos


# -- numeric infos ------------------------------------------------------------------------------
#: the kinds of info value an ``info_spec`` names (besides a tuple of strings and a nested dict)
class NumericInfos(ParallelWrapper):
    """Every agent's infos as one fixed set of float numbers: the same keys at reset and at every
    step, for clients that turn infos into tensors (TorchRL's ``PettingZooWrapper``).

    The envs of this package give such infos by default (:mod:`mimo_social.core.infos`); this
    wrapper encodes their text infos itself, with its own options: it turns the wrapped env's
    text infos on (``env.unwrapped.info_text = True``). The keys are declared up front by the
    wrapped env's ``info_spec(agent)`` (the env's, its senses' and its task's, see
    :meth:`mimo_social.core.env.MimoParallelEnv.info_spec`) and ``extra`` (key -> kind, e.g.
    ``{"partner_rewards": {"infant_1": "number"}}``); the kinds and their numbers:
    :class:`mimo_social.core.infos.InfoEncoder`.

    A declared key missing from an info (task keys at reset) reads ``missing`` (default 0).
    Keys nobody declared are dropped; with ``strict=True`` they, and strings not in their tuple,
    raise a ValueError naming the agent and the key (what the tests use to keep specs right).
    ``info_keys(agent)``: the keys, in order. Observations, actions, rewards and ends are the
    wrapped env's, untouched.
    """

    def __init__(self, env: ParallelEnv, extra: Mapping[str, Any] | None = None,
                 missing: float = 0.0, strict: bool = False):
        super().__init__(env)
        spec_of = getattr(env, "info_spec", None)
        if spec_of is None:
            raise TypeError(f"NumericInfos needs an env with info_spec(agent) (the envs of this "
                            f"package have one), got {type(env).__name__}")
        self.possible_agents = list(env.possible_agents)
        self._encoder = InfoEncoder({a: {**spec_of(a), **dict(extra or {})}
                                     for a in self.possible_agents}, missing, strict)
        self.missing, self.strict = self._encoder.missing, self._encoder.strict
        if getattr(env.unwrapped, "info_text", True) is False:
            env.unwrapped.info_text = True   # encoded here, with this wrapper's options

    def info_keys(self, agent) -> tuple[str, ...]:
        """The keys of ``agent``'s numeric infos, in order."""
        try:
            return self._encoder.keys(agent)
        except KeyError:
            reject_old_names(agent, self.possible_agents)
            raise KeyError(f"unknown agent {agent!r}; agents of this env: "
                           f"{self.possible_agents}") from None

    def _encode(self, agent: str, info: Mapping[str, Any]) -> dict[str, float]:
        return self._encoder.encode(agent, info)

    def reset(self, seed: int | None = None, options: dict | None = None):
        obs, infos = self.env.reset(seed=seed, options=options)
        return obs, self._encoder.encode_all(infos)

    def step(self, actions: Mapping[str, Any]):
        obs, rewards, terminations, truncations, infos = self.env.step(actions)
        return obs, rewards, terminations, truncations, self._encoder.encode_all(infos)


# -- the Gymnasium side -------------------------------------------------------------------------
class FlatActionWrapper(gym.ActionWrapper):
    """A Gymnasium env with a ``Dict(motors, expression)`` action takes the flat Box instead."""

    def __init__(self, env: gym.Env):
        super().__init__(env)
        self._decoder = ActionDecoder(env.action_space)
        self.action_space = self._decoder.space
        self._who = str(getattr(env.unwrapped, "agent", "agent"))   # named in errors

    def action(self, action):
        return self._decoder(action, self._who)


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


