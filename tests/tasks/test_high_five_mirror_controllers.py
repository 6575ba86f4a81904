"""The scripted learners of high five and mirror: they act only through the agent's action,
say clearly what is wrong, and work with the other bodies and actuation models."""

import numpy as np
import pytest

from mimo_social.envs import high_five_v0, mirror_v0
from mimo_social.tasks.high_five.controller import ArmSweep, HighFiveController
from mimo_social.tasks.mirror.controller import MirrorController


def _state(env):
    w = env.world
    return (w.data.qpos.copy(), w.data.qvel.copy(), [w.expression_of(i) for i in range(2)])


@pytest.mark.parametrize("kwargs, pattern", [
    ({"push": 0.5}, r"push=0.5"),
    ({"palm": "down"}, r"palm='down'; allowed: \['partner', 'up', 'forward', 'posture'\]"),
    ({"ready": (0.1, 0.0)}, r"ready=\(0.1, 0.0\); allowed: \(forward, left, up\)"),
    ({"standoff": -1.0}, r"standoff=-1.0"),
    ({"wait_steps": -1}, r"wait_steps=-1"),
    ({"replan_steps": 0}, r"replan_steps=0"),
    ({"frequency": -1.0}, r"frequency=-1.0"),
    ({"partner": 3}, r"partner=3; allowed: None or an agent's name"),
])
def test_high_five_controller_bad_arguments(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        HighFiveController(**kwargs)


@pytest.mark.parametrize("kwargs, pattern", [
    ({"face": "grumpy"}, r"face='grumpy'; allowed: None, names \['neutral'"),
    ({"face": 7}, r"face=7"),
    ({"partner": 1}, r"partner=1"),
])
def test_mirror_controller_bad_arguments(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        MirrorController(**kwargs)


def test_controllers_refuse_agents_without_the_means():
    mirror = mirror_v0.parallel_env(vision=False)
    mirror.reset(seed=0)
    with pytest.raises(ValueError, match=r"HighFiveController: infant_0 does not actuate"):
        HighFiveController().reset(mirror, "infant_0", np.random.default_rng(0))
    with pytest.raises(ValueError, match=r"partner='infant_0' for infant_0; allowed: \['infant_1'\]"):
        MirrorController(partner="infant_0").reset(mirror, "infant_0", np.random.default_rng(0))
    five = high_five_v0.parallel_env(expressions=False)
    five.reset(seed=0)
    with pytest.raises(ValueError, match=r"MirrorController acts through the expression.*"
                                         r"expressions=True"):
        MirrorController().reset(five, "infant_0", np.random.default_rng(0))
    with pytest.raises(RuntimeError, match=r"before reset"):
        MirrorController().act(mirror, "infant_0", None)


@pytest.mark.parametrize("controller", [HighFiveController(), ArmSweep()])
def test_high_five_controllers_only_return_an_action(controller):
    env = high_five_v0.parallel_env()
    env.reset(seed=1)
    controller.reset(env, "infant_0", np.random.default_rng(0))
    for _ in range(3):
        before = _state(env)
        a = controller.act(env, "infant_0", None)
        after = _state(env)
        for x, y in zip(before[:2], after[:2]):
            np.testing.assert_array_equal(x, y)
        assert before[2] == after[2]
        assert env.action_space("infant_0").contains(a)
        env.step({"infant_0": a, "infant_1": env.action_space("infant_1").sample()})


def test_mirror_controller_only_returns_the_partners_face():
    env = mirror_v0.parallel_env(vision=False, task_options={"roles": "free"})
    env.reset(seed=0)
    c = MirrorController()
    c.reset(env, "infant_0", np.random.default_rng(0))
    for face in (3, 5, 5, 1):
        env.step({"infant_0": {"motors": np.zeros(0, np.float32), "expression": 0},
                  "infant_1": {"motors": np.zeros(0, np.float32), "expression": face}})
        before = _state(env)
        a = c.act(env, "infant_0", None)
        assert _state(env)[2] == before[2]
        assert env.action_space("infant_0").contains(a) and a["expression"] == face


@pytest.mark.parametrize("settings, controller", [
    ({"actuation": "muscle"}, {}), ({"hands": "five_fingers"}, {}),
    ({"task_options": {"distance": 0.4}}, {}),
    # the far distance of the first version: its rule (any felt touch) and its palm goal
    ({"task_options": {"distance": 0.45, "success": "touch"}}, {"palm": "forward"})])
def test_high_five_controller_other_bodies_and_actuation(settings, controller):
    """Muscles, five-fingered hands, the farthest distance of the palm rule (0.4 m) and the far
    distance of the first version: a high five within 3 s from seed 1000's start."""
    env = high_five_v0.scripted_env(**settings)
    c = HighFiveController(**controller)
    obs, _ = env.reset(seed=1000)
    c.reset(env.unwrapped, "infant_0", np.random.default_rng(0))
    for _ in range(300):
        obs, _, term, _, info = env.step({"infant_0": c.act(env.unwrapped, "infant_0", None)})
        if term["infant_0"]:
            break
    assert info["infant_0"]["is_success"]
