"""The task's plots in a recording: the time series each task chooses (:meth:`Task.plots`).

Each :class:`~mimo_social.core.task.Plot` becomes one series per agent (``/plots/<name>/<agent>``)
or one series (``/plots/<name>``); the reward plot is the recorder's own per-agent reward
(``/agents/<agent>/reward``). At every recorded row after an env step the plots' functions
write their values into one preallocated buffer row (at reset: no value); at flush the columns
go out in the recorder's Arrow batch, like every other scalar. Every per-agent series (the
plots', rewards, action norms, touch totals) is styled once, statically, with the agent's name
and its clothes colour, so that the lines match the bodies in the 3D view; the first agent's
line is the widest, so equal values of two agents show both colours.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyarrow as pa
import rerun as rr

from ..core.task import REWARD, Plot
from ..core.world import CLOTHES_PALETTE
from ..expressions.voice import SOUNDS
from .columns import SCALARS, TEXTS, component_field, entity, optional_scalars, sparse_column

__all__ = ["ONE_SERIES_RGB", "PlotLog", "PlotView", "agent_colors", "SOUND_PLOT"]

#: the colour of a series that is no agent's (one value for the pair, a shared reward): a mid
#: grey, seen on the viewer's light and dark themes alike, and no infant's clothes
ONE_SERIES_RGB = (105, 105, 110)
#: the plot of the agents' sound levels (agents with a voice; a task's own plot of this name
#: replaces it)
SOUND_PLOT = "sound_level"
_WIDTH = 2.0               # px: a line's width (the last agent's)
_WIDEST = 3.0              # px more for the first agent's line


def agent_colors(world) -> list[tuple[int, int, int]]:
    """Each agent's clothes colour as 8-bit RGB (its ``clothes_rgba``, else the palette's)."""
    out = []
    for i, setup in enumerate(world.agent_setups):
        rgba = setup.config.clothes_rgba or CLOTHES_PALETTE[i % len(CLOTHES_PALETTE)]
        out.append(tuple(int(round(255 * float(c))) for c in rgba[:3]))
    return out


@dataclass(frozen=True)
class PlotView:
    """One time-series view of the default layout: its title and the series' entity paths."""

    title: str
    paths: tuple[str, ...]
    text: bool = False     # a text log (the sounds' events), not a time series


