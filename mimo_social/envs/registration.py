"""Gymnasium ids of the one-agent tasks."""

import gymnasium as gym

IDS = {"mimo_social/Reach-v0": "mimo_social.envs.single:make_reach",
       "mimo_social/Standup-v0": "mimo_social.envs.single:make_standup",
       "mimo_social/SelfBody-v0": "mimo_social.envs.single:make_selfbody",
       "mimo_social/Catch-v0": "mimo_social.envs.single:make_catch"}


def register_envs() -> None:
    for env_id, entry in IDS.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=entry, disable_env_checker=False)
