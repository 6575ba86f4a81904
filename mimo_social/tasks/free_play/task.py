"""The free_play task: the Task, its options and its env factories (table: the package docstring).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.task import Plot, Task, TaskOptions
from ...core.world import Prop
from ...core.factory import make_aec, make_parallel

__all__ = ["parallel_env", "env", "FreePlay", "FreePlayOptions"]


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

    def bind(self, env):
        """Index tables of this world (once per world: :meth:`Task.bind`)."""
        w = env.world
        self._heads = np.array([a.head_site for a in w.agents], np.intp)
        self._roots = np.array([a.root_body for a in w.agents], np.intp)
        self._self_pair = np.eye(len(w.agents), dtype=bool)

    def _head_height(self, env):
        return env.world.data.site_xpos[self._heads, 2]

    def _nearest(self, env):
        xy = env.world.data.xpos[self._roots, :2]
        diff = xy[:, None, :] - xy[None, :, :]
        gap = np.einsum("ijk,ijk->ij", diff, diff)
        gap[self._self_pair] = np.inf
        return np.sqrt(gap.min(axis=1))


# -- the env factories (``mimo_social.envs.free_play_v0`` re-exports them) ----------------

def parallel_env(**kwargs):
    return make_parallel(FreePlay, **kwargs)


def env(**kwargs):
    return make_aec(FreePlay, **kwargs)
