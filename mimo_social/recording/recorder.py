"""Record simulations to Rerun ``.rrd`` files (written to disk only: no viewer, no network).

A :class:`Recorder` attaches to a :class:`~mimo_social.core.env.MimoParallelEnv` (or a
Gymnasium :class:`~mimo_social.core.gym_adapter.SingleAgentEnv`, through its ``.parallel``)::

    env = free_play_v0.parallel_env(n_agents=2)
    with Recorder(env, "recordings/run.rrd") as rec:
        obs, infos = env.reset(seed=0)
        rec.log_reset(obs)
        while env.agents:
            actions = policy(obs)
            obs, rewards, term, trunc, infos = env.step(actions)
            rec.log_step(actions, rewards, obs)

Open the file with ``rerun recordings/run.rrd`` or ``mimo-social replay recordings/run.rrd``
(``--summary`` prints what it holds without a viewer). For training,
:class:`~mimo_social.recording.episodes.RecordingParallelEnv` records every k-th episode of one
env by itself and :func:`~mimo_social.recording.episodes.recording_env_fn` makes an ``env_fn``
for :func:`~mimo_social.train.vector.sb3_vec_env` whose first sub-environment records.

Layout of a recording::

    /world                          view coordinates (right-handed, z up)
    /world/scene/<geom>             static geoms of the world body (the floor)
    /world/<agent>/<body>           Transform3D of the body in the world, every logged step
    /world/<agent>/<body>/<geom>    static shape of each visible geom, in its body's frame
    /world/<agent>/skin             Points3D (world frame): the skin points that feel a force,
                                    coloured and sized by its magnitude (yellow 2.5 mm at 0.01 N
                                    -> dark red 10 mm at 10 N, log scale; touch on); every logged
                                    step, empty when nothing touches
    /legend/skin_force[_text]       the legend of those (static; :mod:`.skin`)
    /world/props/<body>[/<geom>]    the same for every other body (props)
    /agents/<agent>/reward          Scalars: reward, summed over the steps since the last row
    /agents/<agent>/action_norm     Scalars: L2 norm of the motor action, clipped to [-1, 1]
    /agents/<agent>/touch_total     Scalars: summed normal force (N) on the agent's skin (touch on)
    /agents/<agent>/expression      TextLog at reset and at every change of the expression
    /agents/<agent>/face            Image of the face at reset and at every change (see below)
    /agents/<agent>/eyes/left|right EncodedImage (PNG, lossless) of each eye (vision on), 25 Hz
    /events/contacts                TextLog, a full line when a body part of one agent starts or
                                    stops touching one of another, with the force (:mod:`.contacts`)
    /scalars/<name>                 Scalars: the ``scalars={name: fn(env)}`` given to the Recorder
    /plots/<name>[/<agent>]         Scalars: the task's plots (``Task.plots()``, :mod:`.plots`)

Heads are textured spheres (Mesh3D) that show the current face; the eyeballs (sclera, iris,
pupil) are drawn and turn with the eye joints; geoms in group 3 (none of the body's) are left
out. Face images and head textures are logged for expressions that stay at
least ``face_hold_s`` (0.05 s), stamped with the step they appeared, so that a policy switching
faces every step does not fill the file with images; the text log has every change.

Two timelines: ``sim_time`` (simulated seconds: ``data.time`` in the first episode, continued
without overlap across later resets) and ``step`` (env steps since the recording started, the
reset of each episode counting as one).

Cost: paths, index arrays and the Arrow schema are built once. Per step the recorder copies
``data.xpos``/``data.xquat`` and the motor actions into preallocated buffers, notes an expression
change (a change of the head materials' texture), looks for contacts between agents (one lookup of
all ``data.contact`` geom pairs in a table of "two different agents"), with touch notes which skin
points feel a force (one pass over the force array), and with vision copies the eye images for a
worker thread that encodes them (:mod:`.eyes`). Every ``flush_every_s`` of simulated time the
buffer goes out as **one** Arrow record batch (poses of all bodies, scalars, skin points placed,
coloured and sized then, for all rows at once), then a batch each of expression changes, eye
images and contact events (Rerun splits a batch into a chunk per entity, written on its own
thread). The next flush first waits until the previous one is written (long done by then), so a
crash keeps every row up to :attr:`Recorder.flushed_step`, losing at most two intervals. Rerun's
cost is mostly per chunk (entity and flush): the interval sets the price. Measured on a 2-core VM
busy with other work, stepping thread's CPU time against the plain step's: 2 infants without
images 7-16 % (the busier the machine, the more), ~16 MB per simulated minute (touch adds ~18,
eyes at 25 Hz ~5: ``mimo-social bench recording``); with touch and 2 x 64x64 eyes each
(``mimo-social bench recording --eyes``, medians of interleaved runs) 7 % without eyes, 8 %
with eyes at 25 Hz (the default; +3 % on the encoder thread), 10 % with every frame
(``eye_every_k_steps=1``; +12 % on the encoder thread). ``every_k_steps=2`` halves poses and
skin. Call :meth:`Recorder.close` (or use ``with``): it sends the rest, writes the footer, ends
the eye encoder's thread and frees the recorder's Rerun stream.

Resources (:mod:`.streams`): an open recorder holds one Rerun stream (2 OS threads, and Rerun's
file writer thread) and, with eyes, one encoder thread; :meth:`Recorder.close` frees them, so any
number of successive recordings cost the threads of one (Rerun's runtime adds 3 threads to the
process at its first use). While a
file is open, Rerun keeps an index entry per chunk for its footer: ~0.3 MB per 1000 steps with 2
infants (~0.5 MB with 2 x 32x32 eyes each), freed at close; record long runs as episodes
(:class:`~mimo_social.recording.episodes.RecordingParallelEnv`). A path that cannot be written
fails when the recorder is made, a disk that fills up at the next flush (or at close), with a
:class:`~mimo_social.recording.streams.RecordingFileError` naming the file and the cause.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pyarrow as pa
import rerun as rr
import rerun.blueprint as rrb

from ..util.checks import check_choice, check_int, show
from .blueprint import blueprint as _blueprint
from .blueprint import scene_eye
from .columns import (
    QUAT,
    SCALARS,
    VEC3,
    Rows,
    component_field,
    entity,
    index_fields,
    optional_scalars,
)
from .contacts import ContactLog
from .eyes import EYE_FORMATS, EyeLog
from .eyes import eye_every_k_steps as eye_every
from .faces import FaceLog
from .geometry import WXYZ_TO_XYZW, log_shapes, visible_bodies
from .plots import PlotLog
from .skin import SkinLog
from .streams import WRITE_TIMEOUT_S, FileStream

__all__ = ["Recorder", "parallel_of"]


def parallel_of(env):
    """The ``MimoParallelEnv`` inside ``env``: ``env`` itself, the ``.parallel`` of the Gymnasium
    adapter, or found through wrappers (``gym.make``'s chain, PettingZoo-style ``.env``); None
    if there is none."""
    seen = 0
    while env is not None and seen < 64:
        inner = env.__dict__.get("parallel") if hasattr(env, "__dict__") else None
        if inner is None:
            inner = getattr(env, "env", None)
        # (a wrapper such as ScriptedPartners forwards `world` but lists only its learners)
        if hasattr(env, "world") and hasattr(env, "possible_agents") and inner is None:
            return env
        if inner is None and isinstance(env, gym.Env) and env.unwrapped is not env:
            inner = env.unwrapped
        env, seen = inner, seen + 1
    return None


class Recorder:
    """Writes an env's simulation to a Rerun ``.rrd`` file; see the module docstring for the layout.

    Parameters
    ----------
    env:
        A ``MimoParallelEnv`` (or a wrapper of one), or the Gymnasium adapter (``SingleAgentEnv``,
        also inside ``gym.make``'s wrappers). With a Gymnasium env, :meth:`log_step` takes that
        agent's action and reward directly.
    path:
        The ``.rrd`` file to write (its folder is created). A path that cannot be written (a
        folder, no permission, a full disk) is a :class:`~mimo_social.recording.streams.
        RecordingFileError` (an ``OSError``) here; a write that fails later (the disk fills up)
        is one at the next flush or at :meth:`close`, naming the file and the cause.
    every_k_steps:
        Record poses and scalars every k-th env step (rewards are summed over the k steps);
        expression changes are always recorded at the step they happen.
    flush_every_s:
        Send buffered rows at least this often, in simulated seconds (default 4); a crash keeps
        the rows up to :attr:`flushed_step` (so it loses at most the rows of two such
        intervals). Shorter intervals cost more (see the module docstring).
    face_size:
        Edge length in pixels of the face images (and of the head textures).
    face_hold_s:
        Log the face image and head texture of an expression once it has been shown this long
        (simulated seconds), stamped with the step it appeared; every change is in the text log
        regardless. Keeps policies that switch faces every step from filling the file with
        images. 0: an image for every change.
    textured_heads:
        Draw sphere heads as meshes textured with the current face.
    blueprint:
        Store a default viewer layout (:mod:`.blueprint`): the 3D world with the skin legend,
        the contact events; per agent its face and two eyes; the task's plots, touch totals and
        chosen scalars over time; expressions and action norms in tabs.
    scalars:
        ``{name: fn}``: ``fn(env) -> float`` is called with the env given here at every logged
        step and goes to ``/scalars/<name>`` (a ``/`` in the name makes sub-paths); NaN: none.
    eyes:
        Log the eye images of agents with vision (``eye_left`` / ``eye_right``): taken from the
        ``observations`` given to :meth:`log_step` / :meth:`log_reset` when they hold them, else
        from the env's vision system. Only images rendered anew are logged (vision's ``every``).
    eye_format:
        ``"png"`` (default: lossless, ~2 KB a 64x64 image), ``"jpeg"`` (needs Pillow; smaller,
        lossy, ``eye_jpeg_quality``) or ``"raw"`` (uncompressed ``Image``; 12 KB a 64x64 image).
    eye_every_k_steps:
        Log eye images every k-th env step of an episode (default: 25 a simulated second, every
        4th step at 100 Hz, see :mod:`.eyes`; 1: every rendered frame).
    skin:
        Log the skin points that feel a force (agents with touch) and each agent's touch total.
    contacts:
        Log an event when a body part of one agent starts touching a body part of another.
    write_timeout_s:
        How long a flush may wait for Rerun's file writer while it is alive before the write
        counts as failed (a writer that stopped is noticed within a second).
    """

    def __init__(self, env, path: str | Path, every_k_steps: int = 1, *,
                 flush_every_s: float = 4.0, face_size: int = 64, face_hold_s: float = 0.05,
                 textured_heads: bool = True, blueprint: bool = True,
                 application_id: str = "mimo_social", recording_name: str | None = None,
                 scalars: Mapping[str, Callable[[Any], float]] | None = None,
                 eyes: bool = True, eye_format: str = "png",
                 eye_every_k_steps: int | None = None, eye_jpeg_quality: int = 90,
                 skin: bool = True, contacts: bool = True,
                 write_timeout_s: float = WRITE_TIMEOUT_S):
        penv = parallel_of(env)
        if penv is None:
            raise TypeError(f"Recorder needs a MimoParallelEnv, the Gymnasium adapter or a wrapper "
                            f"of one, got {type(env).__name__}")
        world = penv.world
        every_k_steps = check_int("Recorder", "every_k_steps", every_k_steps, lo=1)
        if not flush_every_s > 0:
            raise ValueError(f"flush_every_s={flush_every_s!r}; allowed: a positive number")
        eye_every_k_steps = eye_every(float(penv.dt), every_k_steps, eye_every_k_steps)
        check_choice("Recorder", "eye_format", eye_format, EYE_FORMATS)
        scalars = dict(scalars or {})
        for name, fn in scalars.items():
            if not isinstance(name, str) or not name.strip("/") or not callable(fn):
                raise ValueError(f"scalars: {name!r}: {fn!r}; each entry must be a non-empty name "
                                 "-> a callable fn(env) returning a float")
        self._user_env = env
        self.env = penv
        self.world = world
        self.path = Path(path)
        self.every_k_steps = int(every_k_steps)
        # a Gymnasium adapter: actions, rewards and observations are its learner's, infant_0
        self._single = isinstance(env, gym.Env)
        self.agents = list(penv.possible_agents)
        self._dt = float(penv.dt)
        self._textured_heads = textured_heads
        self._motor_counts = [self._motor_count(penv.action_space(a)) for a in self.agents]
        self._motor_index = {a: i for i, a in enumerate(self.agents)}
        self._bodies = visible_bodies(world)
        self._body_ids = self._bodies.ids
        self.body_paths: list[str] = self._bodies.paths
        self._find_senses(eyes, skin, contacts, eye_format, eye_jpeg_quality)
        self.eye_format = eye_format
        self.eye_every_k_steps = int(eye_every_k_steps)
        self._scalar_fns = list(scalars.values())
        self._scalar_paths = [entity("scalars", *[p for p in name.split("/") if p])
                              for name in scalars]
        self.scalar_names = list(scalars)
        if len(set(self._scalar_paths)) < len(self._scalar_paths):
            raise ValueError(f"scalars: names {self.scalar_names} give the same entity path twice")
        self._capacity = max(1, math.ceil(flush_every_s / (self._dt * self.every_k_steps)))
        self._plots = PlotLog(penv, self.agents, self._capacity)
        self._schema = self._build_schema()
        self._faces = FaceLog(world, self.agents,
                              max(0, math.ceil(face_hold_s / self._dt - 1e-9)))
        n_touch = len(self._skin.agents) if self._skin is not None else 0
        self._rows = Rows(self._capacity, world.model.nbody, self._motor_counts, n_touch,
                          len(self._scalar_fns))

        import pyarrow.compute  # noqa: F401  (Arrow imports it at the first masked array: now)

        self._stream = FileStream(self.path, application_id,
                                  self.blueprint() if blueprint else None, write_timeout_s)
        self._rec = self._stream.rec
        #: the Rerun recording id of the file (a new one per recorder)
        self.recording_id = self._rec.get_recording_id()
        if recording_name:
            self._rec.send_recording_name(recording_name)
        self._closed = False
        self._started = False
        self._global_step = -1
        self._episode_steps = 0
        self._time_offset = 0.0
        self._last_time: float | None = None
        self.rows = 0                 # pose rows recorded so far
        # pose rows (and the last step with one) known to be in the file: a crash keeps them
        self.flushed_rows = 0
        self.flushed_step = -1
        self._sent_rows, self._sent_step = 0, -1     # sent to Rerun, maybe not written yet
        self.eye_frames = 0           # eye image pairs recorded so far
        self.contact_events = 0       # contact events between agents recorded so far
        self.overhead_s = 0.0         # wall-clock seconds spent in this recorder's methods
        self._log_static()
        self._faces.build_columns(self._head_paths, face_size)

    # -- set-up ---------------------------------------------------------------------------------
    def _find_senses(self, eyes: bool, skin: bool, contacts: bool, eye_format: str,
                     eye_jpeg_quality: int) -> None:
        """The logs of the env's shared touch and vision systems (if on) and of contacts."""
        touch = self.env.systems.get("touch")
        vision = self.env.systems.get("vision")
        self._skin = SkinLog(touch, self.agents) if touch is not None and skin else None
        if self._skin is not None and not self._skin.agents:
            self._skin = None
        self._eyes = (EyeLog(self.env, vision, self.agents, eye_format, eye_jpeg_quality,
                             self._single)
                      if vision is not None and eyes else None)
        if self._eyes is not None and not self._eyes.agents:
            self._eyes = None
        self._contacts = (ContactLog(self.world, self.agents)
                          if contacts and len(self.agents) > 1 else None)

    def _build_schema(self) -> pa.Schema:
        fields = index_fields()
        t_desc = rr.Transform3D.descriptor_translation()
        q_desc = rr.Transform3D.descriptor_quaternion()
        for p in self.body_paths:
            fields.append(component_field(f"{p}:translation", p, t_desc, VEC3))
            fields.append(component_field(f"{p}:quaternion", p, q_desc, QUAT))
        s_desc = rr.Scalars.descriptor_scalars()
        for a in self.agents:
            for what in ("reward", "action_norm"):
                p = entity("agents", a, what)
                fields.append(component_field(f"{p}:scalars", p, s_desc, SCALARS))
        if self._skin is not None:
            fields += self._skin.fields()
        fields += self._plots.fields()
        for p in self._scalar_paths:
            fields.append(component_field(f"{p}:scalars", p, s_desc, SCALARS))
        return pa.schema(fields)

    def _log_static(self):
        self._rec.log("/world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        if self._skin is not None:
            self._skin.log_static(self._rec)
        self._plots.log_static(self._rec, self._skin.agents if self._skin is not None else ())
        self._head_paths = log_shapes(self._rec, self.world, self._bodies, self._textured_heads)

    def blueprint(self) -> rrb.Blueprint:
        """The default viewer layout (:func:`.blueprint.blueprint`; the ``blueprint``
        parameter)."""
        return _blueprint(self.agents, self._faces.face_paths,
                          self._eyes.paths if self._eyes is not None else None,
                          self._skin.agents if self._skin is not None else (),
                          bool(self._scalar_paths), self._contacts is not None,
                          scene_eye(self.env), self._plots.views,
                          getattr(self._skin, "legend_paths", ()))

    # -- logging ----------------------------------------------------------------------------------
    def log_reset(self, observations: Mapping[str, Any] | None = None) -> None:
        """Record the state right after ``env.reset()`` (the first row of an episode).

        ``observations``: what ``reset`` returned (optional): the eye images are taken from it
        when it holds them (with a single-agent adapter: that agent's observation).
        """
        t0 = time.perf_counter()
        self._check_open()
        w = self.world
        # views into the model/data memory, valid for the life of the world; taken anew per episode
        self._data, self._xpos, self._xquat = w.data, w.data.xpos, w.data.xquat
        self._xmat = w.data.xmat
        if self._contacts is not None and self._last_time is not None:
            self._note_contacts(end="episode reset")
        if self._last_time is not None:  # later episodes continue the timeline
            self._time_offset = self._last_time + self._dt - float(w.data.time)
        self._started = True
        self._global_step += 1
        self._episode_steps = 0
        na = len(self.agents)
        self._reward_acc = [math.nan] * na
        self._faces.reset(w.model.mat_texid)
        self._faces.commit(self._rows, self._global_step, everything=True)  # last episode's
        self._note_expressions(range(na), at_once=True)
        if self._contacts is not None:
            self._contacts.reset()                # contacts at reset are new ones
            self._note_contacts()
        if self._eyes is not None:
            self._eyes.reset()
            self.eye_frames += self._eyes.note(self._rows.eyes, self._now(), self._global_step,
                                               observations)
        self._append_row([math.nan] * na, None)
        self.overhead_s += time.perf_counter() - t0

    def log_step(self, actions: Mapping[str, Any] | Any,
                 rewards: Mapping[str, float] | float | None = None,
                 observations: Mapping[str, Any] | None = None) -> None:
        """Record the state right after ``env.step(actions)`` returned ``rewards``.

        ``actions`` and ``rewards`` are the dicts given to and returned by ``env.step`` (with a
        single-agent adapter: that agent's action and reward). Agents missing from them (done,
        or scripted) get no reward or action-norm value in that row; the actions are checked as
        ``env.step`` checks them (``env.check_action``): an unknown agent, a wrong shape, NaN/inf
        or a bad expression is a ValueError naming the agent, the field, the value and what is
        allowed. ``observations`` (optional): what ``env.step`` returned; eye images are taken
        from it when it holds them.
        """
        t0 = time.perf_counter()
        if not self._started:
            self._check_open()
            raise RuntimeError("log_step() before log_reset(): "
                               "call rec.log_reset() after env.reset()")
        if self._single:
            actions = {self.agents[0]: actions}
            if rewards is not None and not isinstance(rewards, Mapping):
                rewards = {self.agents[0]: rewards}
        motors = self._checked_motors(actions)
        self._global_step += 1
        self._episode_steps += 1
        if rewards:
            acc = self._reward_acc                   # NaN: no reward yet since the last row
            for i, a in enumerate(self.agents):
                r = rewards.get(a)
                if r is not None:
                    x = acc[i]
                    acc[i] = float(r) if x != x else x + float(r)
        faces = self._faces
        changed = faces.changed()
        if changed is not None:
            self._note_expressions(changed)
        if faces.pending:
            faces.commit(self._rows, self._global_step)
        if self._contacts is not None:
            self._note_contacts()
        if self._eyes is not None and self._episode_steps % self.eye_every_k_steps == 0:
            self.eye_frames += self._eyes.note(self._rows.eyes, self._now(), self._global_step,
                                               observations)
        if self._episode_steps % self.every_k_steps == 0:
            reward, self._reward_acc = self._reward_acc, [math.nan] * len(self.agents)
            self._append_row(reward, motors)
        self.overhead_s += time.perf_counter() - t0

    def _checked_motors(self, actions) -> dict[str, np.ndarray]:
        """Each agent's motor commands in ``actions``, checked as ``env.step`` checks them."""
        if not isinstance(actions, Mapping):
            raise ValueError(f"Recorder.log_step: actions={show(actions)} not allowed; allowed: "
                             f"the dict agent -> action given to env.step ({self.agents})")
        out = {}
        for a, action in actions.items():
            if a not in self._motor_index:
                raise ValueError(f"Recorder.log_step: an action for unknown agent {a!r}; "
                                 f"allowed: agents of this env {self.agents}")
            try:
                out[a] = self.env.check_action(a, action)[1]
            except ValueError as e:
                raise ValueError(f"Recorder.log_step: {e}") from None
        return out

    def _note_expressions(self, agents, at_once: bool = False) -> None:
        t = self._now()
        self._faces.note(self._rows, agents, t, self._global_step, at_once)
        self._last_time = t

    def _note_contacts(self, end: str | None = None) -> None:
        """Contacts between agents that started or stopped; ``end``: end all still on (why)."""
        c, out = self._contacts, self._rows.contacts
        self.contact_events += (c.note(self._data, out, self._now(), self._global_step)
                                if end is None else
                                c.end_all(out, self._last_time, self._global_step, end))


    @staticmethod
    def _motor_count(space) -> int:
        motors = space["motors"] if hasattr(space, "spaces") and "motors" in space.spaces else space
        return int(np.prod(motors.shape))

    def _now(self) -> float:
        return self._time_offset + float(self.world.data.time)

    def _append_row(self, reward, motors) -> None:
        """Copy the poses, time, rewards and motor actions (NaN: none) into the next buffer row."""
        rows = self._rows
        n = rows.n
        self._plots.note(n, self._episode_steps > 0)   # first: a failing plot adds no row
        for k, fn in enumerate(self._scalar_fns):
            try:
                rows.scalars[n, k] = fn(self._user_env)
            except Exception as e:
                raise RuntimeError(f"Recorder scalar {self.scalar_names[k]!r}: {fn!r} failed: "
                                   f"{type(e).__name__}: {e}") from e
        rows.xpos[n] = self._xpos
        rows.xquat[n] = self._xquat
        self._last_time = self._time_offset + self._data.time
        rows.time.append(self._last_time)
        rows.step.append(self._global_step)
        rows.reward.append(reward)
        for i, a in enumerate(self.agents):
            u = motors.get(a) if motors else None     # checked by log_step; None: no action
            rows.motors[i][n] = np.nan if u is None else u
        if self._skin is not None:
            self._skin.note(rows, n, self._xmat)
        rows.n = n + 1
        self.rows += 1
        if rows.n == self._capacity:
            self._flush()

    # -- sending --------------------------------------------------------------------------------
    def flush(self) -> None:
        """Send the buffered rows and events now and wait until they are in the file (this
        happens by itself when the buffer is full, i.e. every ``flush_every_s`` simulated
        seconds, without the wait, and at :meth:`close`)."""
        t0 = time.perf_counter()
        if not self._closed:
            self._flush()
            self._wait_written()
        self.overhead_s += time.perf_counter() - t0

    def _flush(self) -> None:
        rows = self._rows
        if self._sent_step > self.flushed_step:
            # what the last flush sent is written by Rerun's own thread meanwhile: wait for it
            # (it is long done: this costs ~0.5 ms), so everything up to there is on disk
            self._wait_written()
        if rows.n:
            self._rec.send_record_batch(self._record_batch(rows))
        if rows.texts or rows.images:
            self._rec.send_record_batch(self._faces.batch(rows.texts, rows.images))
        if rows.eyes:
            self._rec.send_record_batch(self._eyes.batch(rows.eyes))
        if rows.contacts:
            self._rec.send_record_batch(self._contacts.batch(rows.contacts))
        if rows.n:
            self._sent_rows += rows.n
            self._sent_step = rows.step[-1]
        rows.clear()

    def _record_batch(self, rows: Rows) -> pa.RecordBatch:
        """The buffered rows as one Arrow record batch: poses of all bodies, agents' scalars."""
        n, nb, ids = rows.n, len(self._body_ids), self._body_ids
        # (rows, all bodies, k) -> tracked bodies, each body's rows one after the other, float32;
        # MuJoCo's quaternions are (w, x, y, z), Rerun's (x, y, z, w)
        pos = np.ascontiguousarray(rows.xpos[:n, ids].transpose(1, 0, 2), dtype=np.float32)
        quat = np.ascontiguousarray(rows.xquat[:n, ids[:, None], WXYZ_TO_XYZW].transpose(1, 0, 2),
                                    dtype=np.float32)
        pos = pa.FixedSizeListArray.from_arrays(pos.ravel(), type=VEC3)
        quat = pa.FixedSizeListArray.from_arrays(quat.ravel(), type=QUAT)
        times = np.round(np.array(rows.time) * 1e9).astype(np.int64)
        # Arrow wraps numpy memory without copying and Rerun encodes later, on its own thread:
        # every column must own fresh memory, never a view of the reused buffers
        columns = [pa.array(times, pa.duration("ns")),
                   pa.array(np.array(rows.step, dtype=np.int64))]
        rewards = np.array(rows.reward, dtype=np.float64).reshape(n, -1)
        for b in range(nb):
            columns += [pos.slice(b * n, n), quat.slice(b * n, n)]
        for i in range(len(self.agents)):
            reward = rewards[:, i].copy()
            u = np.clip(rows.motors[i][:n].astype(np.float64), -1.0, 1.0)
            norm = np.sqrt(np.einsum("ij,ij->i", u, u))        # NaN where there was no action
            columns += [optional_scalars(reward, ~np.isnan(reward)),
                        optional_scalars(norm, ~np.isnan(norm))]
        if self._skin is not None:
            columns += self._skin.columns(rows)
        columns += self._plots.columns(n)
        for k in range(len(self._scalar_fns)):
            value = rows.scalars[:n, k].copy()
            columns.append(optional_scalars(value, ~np.isnan(value)))
        return pa.RecordBatch.from_arrays(columns, schema=self._schema)

    def _wait_written(self) -> None:
        """Wait until all that was sent is in the file (a write failure closes the recorder)."""
        try:
            self._stream.wait_written()
        except OSError:
            self._detach()
            raise
        self.flushed_rows, self.flushed_step = self._sent_rows, self._sent_step

    # -- closing --------------------------------------------------------------------------------
    def _check_open(self):
        if self._stream.failed is not None:
            raise self._stream.failed
        if self._closed:
            raise RuntimeError(f"the recorder of {self.path} is closed")

    def _detach(self) -> None:
        self._closed = True
        self._started = False
        self._rec = None

    def close(self) -> None:
        """Send what is buffered, finish the file (with its footer), detach and free Rerun's
        stream and its threads (idempotent). A write that failed is a ``RecordingFileError``."""
        if self._closed:
            return
        t0 = time.perf_counter()
        try:
            self._faces.commit(self._rows, self._global_step, everything=True)
            if self._contacts is not None and self._started:
                self._note_contacts(end="end of recording")
            self._flush()                      # (waits for the eye frames still being encoded)
            self._rec = None                   # the stream's last reference is the FileStream's
            self._stream.close()
            self.flushed_rows, self.flushed_step = self._sent_rows, self._sent_step
        finally:
            self._rec = None
            if self._eyes is not None:         # ends the eye encoder's thread
                self._eyes.close()
            if self._stream.rec is not None:   # an error before the stream was finished
                self._stream.close()
            self._detach()
            self.overhead_s += time.perf_counter() - t0

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return (f"Recorder({str(self.path)!r}, agents={self.agents}, bodies={len(self._body_ids)}, "
                f"rows={self.rows}, closed={self._closed})")
