"""The default Rerun viewer layout of a recording, made for a 1920x1080 browser page.

Left (60 % of the width): the 3D world, large, with the skin-force legend beside it (touch
on); under it the contact events between agents in a wide text log (only the time and the text:
no column cuts the sentence) beside tabs with the expression logs (one per agent up to three,
named for it) and the action norms. Right: one panel per agent with its face and its two eyes
side by side (each ~250 px wide, so a 64x64 eye shows at >= 200 px; rows for one or two
agents, a tab per agent for more), and under them
the task's plots (:meth:`~mimo_social.core.task.Task.plots`, one time-series view per plot), the
touch totals and the recorder's ``scalars``, in a grid (two columns, three beyond four views).
The selection and blueprint panels start collapsed and the time panel compact (each is one click
away). Plot lines have the agents' clothes colours (:mod:`.plots`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import rerun.blueprint as rrb
from rerun.blueprint.encodings import TextLogColumn, TextLogColumnKind, TimelineColumn

from .columns import SIM_TIME, STEP, entity
from .contacts import CONTACTS_PATH
from .eyes import EYES

__all__ = ["CEILING_PATH", "EYE_AZIMUTHS", "EYE_ELEVATIONS", "blueprint", "face_visibility",
           "scene_eye"]

#: the play room's ceiling as the recorder logs it (a static geom of the world body)
CEILING_PATH = entity("world", "scene", "playroom/ceiling")


def _text_log(origin: str, name: str, entity_column: bool,
              contents: list[str] | None = None) -> rrb.TextLogView:
    """A text log showing the simulated time and the text (the log level, always "INFO", and
    the step are hidden; the entity path only where it tells who); ``contents``: the entity
    paths shown (None: everything under ``origin``)."""
    return rrb.TextLogView(
        origin=origin, name=name, contents=contents,
        columns=rrb.TextLogColumns(
            timeline_columns=[TimelineColumn(SIM_TIME, visible=True),
                              TimelineColumn(STEP, visible=False)],
            text_log_columns=[TextLogColumn(TextLogColumnKind.EntityPath, visible=entity_column),
                              TextLogColumn(TextLogColumnKind.LogLevel, visible=False),
                              TextLogColumn(TextLogColumnKind.Body, visible=True)]))


def _agent_panel(agent: str, face: str | None, eyes: Sequence[str] | None):
    """One agent's face beside its two eyes (each a third of the panel's width)."""
    views = [rrb.Spatial2DView(origin=face, name=f"{agent} face")] if face else []
    if eyes:
        pair = rrb.Horizontal(*[rrb.Spatial2DView(origin=p, name=f"{agent} {e} eye")
                                for e, p in zip(EYES, eyes)], name=f"{agent} eyes")
        if not views:
            return pair
        return rrb.Horizontal(*views, pair, column_shares=[1, 2], name=agent)
    return views[0]


def blueprint(agents: list[str], face_paths: list[str],
              eye_paths: dict[int, list[str]] | None = None,
              touch_agents: Sequence[int] = (), scalars: bool = False, contacts: bool = False,
              eye: rrb.EyeControls3D | None = None, plots: Sequence | None = None,
              legend: Sequence[str] = ()) -> rrb.Blueprint:
    """The layout of the module docstring. ``face_paths``: each agent's face image; ``eye_paths``:
    agent index -> its left and right eye paths (vision on); ``touch_agents``: indices of the
    agents with touch totals; ``scalars``: a view of ``/scalars``; ``contacts``: the contact
    events' log; ``eye``: the 3D view's camera; ``plots``: the task's plot views (objects with
    ``title`` and ``paths``; None: a reward view of every agent); ``legend``: entity paths of the
    skin-force legend, shown beside the 3D view (the first a 2D space: the colour bar; the others
    text documents)."""
    eye_paths = eye_paths or {}
    # -- left: the world, its legend, the logs
    # the play room's ceiling is left out of the 3D view (it hides the room from above; the
    # eyes still see it, and the viewer's entity tree can show it again)
    world = rrb.Spatial3DView(origin="/world", name="world", eye_controls=eye,
                              contents=["$origin/**", f"- {CEILING_PATH}"])
    if legend:   # the colour bar (a 2D space), then text documents under it
        # short titles: the legend column is ~165 px wide on a 1920 px page
        keys = [rrb.Spatial2DView(origin=legend[0], name="skin N")]
        keys += [rrb.TextDocumentView(origin=p, name="key") for p in legend[1:]]
        key = keys[0] if len(keys) == 1 else rrb.Vertical(*keys, row_shares=[2] + [1] * (
            len(keys) - 1), name="skin legend")
        world = rrb.Horizontal(world, key, column_shares=[6, 1])
    if len(agents) <= 3:   # one log per agent: its name in the title, no path column to cut
        expressions = rrb.Horizontal(*[_text_log(entity("agents", a, "expression"),
                                                 a, entity_column=False)
                                       for a in agents], name="expressions")
    else:
        expressions = _text_log("/agents", "expressions", entity_column=True)
    logs = [expressions,
            rrb.TimeSeriesView(origin="/", name="action norms",
                               contents=[entity("agents", a, "action_norm") for a in agents])]
    # text views among the plots (the agents' sounds): a tab beside the expressions
    logs[1:1] = [_text_log("/", p.title, True, list(p.paths)) for p in plots or ()
                 if getattr(p, "text", False)]
    bottom = rrb.Tabs(*logs)
    if contacts:
        bottom = rrb.Horizontal(_text_log(CONTACTS_PATH, "contacts between agents", False),
                                bottom, column_shares=[5, 2])
    left = rrb.Vertical(world, bottom, row_shares=[3, 1])
    # -- right: one panel per agent, then the plots
    panels = [_agent_panel(a, face_paths[i] if i < len(face_paths) else None,
                           eye_paths.get(i)) for i, a in enumerate(agents)]
    if not eye_paths:
        agent_part = rrb.Horizontal(*panels, name="faces")
        agent_rows = 0.6
    elif len(agents) <= 2:
        agent_part = panels[0] if len(panels) == 1 else rrb.Vertical(*panels, name="agents")
        agent_rows = len(panels)
    else:
        agent_part = rrb.Tabs(*panels, name="agents")
        agent_rows = 1.1
    if plots is None:
        from .plots import PlotView
        plots = [PlotView("reward", tuple(entity("agents", a, "reward") for a in agents))]
    series = [rrb.TimeSeriesView(origin="/", name=p.title, contents=list(p.paths))
              for p in plots if not getattr(p, "text", False)]
    if touch_agents:
        series.append(rrb.TimeSeriesView(
            origin="/", name="touch totals (N)",
            contents=[entity("agents", agents[i], "touch_total") for i in touch_agents]))
    if scalars:
        series.append(rrb.TimeSeriesView(origin="/scalars", name="scalars"))
    right_parts, shares = [agent_part], [agent_rows]
    if series:
        right_parts.append(series[0] if len(series) == 1 else
                           rrb.Grid(*series, grid_columns=2 if len(series) <= 4 else 3,
                                    name="plots"))
        shares.append(max(1.0, 2.0 - 0.4 * agent_rows) if agent_rows else 1.5)
    right = rrb.Vertical(*right_parts, row_shares=shares)
    return rrb.Blueprint(
        rrb.Horizontal(left, right, column_shares=[3, 2]),
        rrb.TimePanel(timeline=SIM_TIME, state="collapsed"),
        # the selection panel took a fifth of the page, empty until one clicks; the blueprint
        # tree is for rearranging: both one click away
        rrb.SelectionPanel(state="collapsed"),
        rrb.BlueprintPanel(state="collapsed"),
        collapse_panels=False)


def face_visibility(heads: np.ndarray, faces: np.ndarray, position) -> np.ndarray:
    """How much of each face a camera at ``position`` sees: the cosine of the angle between where
    the face looks (``faces``, unit vectors) and the direction from its head (``heads``) to the
    camera (1: face on, 0.7: three quarters, 0: profile, < 0: the back of the head)."""
    to_camera = np.asarray(position, np.float64) - heads
    to_camera /= np.linalg.norm(to_camera, axis=1, keepdims=True)
    return np.einsum("ij,ij->i", faces, to_camera)


#: the camera directions :func:`scene_eye` tries: azimuths and elevations (degrees, MuJoCo's)
EYE_AZIMUTHS = np.arange(0.0, 360.0, 5.0)
EYE_ELEVATIONS = np.arange(-15.0, -46.0, -5.0)


def scene_eye(env) -> rrb.EyeControls3D | None:
    """The 3D view's starting camera: it looks where the env's scene camera looks (which shows
    every agent), from the direction (:data:`EYE_AZIMUTHS` x :data:`EYE_ELEVATIONS`) that shows
    the agents' faces best at the recording's start (the largest :func:`face_visibility` of the
    face seen least; inside the play room, at least 80 % of the scene camera's distance from
    what it looks at, so that the scene still fits)."""
    scene_camera = getattr(env, "scene_camera", None)
    if scene_camera is None:
        return None
    cam = scene_camera()
    look = np.array(cam.lookat, dtype=np.float64)
    world = getattr(env, "world", None)
    best = (-np.inf, cam.azimuth, cam.elevation, cam.distance)
    if world is not None and world.agents:
        from ..scenery import inside_camera

        d = world.data
        sites = [a.head_site for a in world.agents]
        heads = d.site_xpos[sites].astype(np.float64)
        faces = d.site_xmat[sites].reshape(-1, 3, 3)[:, :, 0].astype(np.float64)
        room = getattr(world, "room", None)
        for az in EYE_AZIMUTHS:
            for el in EYE_ELEVATIONS:
                dist = cam.distance if room is None else inside_camera(
                    room.centre, look, cam.distance, az, el)
                if dist < 0.8 * cam.distance:
                    continue
                seen = face_visibility(heads, faces, look - dist * _forward(az, el)).min()
                if seen > best[0] + 1e-9:
                    best = (seen, az, el, dist)
    _, az, el, dist = best
    return rrb.EyeControls3D(position=look - dist * _forward(az, el), look_target=look,
                             eye_up=[0.0, 0.0, 1.0])


def _forward(azimuth: float, elevation: float) -> np.ndarray:
    """The direction a MuJoCo free camera at ``azimuth`` / ``elevation`` (degrees) looks."""
    az, el = np.deg2rad(azimuth), np.deg2rad(elevation)
    return np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
