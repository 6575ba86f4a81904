"""Eye images in a recording: each agent's two eye pictures, when rendered anew.

Images are taken from the observations given to the recorder when they hold them, else from
the env's vision system, and stored as PNG (lossless), JPEG (lossy, needs Pillow) or raw pixels.

Cost: the stepping thread only copies the pixels (a few microseconds an image) and hands them,
those of :data:`EYE_BATCH_STEPS` logged steps at a time, to one worker thread
(:class:`EyeEncoder`), which encodes them meanwhile (zlib and numpy let go
of Python's lock while they work, so the worker runs beside the simulation). Each frame keeps
the time and step it was taken at: the batch of an interval is built with explicit ``sim_time``
and ``step`` columns (Rerun's own time context is per thread and never used here). A flush waits
for the frames of its interval (by then long encoded, save the last one or two), so a file holds
every logged frame up to :attr:`~mimo_social.recording.Recorder.flushed_step`; ``close`` flushes
the worker and ends its thread.

Rate: by default eye images are logged at :data:`EYE_LOG_HZ` (25 per simulated second, every
4th step at the default 100 Hz control): a replay is watched at about video rate, and every
frame of two agents' four 64x64 eyes at 100 Hz costs about a fifth of the step's CPU time
(10 % on the stepping thread, 12 % on the encoder's), at 25 Hz a tenth (7.6-8 % and 3 %, of
which the recording without eyes takes 6.7-7 %; ``mimo-social bench recording --eyes`` on a
2-core VM busy with other work). ``Recorder(eye_every_k_steps=1)`` logs every rendered frame.
"""

from __future__ import annotations

import io
import math
import time
from collections.abc import Mapping
from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np
import pyarrow as pa
import rerun as rr

from ..render.png import encode_png
from ..util.checks import check_int
from .columns import (
    BLOBS,
    TEXTS,
    blob_values,
    component_field,
    entity,
    index_columns,
    index_fields,
    sparse_column,
)

__all__ = ["EYES", "EYE_BATCH_STEPS", "EYE_FORMATS", "EYE_LOG_HZ", "EyeEncoder", "EyeLog",
           "FrameBatch", "eye_every_k_steps"]

EYE_FORMATS = ("png", "jpeg", "raw")   # how eye images are stored (see Recorder)
EYES = ("left", "right")
#: default rate (frames per simulated second) of eye images in a recording (see the docstring)
EYE_LOG_HZ = 25.0
#: the frames of this many logged steps go to the encoder's thread together
EYE_BATCH_STEPS = 8


def eye_every_k_steps(dt: float, every_k_steps: int, value: int | None = None) -> int:
    """Every how many env steps eye images are logged: ``value`` when given (checked), else
    the smallest multiple of ``every_k_steps`` that is at least ``1 / EYE_LOG_HZ`` seconds of
    steps of ``dt`` seconds (4 at 100 Hz)."""
    if value is not None:
        return check_int("Recorder", "eye_every_k_steps", value, lo=1)
    k = max(1, math.ceil(1.0 / (EYE_LOG_HZ * dt) - 1e-9))
    return every_k_steps * math.ceil(k / every_k_steps)


def _encode_jpeg(image: np.ndarray, quality: int) -> bytes:
    from PIL import Image as PILImage

    out = io.BytesIO()
    PILImage.fromarray(np.ascontiguousarray(image)).save(out, format="JPEG", quality=quality)
    return out.getvalue()


class FrameBatch:
    """Eye frames (pixels) gathered over a few logged steps, handed to the encoder together
    (fewer wake-ups of its thread), then the :class:`~concurrent.futures.Future` of them."""

    __slots__ = ("frames", "future")

    def __init__(self):
        self.frames: list = []
        self.future: Future | None = None


