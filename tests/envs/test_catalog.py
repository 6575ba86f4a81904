"""The catalogue: every one-agent task names a scripted controller that acts through the agent's
own action space."""

import numpy as np
import pytest

from mimo_social.envs.catalog import CATALOG, entry, names
from mimo_social.partners import Partner


@pytest.mark.parametrize("name", names("one-agent"))
def test_every_one_agent_task_has_a_scripted_controller(name):
    e = entry(name)
    assert e.controller is not None and issubclass(e.controller, Partner)
    env = e.parallel_env()
    obs, _ = env.reset(seed=0)
    ctrl = e.controller()
    agent = env.possible_agents[0]
    ctrl.reset(env, agent, np.random.default_rng(0))
    action = ctrl.act(env, agent, obs[agent])
    assert env.action_space(agent).contains(np.asarray(action, dtype=np.float32))


def test_unknown_task_names_the_allowed_ones():
    with pytest.raises(ValueError, match="allowed: free_play, reach"):
        entry("fly")
    assert len(names()) == len(CATALOG)
