"""Task settings a task cannot use are a ConfigError (the package's error for user values) that
names the task, the setting, the value and what is allowed."""

from __future__ import annotations

import pytest

from mimo_social.envs import catch_v0, handover_v0, selfbody_v0
from mimo_social.util.checks import ConfigError


@pytest.mark.parametrize("options, words", [
    ({"target": ""}, ["selfbody", "target=''", "hip"]),
    ({"target": "left_wing"}, ["selfbody", "left_wing", "hip"]),
    ({"targets": ["hip", "tail"]}, ["selfbody", "tail", "not allowed"]),
])
def test_selfbody_targets_outside_the_body(options, words):
    with pytest.raises(ConfigError) as e:
        selfbody_v0.parallel_env(task_options=options)
    assert all(w in str(e.value) for w in words), str(e.value)


def test_catch_needs_five_fingers():
    with pytest.raises(ConfigError, match=r"catch: hands='mitten' not allowed.*five_fingers"):
        catch_v0.parallel_env(hands="mitten")


def test_handover_posture_named_with_the_agent():
    with pytest.raises(ConfigError, match=r"handover: infant_1: posture='sitting' not allowed"):
        handover_v0.parallel_env(per_agent=[{}, {"posture": "sitting"}])
