"""A keyword ``parallel_env`` does not take is refused as unknown, by name and value, with the
closest allowed name and the lists of env keywords (``n_agents`` among them) and agent
settings; it is not reported as an agent's setting."""

from __future__ import annotations

import inspect

import pytest

from mimo_social.core.env import MimoParallelEnv
from mimo_social.core.factory import ENV_KEYWORDS, agent_settings
from mimo_social.envs import free_play_v0, high_five_v0, reach_v0
from mimo_social.util.checks import ConfigError


def test_a_misspelt_n_agents_is_an_unknown_keyword_with_the_close_match():
    with pytest.raises(ConfigError) as e:
        reach_v0.parallel_env(n_agent=2)
    msg = str(e.value)
    assert msg.startswith("reach: unknown keyword n_agent=2 (did you mean n_agents?)")
    assert "agent setting(s)" not in msg and "infant_0" not in msg
    envs = msg.split("allowed env keywords: ")[1].split(";")[0].split(", ")
    assert envs == list(ENV_KEYWORDS) and "n_agents" in envs
    settings = msg.split("allowed agent settings")[1]
    assert all(name in settings for name in agent_settings())


@pytest.mark.parametrize("make, kwargs, expected", [
    (free_play_v0.parallel_env, {"max_step": 5}, "free_play: unknown keyword max_step=5 "
                                                 "(did you mean max_steps?)"),
    (high_five_v0.env, {"tuch": True}, "high_five: unknown keyword tuch=True "
                                       "(did you mean touch?)"),
    (free_play_v0.parallel_env, {"colour": 3, "scne": "moon"},
     "free_play: unknown keyword colour=3; also unknown: scne='moon'; allowed env keywords"),
])
def test_every_factory_names_the_unknown_keywords(make, kwargs, expected):
    with pytest.raises(ConfigError) as e:
        make(**kwargs)
    assert str(e.value).startswith(expected)


def test_the_env_keywords_are_what_the_env_and_its_factory_take():
    own = {p.name for p in inspect.signature(MimoParallelEnv.__init__).parameters.values()
           if p.kind is p.POSITIONAL_OR_KEYWORD} - {"self", "task"}
    assert set(ENV_KEYWORDS) == own | {"n_agents", "task_options", "max_cycles"}


def test_a_per_agent_setting_that_is_unknown_still_names_its_agent():
    with pytest.raises(ConfigError, match=r"infant_1: unknown agent setting.*colour"):
        free_play_v0.parallel_env(per_agent=[{}, {"colour": 3}])