class PlotLog:
    """The series of an env's task plots, their buffer and their static styles.

    ``env``: the ``MimoParallelEnv`` (its ``task.plots()`` are read once, here; a task without
    ``plots`` gets the reward); ``agents``: the agent names (by index); ``capacity``: the
    recorder's rows per flush.
    """

    def __init__(self, env, agents: list[str], capacity: int):
        task = getattr(env, "task", None)
        plots = list(task.plots()) if hasattr(task, "plots") else [Plot.reward()]
        self.env = env
        self.agents = list(agents)
        self.colors = agent_colors(env.world)
        n = len(self.agents)
        task_name = getattr(task, "name", type(task).__name__)
        # the agents with a voice: their sound level as a series and their sounds as events
        self.voiced = [i for i, c in enumerate(getattr(env, "agent_configs", ()))
                       if getattr(c, "voice", False)]
        if self.voiced and SOUND_PLOT not in {getattr(p, "name", None) for p in plots}:
            plots.append(Plot(SOUND_PLOT, "dB SPL at 1 m", _sound_levels, True,
                              tuple(self.voiced)))
        seen = set()
        self.plots: list[Plot] = []
        self.views: list[PlotView] = []
        self.paths: list[str] = []            # the logged series (all but the reward), in order
        self._styles: dict[str, tuple[tuple[int, int, int], str]] = {}
        self._calls = []                      # (fn, per_agent, agent indices or None, first col)
        for plot in plots:
            if not isinstance(plot, Plot):
                raise TypeError(f"{task_name}.plots(): {plot!r}; allowed: Plot instances")
            if plot.name in seen:
                raise ValueError(f"{task_name}.plots(): the name {plot.name!r} twice; "
                                 "allowed: one plot per name")
            seen.add(plot.name)
            who = list(plot.agents) if plot.agents is not None else list(range(n))
            bad = [i for i in who if i >= n]
            if bad:
                raise ValueError(f"{task_name}.plots(): plot {plot.name!r} agents={plot.agents}; "
                                 f"allowed: indices below {n} (the env's agents)")
            self.plots.append(plot)
            if plot.fn is None:               # the reward: the recorder logs it per agent
                paths = [entity("agents", a, REWARD) for a in self.agents]
                if plot.per_agent:
                    for i in who:
                        self._styles[paths[i]] = (self.colors[i], self.agents[i])
                    paths = [paths[i] for i in who]
                else:
                    paths = paths[:1]
                    self._styles[paths[0]] = (ONE_SERIES_RGB, "reward (shared)")
                self.views.append(PlotView(plot.title, tuple(paths)))
                continue
            first = len(self.paths)
            if plot.per_agent:
                paths = [entity("plots", plot.name, self.agents[i]) for i in who]
                for i, p in zip(who, paths):
                    self._styles[p] = (self.colors[i], self.agents[i])
                index = None if who == list(range(n)) else np.array(who, dtype=np.intp)
            else:
                paths = [entity("plots", plot.name)]
                self._styles[paths[0]] = (ONE_SERIES_RGB, plot.name)
                index = None
            self.paths += paths
            self._calls.append((plot, index, first, first + len(paths)))
            self.views.append(PlotView(plot.title, tuple(paths)))
        self.values = np.full((max(1, int(capacity)), len(self.paths)), np.nan)
        self.sound_paths = [entity("agents", self.agents[i], "voice") for i in self.voiced]
        if self.voiced:
            self.views.append(PlotView("sounds", tuple(self.sound_paths), text=True))
        self._said = [None] * len(self.voiced)     # per voiced agent its last (kind, dB)
        self.sound_texts = [[None] * len(self.values) for _ in self.voiced]

    # -- set-up ---------------------------------------------------------------------------------
    def fields(self) -> list[pa.Field]:
        """One Scalars field per logged series."""
        desc = rr.Scalars.descriptor_scalars()
        text = rr.TextLog.descriptor_text()
        return ([component_field(f"{p}:scalars", p, desc, SCALARS) for p in self.paths]
                + [component_field(f"{p}:text", p, text, TEXTS) for p in self.sound_paths])

    def log_static(self, rec: rr.RecordingStream, touch_agents=()) -> None:
        """Every series' name and colour (the agent's clothes colour): the task's plots, and the
        recorder's per-agent rewards, action norms and (``touch_agents``) touch totals."""
        styles = dict(self._styles)
        for i, a in enumerate(self.agents):
            styles.setdefault(entity("agents", a, REWARD), (self.colors[i], a))
            styles[entity("agents", a, "action_norm")] = (self.colors[i], a)
        for i in touch_agents:
            styles[entity("agents", self.agents[i], "touch_total")] = (self.colors[i],
                                                                      self.agents[i])
        for path, (rgb, name) in styles.items():
            rec.log(path, rr.SeriesLines(colors=[rgb], names=[name], widths=[self._width(name)]),
                    static=True)

    def _width(self, name: str) -> float:
        """Line width (px): the agents' lines narrower from the first to the last, each drawn
        over the ones before, so that equal values show as a line with a border in the first
        agent's colour (both right hands feel the partner at once, touch totals of a contact)."""
        n = len(self.agents)
        if name not in self.agents or n == 1:
            return _WIDTH
        return _WIDTH + _WIDEST * (n - 1 - self.agents.index(name)) / (n - 1)

    # -- per row --------------------------------------------------------------------------------
    def note(self, n: int, stepped: bool = True) -> None:
        """Row ``n``: every plot's value(s) now (``stepped``: after an env step; at reset the
        row holds no values)."""
        row = self.values[n]
        if self.voiced:
            self._note_sounds(n, stepped)
        if not stepped:
            row.fill(np.nan)
            return
        env = self.env
        for plot, index, a, b in self._calls:
            try:
                value = plot.fn(env)
                if plot.per_agent:
                    row[a:b] = value if index is None else np.asarray(value, float)[index]
                else:
                    row[a] = value
            except Exception as e:
                raise RuntimeError(f"{getattr(env.task, 'name', 'task')} plot {plot.name!r}: "
                                   f"{plot.fn!r} failed: {type(e).__name__}: {e}") from e

    def _note_sounds(self, n: int, stepped: bool) -> None:
        """Row ``n``'s sound events: a line per voiced agent whose sound (kind or level)
        changed since the last row ("cry 95 dB", "silence"); at reset every agent is silent."""
        sounds = self.env.sounds
        for k, i in enumerate(self.voiced):
            now = (int(sounds[i, 0]), round(float(sounds[i, 1]), 1)) if stepped else (0, 0.0)
            text = None
            if now != self._said[k] and (stepped or self._said[k] is not None):
                text = "silence" if now[0] == 0 else f"{SOUNDS[now[0]]} {now[1]:.0f} dB"
            self._said[k] = now
            self.sound_texts[k][n] = text

    def columns(self, n: int) -> list[pa.Array]:
        """The Scalars columns of the first ``n`` rows (no data where NaN), then the sound
        events' TextLog columns (no data where no event)."""
        out = []
        for k in range(len(self.paths)):
            value = self.values[:n, k].copy()          # fresh memory: Arrow wraps it
            out.append(optional_scalars(value, ~np.isnan(value)))
        for texts in self.sound_texts:
            rows = texts[:n]
            out.append(sparse_column(rows, pa.array([t for t in rows if t is not None],
                                                    pa.utf8()), TEXTS))
        return out


def _sound_levels(env) -> np.ndarray:
    """Every agent's sound level this step (dB SPL at 1 m; silence: 0)."""
    return env.sounds[:, 1]
