"""Three infants in free play with random actions; prints what happens and saves a picture.

    python examples/free_play_random.py
"""

import mimo_social  # noqa: F401  (sets up headless rendering before mujoco is imported)
import numpy as np

from mimo_social.envs import free_play_v0


def main(steps: int = 300, out: str = "free_play.png") -> None:
    env = free_play_v0.parallel_env(
        n_agents=3, render_mode="rgb_array", task_options={"props": True},
        per_agent=[{}, {"posture": "sitting"}, {"posture": "lying"}])
    obs, infos = env.reset(seed=0)
    print({a: {k: v.shape for k, v in o.items()} for a, o in obs.items()})
    for t in range(steps):
        actions = {a: env.action_space(a).sample() for a in env.agents}
        obs, rewards, terms, truncs, infos = env.step(actions)
        if t % 100 == 0:
            print(t, {a: i["expression"] for a, i in infos.items()})
        if not env.agents:
            break
    frame = env.render()
    try:
        import matplotlib.pyplot as plt
        plt.imsave(out, frame)
        print("saved", out)
    except ImportError:
        print("matplotlib not installed: frame", frame.shape, "not saved")
    env.close()


if __name__ == "__main__":
    main()
