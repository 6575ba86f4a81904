"""Two infants learn a high five with one shared PPO policy (parameter sharing).

    python examples/ppo_high_five.py --steps 20000

Needs the `train` extra (torch==2.13.0 first, then `pip install -e ".[train]"`).
"""

import argparse

import mimo_social  # noqa: F401
import numpy as np


def main() -> None:
    import torch
    from stable_baselines3 import PPO

    from mimo_social.envs import high_five_v0
    from mimo_social.train.vector import sb3_vec_env

    parser = argparse.ArgumentParser()
    parser.add_argument("--steps", type=int, default=20000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    torch.set_num_threads(1)
    vec = sb3_vec_env(lambda: high_five_v0.parallel_env(expressions=False), n_envs=1)
    model = PPO("MlpPolicy", vec, seed=args.seed, verbose=1, device="cpu")
    model.learn(total_timesteps=args.steps, progress_bar=False)
    # evaluate: distance of the right hands at the end of one episode
    env = high_five_v0.parallel_env(expressions=False)
    from mimo_social.core.wrappers import FlattenParallel
    flat = FlattenParallel(env)
    obs, _ = flat.reset(seed=123)
    infos = {}
    while flat.agents:
        actions = {a: model.predict(obs[a], deterministic=True)[0] for a in flat.agents}
        obs, rewards, terms, truncs, infos = flat.step(actions)
    print("final:", {a: (i["hands_touching"], round(i["hand_distance"], 3)) for a, i in infos.items()})


if __name__ == "__main__":
    main()
