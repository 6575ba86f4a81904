"""Gymnasium adapter over a one-agent env of this package (no second code path).

``SingleAgentEnv(parallel_env)`` exposes the only agent's observation and action spaces, and
steps the ParallelEnv with ``{agent: action}``.
"""

from __future__ import annotations

import gymnasium as gym

from ..util.checks import check_seed
from .env import MimoParallelEnv

__all__ = ["SingleAgentEnv"]


class SingleAgentEnv(gym.Env):
    def __init__(self, env: MimoParallelEnv):
        if len(env.possible_agents) != 1:
            raise ValueError(f"SingleAgentEnv needs a one-agent env; this one has "
                             f"{len(env.possible_agents)} agents: {env.possible_agents}")
        self.parallel = env
        self.agent = env.possible_agents[0]
        self.observation_space = env.observation_space(self.agent)
        self.action_space = env.action_space(self.agent)
        self.render_mode = env.render_mode
        self.metadata = {"render_modes": ["rgb_array"], "render_fps": env.metadata["render_fps"]}

    def reset(self, *, seed=None, options=None):
        seed = check_seed(seed, "reset")   # before Gymnasium's own, less clear, check
        super().reset(seed=seed)
        obs, infos = self.parallel.reset(seed=seed, options=options)
        return obs[self.agent], infos[self.agent]

    def set_age(self, age_months: float | None = None, motor_age_months: float | None = None,
                agent: str | None = None) -> None:
        """The infant's ages from the next reset on (:meth:`MimoParallelEnv.set_age`); reset's
        ``options`` (``age_months``, ``motor_age_months``) go to the ParallelEnv too."""
        self.parallel.set_age(age_months, motor_age_months, agent)

    def step(self, action):
        obs, rew, term, trunc, infos = self.parallel.step({self.agent: action})
        a = self.agent
        return obs[a], rew[a], term[a], trunc[a], infos[a]

    def render(self):
        return self.parallel.render()

    def close(self):
        self.parallel.close()

