"""``ReplayCaregiver``: plays a recorded caregiver's actions back, step by step, whatever the
learner does (the replay condition of Murray and Trevarthen's double video, 1985).

A stream is what :attr:`~mimo_social.partners.contingent.ContingentCaregiver.stream` holds:
``motors`` (T, n) float32, one row per control step, ``expression`` (T,) int64 (-1: the
caregiver had no expression action), optionally ``voice`` (T,) int64 (the sound kind of each
step; -1: no voice) with ``loudness`` (T,) float32, and ``dt`` (the control step, s); a stream
without ``voice`` (saved before voices were recorded) has none. The replay returns row
``offset + t`` at its step ``t`` of every episode, bit for bit, in the agent's action form
(its face and voice where its action has them: a talking caregiver's speech and silences are
replayed as recorded): the caregiver's actions are the
recorded ones, independent of the learner's; with the same start state and the same learner
actions its trajectory is the recorded one too (the physics is deterministic). Past the end it
repeats the last row (``past_end="hold"``; with positional actuation that holds the last pose)
or raises (``"error"``).

:func:`save_stream` / :func:`load_stream` keep a stream in a ``.npz`` file. A Rerun recording
of :mod:`mimo_social.recording` does not hold the actions themselves (only their norms per
agent), so a stream cannot be read back from one; save the stream next to the recording.
"""

from __future__ import annotations

import os
from typing import Mapping

import numpy as np
from gymnasium import spaces

from ..util.checks import ConfigError, check_choice, check_int, show
from .base import Partner

__all__ = ["ReplayCaregiver", "save_stream", "load_stream", "check_stream"]

PAST_END = ("hold", "error")


def check_stream(stream, who: str = "ReplayCaregiver") -> dict:
    """``stream`` as a dict of arrays (``motors`` (T, n) float32, ``expression`` (T,) int64,
    ``voice`` (T,) int64 and ``loudness`` (T,) float32 (-1 and 0 throughout where the stream
    has none), ``dt`` float), or a ConfigError naming what is wrong."""
    allowed = ("a mapping with 'motors' ((T, n) floats), 'expression' ((T,) integers, -1: "
               "none), optionally 'voice' ((T,) integers, -1: none) with 'loudness' ((T,) "
               "numbers in [0, 1]) and 'dt' (s), e.g. ContingentCaregiver.stream or "
               "load_stream()")
    if not isinstance(stream, Mapping) or "motors" not in stream or "expression" not in stream:
        raise ConfigError(f"{who}: stream={show(stream)} not allowed; allowed: {allowed}")
    try:
        motors = np.asarray(stream["motors"], dtype=np.float32)
        faces = np.asarray(stream["expression"])
    except (TypeError, ValueError) as e:
        raise ConfigError(f"{who}: stream arrays unreadable ({e}); allowed: {allowed}") from None
    if motors.ndim != 2 or faces.shape != (motors.shape[0],) or not len(motors) \
            or faces.dtype.kind not in "iu" or not np.all(np.isfinite(motors)):
        raise ConfigError(f"{who}: stream with motors {motors.shape} and expression "
                          f"{faces.shape} ({faces.dtype}) not allowed; allowed: {allowed}, "
                          "T >= 1, motors finite")
    t = motors.shape[0]
    voice = stream.get("voice")
    loud = stream.get("loudness")
    if (voice is None) != (loud is None):
        raise ConfigError(f"{who}: stream with {'voice' if loud is None else 'loudness'} but "
                          f"not {'loudness' if loud is None else 'voice'}; allowed: {allowed}")
    if voice is None:
        voice, loud = np.full(t, -1, np.int64), np.zeros(t, np.float32)
    try:
        voice, loud = np.asarray(voice), np.asarray(loud, dtype=np.float32)
    except (TypeError, ValueError) as e:
        raise ConfigError(f"{who}: stream voice unreadable ({e}); allowed: {allowed}") from None
    if voice.shape != (t,) or loud.shape != (t,) or voice.dtype.kind not in "iu" \
            or not np.all((loud >= 0.0) & (loud <= 1.0)):
        raise ConfigError(f"{who}: stream with voice {voice.shape} ({voice.dtype}) and loudness "
                          f"{loud.shape} for {t} steps not allowed; allowed: {allowed}")
    dt = float(stream.get("dt", np.nan))
    return {"motors": motors, "expression": faces.astype(np.int64),
            "voice": voice.astype(np.int64), "loudness": loud, "dt": dt}


