"""Flat actions: what a learner's network outputs, mapped onto an agent's action space.

:class:`ActionDecoder` maps a flat float32 ``Box`` action (the motors, then one logit per
expression, one per sound kind and the loudness) onto an agent's ``Box`` or ``Dict`` action, and
back (:meth:`ActionDecoder.encode`, for cloning a controller); a face-only agent takes its
expression id (``Discrete``), a voice-only agent its sound id (``Discrete``, at
:data:`VOICE_ONLY_LOUDNESS`).
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from ..util.checks import number_array

__all__ = ["ActionDecoder", "LOGIT_LOW", "LOGIT_HIGH", "VOICE_ONLY_LOUDNESS",
           "is_expression_only", "is_voice_only", "flat_action_space"]

LOGIT_LOW, LOGIT_HIGH = -1.0, 1.0
#: the loudness of a voice-only agent's sounds (the middle of each kind's range; the scripted
#: turn-taking infant's)
VOICE_ONLY_LOUDNESS = 0.5


def _is_dict_action(space: spaces.Space) -> bool:
    """A Dict action of this package: motors (a Box), an expression (Discrete) and / or a voice
    (Discrete) with its loudness (a Box of one value)."""
    if not isinstance(space, spaces.Dict) or not isinstance(space.spaces.get("motors"),
                                                            spaces.Box):
        return False
    keys = set(space.spaces)
    voice = {"voice", "loudness"} <= keys
    if keys - {"motors", "expression", "voice", "loudness"} or keys == {"motors"} or (
            ("voice" in keys or "loudness" in keys) and not voice):
        return False
    return (("expression" not in keys or isinstance(space["expression"], spaces.Discrete))
            and (not voice or (isinstance(space["voice"], spaces.Discrete)
                               and isinstance(space["loudness"], spaces.Box)
                               and space["loudness"].shape == (1,))))


def is_expression_only(space: spaces.Space) -> bool:
    """True for ``Dict(motors=Box with no values, expression=Discrete)``."""
    return (isinstance(space, spaces.Dict) and set(space.spaces) == {"motors", "expression"}
            and isinstance(space["motors"], spaces.Box) and space["motors"].shape
            and int(np.prod(space["motors"].shape)) == 0
            and isinstance(space["expression"], spaces.Discrete))


def _one_id(action, who: str, field: str, what: str, first: int, n: int, agent: str):
    """``action`` as one integer id of ``n`` from ``first`` (np.int64), else a ValueError naming
    the agent, the field, the value and what is allowed."""
    allowed = f"one {what} id, an integer {first}..{first + n - 1}"
    v = _numbers(action, who, field, allowed)
    if v.size != 1 or not np.isfinite(v).all() or v.ravel()[0] != int(v.ravel()[0]):
        raise ValueError(f"{who}: action field {field!r} = {action!r:.120} not allowed "
                         f"({agent}); {allowed}")
    return np.int64(int(v.ravel()[0]))


def is_voice_only(space: spaces.Space) -> bool:
    """True for ``Dict(motors=Box with no values, voice=Discrete, loudness=Box((1,)))``."""
    return (isinstance(space, spaces.Dict) and set(space.spaces) == {"motors", "voice", "loudness"}
            and _is_dict_action(space) and int(np.prod(space["motors"].shape)) == 0)


class ActionDecoder:
    """Maps a flat float32 action onto an agent's action space of this package.

    Supported: a ``Box`` (returned reshaped), or ``Dict({"motors": Box, "expression": Discrete})``
    (the Box holds the motors then one logit per expression; with no motors at all, the action
    is the ``Discrete`` expression id itself), with ``voice`` and ``loudness`` too (one logit per
    sound kind, then the loudness); an agent whose only action is its voice (no motors, no
    face) takes the ``Discrete`` sound id itself, at :data:`VOICE_ONLY_LOUDNESS`.
    """

    def __init__(self, space: spaces.Space):
        self.source = space
        self.n_voices = self.voice_start = 0
        self.voice_only = is_voice_only(space)
        self.discrete = is_expression_only(space) or self.voice_only
        if self.voice_only:  # a voice-only agent: its action is the sound kind itself
            voice = space["voice"]
            self.n_motors, self.n_expressions = 0, 0
            self.n_voices, self.voice_start = int(voice.n), int(voice.start)
            self._motors = np.zeros(space["motors"].shape, space["motors"].dtype)
            self._loudness = np.array([VOICE_ONLY_LOUDNESS], np.float32)
            self.space = spaces.Discrete(voice.n, start=voice.start)
            return
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
        elif _is_dict_action(space):
            motors = space["motors"]
            expression = space.spaces.get("expression")
            self.n_motors = int(np.prod(motors.shape))
            self.n_expressions = int(expression.n) if expression is not None else 0
            self.expression_start = int(expression.start) if expression is not None else 0
            self.motor_shape = motors.shape
            voice = space.spaces.get("voice")
            self.n_voices = int(voice.n) if voice is not None else 0
            self.voice_start = int(voice.start) if voice is not None else 0
            n_logits = self.n_expressions + self.n_voices
            low = np.concatenate([motors.low.ravel(), np.full(n_logits, LOGIT_LOW)]
                                 + ([space["loudness"].low.ravel()] if voice is not None else []))
            high = np.concatenate([motors.high.ravel(), np.full(n_logits, LOGIT_HIGH)]
                                  + ([space["loudness"].high.ravel()] if voice is not None else []))
        else:
            raise TypeError(f"cannot flatten action space {space}; supported: a Box of motors, or "
                            "Dict(motors=Box, expression=Discrete) (with voice=Discrete and "
                            "loudness=Box((1,)) when the voice is on)")
        self.space = spaces.Box(np.asarray(low, np.float32), np.asarray(high, np.float32),
                                dtype=np.float32)

    @property
    def categorical_groups(self) -> tuple[tuple[int, int], ...]:
        """The flat ``Box``'s logit groups as ``(start, n)``: the expression's, then the
        voice's; ``()`` for a ``Box`` of motors and for a ``Discrete`` (face- or voice-only)
        action."""
        if self.discrete:
            return ()
        groups, start = [], self.n_motors
        for n in (self.n_expressions, self.n_voices):
            if n:
                groups.append((start, n))
                start += n
        return tuple(groups)

    def __call__(self, action, who: str = "agent"):
        if self.voice_only:
            kind = _one_id(action, who, "voice", "sound", self.voice_start, self.n_voices,
                           "a voice-only agent")
            return {"motors": self._motors, "voice": kind, "loudness": self._loudness.copy()}
        if self.discrete:
            face = _one_id(action, who, "expression", "expression", self.expression_start,
                           self.n_expressions, "a face-only agent")
            return {"motors": self._motors, "expression": face}
        layout = f"{self.n_motors} motors" + (
            f" + {self.n_expressions} expression logits" if self.n_expressions else "") + (
            f" + {self.n_voices} voice logits + loudness" if self.n_voices else "")
        a = _numbers(action, who, "action", f"{self.space.shape[0]} numbers ({layout})")
        if a.shape != self.space.shape:
            raise ValueError(f"{who}: action field 'action' (the flat action) has shape "
                             f"{a.shape}; expected "
                             f"{self.space.shape} ({layout})")
        # clipped in float64: a finite value beyond float32's range is clipped, not made inf
        # (NaN and inf motors go on to the env, whose error names the motors)
        motors = np.clip(a[:self.n_motors], self.space.low[:self.n_motors],
                         self.space.high[:self.n_motors])
        motors = motors.astype(np.float32).reshape(self.motor_shape)
        if not self.n_expressions and not self.n_voices:
            return motors
        out = {"motors": motors}
        end = self.n_motors + self.n_expressions
        if self.n_expressions:
            logits = a[self.n_motors:end]
            if not np.isfinite(logits).all():
                raise ValueError(f"{who}: action field 'expression logits' = {logits} not "
                                 f"allowed; allowed: {self.n_expressions} finite numbers (the "
                                 "largest picks the expression)")
            out["expression"] = np.int64(self.expression_start + int(np.argmax(logits)))
        if self.n_voices:
            logits, loud = a[end:end + self.n_voices], a[end + self.n_voices:]
            if not np.isfinite(a[end:]).all():
                raise ValueError(f"{who}: action field 'voice logits and loudness' = {a[end:]} "
                                 f"not allowed; allowed: {self.n_voices + 1} finite numbers (the "
                                 "largest logit picks the sound; the loudness is clipped to "
                                 "[0, 1])")
            out["voice"] = np.int64(self.voice_start + int(np.argmax(logits)))
            out["loudness"] = np.clip(loud, 0.0, 1.0).astype(np.float32)
        return out

    def encode(self, action):
        """The inverse: the flat action for ``action`` (logits HIGH/LOW; face-only or
        voice-only: its id)."""
        if self.voice_only:
            return int(action["voice"])
        if self.discrete:
            return int(action["expression"])
        if not self.n_expressions and not self.n_voices:
            return np.asarray(action, np.float32).ravel()
        parts = [np.asarray(action["motors"], np.float32).ravel()]
        for n, start, key in ((self.n_expressions, self.expression_start, "expression"),
                              (self.n_voices, self.voice_start, "voice")):
            if n:
                logits = np.full(n, LOGIT_LOW, np.float32)
                logits[int(action[key]) - start] = LOGIT_HIGH
                parts.append(logits)
        if self.n_voices:
            parts.append(np.asarray(action["loudness"], np.float32).ravel())
        return np.concatenate(parts)


def _numbers(action, who: str, field: str, allowed: str) -> np.ndarray:
    """``action`` as a float64 array, else a ValueError naming the agent, the field, the value
    and what is allowed (:func:`mimo_social.util.checks.number_array`)."""
    return number_array(action, f"{who}: action field {field!r}", allowed)


def flat_action_space(space: spaces.Space) -> spaces.Space:
    """The float32 ``Box`` (``Discrete`` for a face-only agent) that :class:`FlattenParallel`
    accepts for an action space."""
    return ActionDecoder(space).space
