"""Free play: infants stand on a floor facing each other; no reward, no end but the time limit.

| | |
|---|---|
| agents | 1-8 (default 2; the Gymnasium id: 1), `infant_0` ... on a circle around the origin, each facing the centre (the circle leaves room for the largest agent's reach) |
| body | free base; standing by default (`posture="sitting"` or `"lying"` too); every joint free, every motor in the action; mitten hands and spring-damper motors by default |
| scene | the floor; with `props=True` a ball (r = 4 cm) and a cube (6 cm) lie between the infants |
| reset | the initial pose; nothing random in the task |
| action | every motor: 44 in [-1, 1] (mitten hands), plus the expression (`Discrete(7)`) while expressions are on (default) |
| observation | `proprioception` (276), `vestibular` (6); other senses on request (`touch=...`, `vision=...`) |
| reward | 0 |
| success | none |
| termination | none; truncation at 1000 steps |
| options | `props` (False) |
| privileged cues | none |
| baselines | no reward, so no learning baseline; its speed (the scene of the benchmarks) is measured by `mimo-social bench` (BENCHMARKS.md) |
| sources | not in the MIMo paper as a task: the sandbox of this package |
| version history | v0: first version, with the first env |
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.task import Plot, Task, TaskOptions
from ..core.world import Prop


@dataclass(frozen=True)
class FreePlayOptions(TaskOptions):
    """``props``: a ball and a cube lie between the infants."""

    task = "free_play"
    props: bool = False

    def __post_init__(self):
        self._bool("props")


class FreePlay(Task):
    name = "free_play"
    default_n_agents = 2
    default_max_steps = 1000
    Options = FreePlayOptions

    def props(self):
        if not self.options.props:
            return []
        return [Prop("ball", "sphere", (0.04,), (0.08, 0.12, 0.04), 0.1, (0.9, 0.25, 0.2, 1)),
                Prop("cube", "box", (0.03, 0.03, 0.03), (-0.08, -0.12, 0.03), 0.1,
                     (0.2, 0.5, 0.9, 1))]

    def plots(self):
        """No reward (it is 0): each infant's head height (standing, sitting or fallen) and its
        distance to the nearest other infant (hips, on the floor plane)."""
        out = [Plot("head_height", "m", self._head_height)]
        if self.n_agents > 1:
            out.append(Plot("nearest_infant", "m", self._nearest))
        return out

    def _head_height(self, env):
        w = env.world
        if getattr(self, "_plot_world", None) is not w:   # index tables, once per world
            self._plot_world = w
            self._heads = np.array([a.head_site for a in w.agents], np.intp)
            self._roots = np.array([a.root_body for a in w.agents], np.intp)
            self._self_pair = np.eye(len(w.agents), dtype=bool)
        return w.data.site_xpos[self._heads, 2]

    def _nearest(self, env):
        self._head_height(env)
        xy = env.world.data.xpos[self._roots, :2]
        diff = xy[:, None, :] - xy[None, :, :]
        gap = np.einsum("ijk,ijk->ij", diff, diff)
        gap[self._self_pair] = np.inf
        return np.sqrt(gap.min(axis=1))
