"""RLlib's ParallelPettingZooEnv around the envs (where ray's RLlib is installed; skipped else):
reset, stepping to the episode's end, and render(), to which RLlib passes the render mode."""

import numpy as np
import pytest

from client_envs import SHORT, entries, parallel

pytest.importorskip("ray")
rllib_pz = pytest.importorskip("ray.rllib.env.wrappers.pettingzoo_env")


@pytest.mark.parametrize("entry", entries())
def test_parallel_pettingzoo_env_steps_and_renders(entry):
    par = parallel(entry, render_mode="rgb_array", render_size=(24, 32))
    env = rllib_pz.ParallelPettingZooEnv(par)
    obs, infos = env.reset(seed=0)
    assert set(obs) == set(par.possible_agents)
    for a in par.possible_agents:
        par.action_space(a).seed(0)
    for _ in range(SHORT + 2):
        actions = {a: par.action_space(a).sample() for a in par.agents}
        obs, rewards, terms, truncs, infos = env.step(actions)
        if terms["__all__"] or truncs["__all__"]:
            break
    assert terms["__all__"] or truncs["__all__"]
    image = env.render()
    assert isinstance(image, np.ndarray) and image.shape == (24, 32, 3)
    env.close()
