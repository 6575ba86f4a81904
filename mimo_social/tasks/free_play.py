"""Free play: infants stand on a floor facing each other; no reward, no end but the time limit.

The scene of the demo and of the benchmarks. Every joint is free and every motor is in the
action; optional props (a ball and a cube) lie between the infants.
"""

from __future__ import annotations

from ..core.world import Prop
from ..core.task import Task


class FreePlay(Task):
    name = "free_play"
    default_n_agents = 2
    default_max_steps = 1000

    def option_defaults(self) -> dict:
        return {"props": False}

    def props(self):
        if not self.options["props"]:
            return []
        return [Prop("ball", "sphere", (0.04,), (0.08, 0.12, 0.04), 0.1, (0.9, 0.25, 0.2, 1)),
                Prop("cube", "box", (0.03, 0.03, 0.03), (-0.08, -0.12, 0.03), 0.1,
                     (0.2, 0.5, 0.9, 1))]
