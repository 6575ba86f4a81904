"""Eye images in a recording: each agent's two eye pictures, when rendered anew.

Images are taken from the observations given to the recorder when they hold them, else from
the env's vision system, and stored as PNG (lossless), JPEG (lossy, needs Pillow) or raw pixels.
"""

from __future__ import annotations

import io
from collections.abc import Mapping

import numpy as np
import pyarrow as pa
import rerun as rr

from ..render.png import encode_png
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

__all__ = ["EYES", "EYE_FORMATS", "EyeLog"]

EYE_FORMATS = ("png", "jpeg", "raw")   # how eye images are stored (see Recorder)
EYES = ("left", "right")


def _encode_jpeg(image: np.ndarray, quality: int) -> bytes:
    from PIL import Image as PILImage

    out = io.BytesIO()
    PILImage.fromarray(np.ascontiguousarray(image)).save(out, format="JPEG", quality=quality)
    return out.getvalue()


class EyeLog:
    """The eye images of the agents with vision (``eye_left`` / ``eye_right`` observations).

    ``env``: the ParallelEnv; ``vision``: its shared vision system; ``agents``: the names of all
    agents (by index). :attr:`agents` holds the indices of those with eye images.
    """

    def __init__(self, env, vision, agents: list[str], eye_format: str = "png",
                 jpeg_quality: int = 90):
        self.vision = vision
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
        """Append to ``out`` the encoded eye images, as (t, step, agent, left, right), of every
        agent with vision rendered anew since the last time; return how many pairs."""
        renders = getattr(self.vision, "renders", None)
        count = 0
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
            out.append((t, step, i, self.encode(left), self.encode(right)))
            count += 1
        return count

    def encode(self, image: np.ndarray):
        """One image in this log's format (PNG / JPEG bytes, or the raw pixel bytes)."""
        if self.format == "png":
            return encode_png(image)
        if self.format == "jpeg":
            return _encode_jpeg(image, self._jpeg_quality)
        return np.ascontiguousarray(image, dtype=np.uint8).tobytes()

    def batch(self, eyes) -> pa.RecordBatch:
        """Eye images as one record batch: a row per step with images, per agent and eye its
        image where rendered, no data elsewhere."""
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
