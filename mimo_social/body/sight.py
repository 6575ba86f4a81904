"""Where an agent's eyes look and what lies in their view, from the compiled world's camera
frames (a camera looks along its frame's -z): one computation for the senses (``faces``), the
tasks and the scripted partners.
"""

from __future__ import annotations

import numpy as np

__all__ = ["gaze_rays", "in_view"]


def gaze_rays(data, cams) -> tuple[np.ndarray, np.ndarray]:
    """Lines of sight from eye cameras ``cams`` (shape ``(..., 2)``: each agent's two eyes, e.g.
    ``AgentSetup.eye_cameras``): the origin between the two eyes and the unit direction along the
    mean of their viewing axes, each ``(..., 3)``."""
    cams = np.asarray(cams, dtype=np.intp)
    origin = data.cam_xpos[cams].mean(axis=-2)
    direction = -data.cam_xmat[cams].reshape(*cams.shape, 3, 3)[..., 2].sum(axis=-2)
    return origin, direction / np.linalg.norm(direction, axis=-1, keepdims=True)


def in_view(data, cams, points, half_tan) -> np.ndarray:
    """Whether each of ``points`` (``(k, 3)``, world) lies inside the view frustum of each of the
    cameras ``cams`` (``(e,)``): in front of it and within ``half_tan`` (the tangent of half the
    field of view: ``(e,)`` for a square image, ``(e, 2)`` for its x and y). Shape ``(k, e)``."""
    cams = np.asarray(cams, dtype=np.intp)
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    rot = data.cam_xmat[cams].reshape(-1, 3, 3)                                  # (e, 3, 3)
    rel = points[:, None, :] - data.cam_xpos[cams][None]                         # (k, e, 3)
    local = np.einsum("eji,kej->kei", rot, rel)
    ahead = -local[..., 2]
    half = np.asarray(half_tan, dtype=float)
    half = np.broadcast_to(half[:, None] if half.ndim == 1 else half, (len(cams), 2))
    return (ahead > 0) & np.all(np.abs(local[..., :2]) <= half[None] * ahead[..., None], axis=2)
