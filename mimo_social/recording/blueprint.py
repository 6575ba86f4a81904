"""The default Rerun viewer layout of a recording."""

from __future__ import annotations

import numpy as np
import rerun.blueprint as rrb

from .columns import SIM_TIME, entity
from .contacts import CONTACTS_PATH
from .eyes import EYES

__all__ = ["blueprint", "scene_eye"]


def blueprint(agents: list[str], face_paths: list[str],
              eye_paths: dict[int, list[str]] | None = None,
              touch_agents: list[int] = (), scalars: bool = False, contacts: bool = False,
              eye: rrb.EyeControls3D | None = None) -> rrb.Blueprint:
    """The 3D world (seen from ``eye``) beside the faces, each agent's two eyes side by side
    (``eye_paths``: agent index -> its left and right eye paths), time series of rewards, of the
    touch totals of ``touch_agents`` and of the ``/scalars``, and tabs with the action norms, the
    expressions and (``contacts``) the contact events. The selection panel starts collapsed."""
    side: list = [rrb.Horizontal(*[rrb.Spatial2DView(origin=p, name=f"{a} face")
                                   for a, p in zip(agents, face_paths)],
                                 name="faces")]
    if eye_paths:
        eyes = [rrb.Horizontal(*[rrb.Spatial2DView(origin=p, name=f"{agents[i]} {e} eye")
                                 for e, p in zip(EYES, paths)],
                               name=f"{agents[i]} eyes")
                for i, paths in eye_paths.items()]
        side.append(eyes[0] if len(eyes) == 1 else rrb.Vertical(*eyes, name="eyes"))
    side.append(rrb.TimeSeriesView(origin="/agents", name="rewards",
                                   contents=[entity("agents", a, "reward") for a in agents]))
    if touch_agents:
        side.append(rrb.TimeSeriesView(
            origin="/agents", name="touch totals (N)",
            contents=[entity("agents", agents[i], "touch_total") for i in touch_agents]))
    if scalars:
        side.append(rrb.TimeSeriesView(origin="/scalars", name="scalars"))
    tabs = [rrb.TimeSeriesView(origin="/agents", name="action norms",
                               contents=[entity("agents", a, "action_norm") for a in agents]),
            rrb.TextLogView(origin="/agents", name="expressions")]
    if contacts:
        tabs.append(rrb.TextLogView(origin=CONTACTS_PATH, name="contacts"))
    side.append(rrb.Tabs(*tabs))
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial3DView(origin="/world", name="world", eye_controls=eye),
            rrb.Vertical(*side),
            column_shares=[3, 2]),
        rrb.TimePanel(timeline=SIM_TIME),
        # the selection panel takes a fifth of the page and is empty until one clicks
        rrb.SelectionPanel(state="collapsed"),
        collapse_panels=False)


def scene_eye(env) -> rrb.EyeControls3D | None:
    """The 3D view's starting camera: the env's scene camera (which shows every agent)."""
    scene_camera = getattr(env, "scene_camera", None)
    if scene_camera is None:
        return None
    cam = scene_camera()
    az, el = np.deg2rad(cam.azimuth), np.deg2rad(cam.elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    look = np.array(cam.lookat, dtype=np.float64)
    return rrb.EyeControls3D(position=look - cam.distance * forward, look_target=look,
                             eye_up=[0.0, 0.0, 1.0])