def save_stream(path, stream) -> str:
    """Write ``stream`` to ``path`` (``.npz``; the suffix is added if missing); returns the
    path written."""
    s = check_stream(stream, "save_stream")
    path = os.fspath(path)
    if not path.endswith(".npz"):
        path += ".npz"
    np.savez(path, motors=s["motors"], expression=s["expression"], voice=s["voice"],
             loudness=s["loudness"], dt=np.float64(s["dt"]))
    return path


def load_stream(path) -> dict:
    """The stream saved at ``path`` by :func:`save_stream`."""
    with np.load(os.fspath(path)) as f:
        return check_stream({k: f[k] for k in f.files}, "load_stream")


class ReplayCaregiver(Partner):
    """Plays ``stream`` (a stream mapping or the path of a saved one) back from row ``offset``
    (see the module docstring). ``step``: the row the next action comes from."""

    def __init__(self, stream, offset: int = 0, past_end: str = "hold"):
        if isinstance(stream, (str, os.PathLike)):
            try:
                stream = load_stream(stream)
            except (OSError, ValueError, EOFError) as e:   # missing, unreadable, not a stream
                raise ConfigError(f"ReplayCaregiver: stream={show(stream)} cannot be read "
                                  f"({type(e).__name__}: {e}); allowed: the path of a .npz "
                                  "file written by save_stream, or a stream mapping") from None
        self._stream = check_stream(stream)
        n = len(self._stream["motors"])
        self.offset = check_int("ReplayCaregiver", "offset", offset, 0, n - 1)
        self.past_end = check_choice("ReplayCaregiver", "past_end", past_end, PAST_END)
        self.step: int | None = None

    @property
    def stream(self) -> dict:
        """The stream played back (copies)."""
        return {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in self._stream.items()}

    #: :func:`load_stream` and :func:`save_stream`, also reachable from the class
    load_stream = staticmethod(load_stream)
    save_stream = staticmethod(save_stream)

    def __len__(self) -> int:
        return len(self._stream["motors"])

    def reset(self, env, agent, rng):
        super().reset(env, agent, rng)
        self._keys = self.check(env, agent)
        self.step = self.offset

    def check(self, env, agent: str) -> tuple[str, ...]:
        """Whether the stream fits ``agent`` of ``env`` (its motors, its face, its voice, the
        control step), else a ConfigError saying what differs; returns the keys of the agent's
        action besides ``motors`` (``expression``, ``voice``; empty: a plain Box action).
        :meth:`reset` runs it; a factory can run it when the env is made."""
        space = env.action_space(agent)
        keys = tuple(k for k in ("expression", "voice")
                     if isinstance(space, spaces.Dict) and k in space.spaces)
        face = "expression" in keys
        box = space.spaces["motors"] if isinstance(space, spaces.Dict) else space
        n = self._stream["motors"].shape[1]
        if box.shape != (n,):
            raise ConfigError(f"ReplayCaregiver: the stream has {n} motors, {agent}'s action "
                              f"{box.shape[0]}; replay it for the agent it was recorded from")
        if face and np.any(self._stream["expression"] < 0):
            raise ConfigError(f"ReplayCaregiver: {agent} acts with its face but the stream has "
                              "no expressions (recorded without them)")
        if "voice" in keys and np.any(self._stream["voice"] < 0):
            raise ConfigError(f"ReplayCaregiver: {agent} acts with its voice but the stream has "
                              "no voice (recorded from a caregiver without one, or saved "
                              "before voices were recorded)")
        dt = self._stream["dt"]
        if np.isfinite(dt) and abs(dt - float(env.dt)) > 1e-9:
            raise ConfigError(f"ReplayCaregiver: the stream was recorded at dt={dt} s, this env "
                              f"steps dt={env.dt} s")
        return keys

    def act(self, env, agent, observation):
        if self.step is None:
            raise RuntimeError("ReplayCaregiver.act() before reset(); reset the env first")
        n = len(self)
        k = self.step
        if k >= n:
            if self.past_end == "error":
                raise RuntimeError(f"ReplayCaregiver: the stream's {n} steps are played "
                                   f"(offset {self.offset}); past_end='error'")
            k = n - 1
        self.step += 1
        u = self._stream["motors"][k].copy()
        if not self._keys:
            return u
        out = {"motors": u}
        if "expression" in self._keys:
            out["expression"] = np.int64(self._stream["expression"][k])
        if "voice" in self._keys:
            out["voice"] = np.int64(self._stream["voice"][k])
            out["loudness"] = np.array([self._stream["loudness"][k]], np.float32)
        return out

    def __repr__(self) -> str:
        return f"ReplayCaregiver({len(self)} steps, offset={self.offset}, past_end={self.past_end!r})"