class EyeEncoder:
    """One worker thread that encodes eye frames, off the stepping thread.

    :meth:`submit` takes a list of (t, step, agent, left, right) frames with pixel arrays and
    returns a Future of the same list with ``encode(image)`` in place of the pixels.
    :attr:`cpu_s`: CPU seconds the worker spent encoding (read after a flush or close).
    """

    def __init__(self, encode):
        self._encode = encode
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="mimo-eye-encoder")
        self.cpu_s = 0.0

    def _run(self, frames: list) -> list:
        enc, c0 = self._encode, time.thread_time()
        out = [(t, step, i, enc(left), enc(right)) for t, step, i, left, right in frames]
        self.cpu_s += time.thread_time() - c0
        return out

    def submit(self, frames: list) -> Future:
        return self._pool.submit(self._run, frames)

    def resolve(self, items: list) -> list:
        """``items`` with every :class:`FrameBatch` replaced by its encoded frames (handed to
        the worker now if it was not yet; waits for them; an error in the worker is raised
        here)."""
        out = []
        for x in items:
            if isinstance(x, FrameBatch):
                if x.future is None:
                    x.future = self.submit(x.frames)
                out += x.future.result()
            else:
                out.append(x)
        return out

    def close(self) -> None:
        self._pool.shutdown(wait=True)


