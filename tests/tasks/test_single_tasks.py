"""The one-agent demos of the paper (reach, standup, selfbody, catch): API checks, rewards, ends."""

import pickle

import mujoco
import numpy as np
import pytest

import mimo_social  # noqa: F401  (registers the ids)
from mimo_social.envs import catch_v0, reach_v0, selfbody_v0, standup_v0

A = "infant_0"


@pytest.mark.parametrize("module", [standup_v0, selfbody_v0, catch_v0])
def test_one_agent_and_the_table(module):   # the API checks: tests/conformance
    env = module.parallel_env(max_steps=30)
    assert env.possible_agents == [A]
    assert module.__doc__ and "\nreward:\n" in module.__doc__  # the table travels with the env
    env.close()


def test_spaces_of_the_published_tasks():
    st = standup_v0.parallel_env()
    assert st.action_space(A).shape == (27,) and st.frame_skip == 2 and st.max_steps == 500
    assert set(st.observation_space(A).spaces) == {"proprioception", "vestibular"}
    sb = selfbody_v0.parallel_env()
    assert sb.action_space(A).shape == (8,) and sb.max_steps == 500
    obs = sb.observation_space(A).spaces
    assert set(obs) == {"proprioception", "touch", "target"}
    assert obs["target"].shape == (len(sb.task.targets),) == (28,)
    ca = catch_v0.parallel_env()
    assert ca.action_space(A).shape == (40,) and ca.max_steps == 800   # 20 axes x 2 muscles
    assert float(ca.action_space(A).low.min()) == 0.0 and float(ca.action_space(A).high.max()) == 1.0
    assert set(ca.observation_space(A).spaces) == {"proprioception", "touch", "ball_size"}
    names = ca.world.agents[0].actuated_names
    assert "right_wrist_flexion" in names and not any("thumb" in n for n in names)
    with pytest.raises(ValueError, match="five_fingers"):
        catch_v0.parallel_env(hands="mitten", touch=False)
    for env in (st, sb, ca):
        env.close()


# -- standup: tests/tasks/test_standup.py -----------------------------------------------


@pytest.mark.parametrize("module, options, match", [
    (reach_v0, {"success_reward": "abc"}, r"reach: task option success_reward='abc' not allowed"),
    (catch_v0, {"radius": (0.02, 0.01)}, r"catch: task option radius=.*low <= high"),
    (standup_v0, {"settle_steps": 2.5}, r"standup: task option settle_steps=2.5.*integer"),
    (selfbody_v0, {"targets": "head"}, r"selfbody: task option targets='head' not allowed"),
    (reach_v0, {"reward": 1}, r"unknown task option.*allowed: \['min_distance'"),
])
def test_task_options_are_checked_when_made(module, options, match):
    with pytest.raises(ValueError, match=match):
        module.parallel_env(task_options=options)


def test_task_options_as_a_dict_or_as_the_dataclass():
    from mimo_social.envs import free_play_v0
    from mimo_social.tasks.reach import Reach, ReachOptions
    assert Reach.Options is ReachOptions
    env = reach_v0.parallel_env(task_options=ReachOptions(success_reward=5.0))
    assert env.task.options == reach_v0.parallel_env(task_options={"success_reward": 5}).task.options
    with pytest.raises(ValueError, match="props='no'.*True or False"):
        free_play_v0.parallel_env(task_options={"props": "no"})
