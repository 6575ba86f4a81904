"""The RLlib callback that sends every finished training episode to the driver's run log.

Each env runner logs, per agent and episode, ``(agent, return, length, success)`` under
:data:`EPISODES_METRIC` (an item series: all items since the last iteration's result);
:func:`episodes_of` reads them back from an iteration's result.
"""

from __future__ import annotations

from ray.rllib.callbacks.callbacks import RLlibCallback
from ray.rllib.utils.metrics import ENV_RUNNER_RESULTS

from .env import EPISODE_KEY

__all__ = ["EpisodeLog", "EPISODES_METRIC", "episodes_of"]

EPISODES_METRIC = "mimo_episodes"


class EpisodeLog(RLlibCallback):
    def on_episode_end(self, *, episode, metrics_logger=None, **kwargs) -> None:
        if metrics_logger is None:
            return
        for agent, sa in getattr(episode, "agent_episodes", {}).items():
            try:
                info = sa.get_infos(-1)
            except IndexError:
                continue
            summary = info.get(EPISODE_KEY) if isinstance(info, dict) else None
            if summary is None:
                continue
            success = info.get("is_success")
            metrics_logger.log_value(
                EPISODES_METRIC,
                (str(agent), float(summary[0]), int(summary[1]),
                 None if success is None else bool(success)),
                reduce="item_series")


def episodes_of(result: dict) -> list[tuple[str, float, int, bool | None]]:
    """The training episodes an iteration's ``result`` reports."""
    items = result.get(ENV_RUNNER_RESULTS, {}).get(EPISODES_METRIC, [])
    if items is None:
        return []
    out = []
    for item in items:
        if isinstance(item, (list, tuple)) and len(item) == 4:
            out.append(tuple(item))
    return out