class EyeLog:
    """The eye images of the agents with vision (``eye_left`` / ``eye_right`` observations).

    ``env``: the ParallelEnv; ``vision``: its shared vision system; ``agents``: the names of all
    agents (by index); ``single``: the observations given to :meth:`note` are the one agent's
    (a single-agent adapter's). :attr:`agents` holds the indices of those with eye images.
    """

    def __init__(self, env, vision, agents: list[str], eye_format: str = "png",
                 jpeg_quality: int = 90, single: bool = False):
        self.vision = vision
        self._single = single
        self.names = agents
        self.format = eye_format
        self._jpeg_quality = int(jpeg_quality)
        self.agents: list[int] = []
        self._shapes: dict[int, tuple[int, int]] = {}
        for i in sorted(getattr(vision, "agents", vision.images)):
            space = env.observation_space(agents[i])
            if hasattr(space, "spaces") and "eye_left" in space.spaces:
                self.agents.append(int(i))
                self._shapes[int(i)] = tuple(space["eye_left"].shape[:2])
        self.paths = {i: [entity("agents", agents[i], "eyes", e) for e in EYES]
                      for i in self.agents}
        if self.agents and eye_format == "jpeg":
            try:
                import PIL  # noqa: F401
            except ImportError:
                raise ImportError("eye_format='jpeg' needs Pillow (pip install pillow); "
                                  "'png' needs nothing") from None
        self._renders: dict[int, int] = {}
        self._encoder: EyeEncoder | None = None      # started at the first frame to encode
        self._batch: FrameBatch | None = None         # frames not yet handed to the encoder
        self._encoded_cpu_s = 0.0
        self._build_schema()

    def _build_schema(self) -> None:
        """Arrow schema of the eye image batches and, for raw images, each agent's format."""
        fields = index_fields()
        self._format_values: dict[int, pa.Array] = {}
        raw = self.format == "raw"
        for i in self.agents:
            if raw:
                h, w = self._shapes[i]
                fmt = next(b for b in rr.Image(np.zeros((h, w, 3), np.uint8)).as_component_batches()
                           if b.component_descriptor().component == "Image:format")
                self._format_values[i] = fmt.as_arrow_array()
                descs = [(rr.Image.descriptor_buffer(), BLOBS),
                         (rr.Image.descriptor_format(),
                          pa.list_(pa.field("item", self._format_values[i].type,
                                            nullable=False)))]
            else:
                descs = [(rr.EncodedImage.descriptor_blob(), BLOBS),
                         (rr.EncodedImage.descriptor_media_type(), TEXTS)]
            for p in self.paths[i]:
                for desc, dtype in descs:
                    fields.append(component_field(f"{p}:{desc.component}", p, desc, dtype))
        self.schema = pa.schema(fields)
        self._media_type = "image/png" if self.format == "png" else "image/jpeg"

    def reset(self) -> None:
        """A new episode: its first images are new ones."""
        self._renders = {}

    def note(self, out: list, t: float, step: int, observations) -> int:
        """Note the eye images, as (t, step, agent, left, right), of every agent with vision
        rendered anew since the last time (raw: appended to ``out``; PNG / JPEG: gathered in a
        :class:`FrameBatch` that ``out`` holds, encoded on the worker thread); return how many
        pairs."""
        renders = getattr(self.vision, "renders", None)
        if self._single and observations is not None:
            observations = {self.names[0]: observations}
        frames = []
        for i in self.agents:
            if renders is not None:
                if self._renders.get(i) == renders[i]:
                    continue                                   # the same images as before
                self._renders[i] = renders[i]
            obs = observations.get(self.names[i]) if isinstance(observations, Mapping) else None
            if isinstance(obs, Mapping) and "eye_left" in obs and "eye_right" in obs:
                left, right = obs["eye_left"], obs["eye_right"]
            else:
                images = self.vision.images[i]
                left, right = images["eye_left"], images["eye_right"]
            # copies: the worker reads them later, and the caller may write into its arrays
            frames.append((t, step, i, np.array(left, np.uint8), np.array(right, np.uint8)))
        if not frames:
            return 0
        if self.format == "raw":
            out += [(t, s, i, left.tobytes(), right.tobytes()) for t, s, i, left, right in frames]
            return len(frames)
        if self._encoder is None:
            self._encoder = EyeEncoder(self.encode)
        batch = self._batch
        if batch is None or batch.future is not None:
            batch = self._batch = FrameBatch()
            out.append(batch)
        batch.frames += frames
        if len(batch.frames) >= EYE_BATCH_STEPS * len(self.agents):
            batch.future = self._encoder.submit(batch.frames)
        return len(frames)

    def close(self) -> None:
        """Wait for the frames being encoded and end the worker thread (idempotent)."""
        if self._encoder is not None:
            self._encoder.close()
            self._encoded_cpu_s += self._encoder.cpu_s
            self._encoder = None

    @property
    def encode_cpu_s(self) -> float:
        """CPU seconds spent encoding images on the worker thread so far."""
        return self._encoded_cpu_s + (self._encoder.cpu_s if self._encoder is not None else 0.0)

    def encode(self, image: np.ndarray):
        """One image in this log's format (PNG / JPEG bytes, or the raw pixel bytes)."""
        if self.format == "png":
            return encode_png(image)
        if self.format == "jpeg":
            return _encode_jpeg(image, self._jpeg_quality)
        return np.ascontiguousarray(image, dtype=np.uint8).tobytes()

    def batch(self, eyes) -> pa.RecordBatch:
        """Eye images as one record batch: a row per step with images, per agent and eye its
        image where rendered, no data elsewhere (waits for the frames still being encoded)."""
        self._batch = None                             # (the next frames start a new one)
        if self._encoder is not None:
            eyes = self._encoder.resolve(eyes)
        steps = sorted({step: t for t, step, _, _, _ in eyes}.items())
        row_of = {step: r for r, (step, _) in enumerate(steps)}
        cells = {(i, e): [None] * len(steps) for i in self.agents for e in range(2)}
        for _, step, i, left, right in eyes:
            r = row_of[step]
            cells[i, 0][r], cells[i, 1][r] = left, right
        columns = index_columns([t for _, t in steps], [step for step, _ in steps])
        raw = self.format == "raw"
        for i in self.agents:
            for e in range(2):
                items = cells[i, e]
                blobs = [b for b in items if b is not None]
                columns.append(sparse_column(items, blob_values(blobs), BLOBS))
                if raw:
                    fmt = self._format_values[i]
                    second = fmt.take(pa.array(np.zeros(len(blobs), dtype=np.int64)))
                    dtype = pa.list_(pa.field("item", fmt.type, nullable=False))
                else:
                    second = pa.array([self._media_type] * len(blobs), pa.utf8())
                    dtype = TEXTS
                columns.append(sparse_column(items, second, dtype))
        return pa.RecordBatch.from_arrays(columns, schema=self.schema)
