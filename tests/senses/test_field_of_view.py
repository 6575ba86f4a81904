"""The eyes' field of view (``vision`` ``field_of_view``): per agent, in the compiled model's
cameras, kept by a pickled copy; a wide one sees what a 60-degree eye cannot (the partner's head
turn while the learner fixates a toy on the floor); bad values are refused by name."""

from __future__ import annotations

import pickle

import mujoco
import numpy as np
import pytest

from mimo_social.core.kinematics import LookAt
from mimo_social.envs import joint_attention_v0
from mimo_social.senses.vision import VisionConfig, eye_images, render_now
from mimo_social.util.checks import ConfigError


def make(fov, size=32):
    return joint_attention_v0.parallel_env(per_agent=[
        {"vision": {"width": size, "height": size, "field_of_view": fov}},
        {"vision": {"width": size, "height": size}}])


def test_the_field_of_view_is_the_agent_s_cameras_and_a_pickled_copy_keeps_it():
    env = make(120.0)
    try:
        env.reset(seed=1)
        w = env.unwrapped.world
        assert np.all(w.model.cam_fovy[list(w.agents[0].eye_cameras)] == 120.0)
        assert np.all(w.model.cam_fovy[list(w.agents[1].eye_cameras)] == 60.0)   # its own
        copy = pickle.loads(pickle.dumps(env))
        zero = {a: env.action_space(a).sample() * 0 for a in env.agents}
        a, b = env.step(zero)[0], copy.step(zero)[0]
        assert np.array_equal(a["infant_0"]["eye_left"], b["infant_0"]["eye_left"])
        cw = copy.unwrapped.world
        assert np.all(cw.model.cam_fovy[list(cw.agents[0].eye_cameras)] == 120.0)
    finally:
        env.close()


def head_turn_changes(fov) -> float:
    """Share of the learner's eye pixels a 10-degree turn of the partner's head changes while
    the learner fixates the toy nearest it (head and eyes set by LookAt)."""
    env = make(fov, 64)
    try:
        env.reset(seed=1000)
        w = env.unwrapped.world
        m, d = w.model, w.data
        toy = int(env.unwrapped.task.toy_bodies[0])
        look = LookAt(w, 0)
        d.qpos[look.qpos] = look(m, d, "body", toy)
        mujoco.mj_forward(m, d)
        render_now(env, [0])
        before = eye_images(env, 0)
        swivel = m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT,
                                                 "infant_1/head_swivel")]
        d.qpos[swivel] += np.deg2rad(10.0)
        mujoco.mj_forward(m, d)
        render_now(env, [0])
        after = eye_images(env, 0)
    finally:
        env.close()
    return float(np.mean([np.any(np.abs(before[k].astype(int) - after[k]) > 16, axis=-1)
                          for k in ("eye_left", "eye_right")]))


def test_a_wide_field_sees_the_partner_s_head_turn_while_fixating_a_toy():
    assert head_turn_changes(None) == 0.0          # the partner's head is out of 60 degrees
    assert head_turn_changes(150.0) > 0.0          # in view: some of its pixels change


@pytest.mark.parametrize("value, words", [
    (5, ["field_of_view=5", "10 to 160"]),
    (170.0, ["field_of_view=170", "10 to 160"]),
    ("wide", ["field_of_view='wide'"]),
    (True, ["field_of_view=True"]),
])
def test_bad_fields_of_view_are_refused_by_name(value, words):
    with pytest.raises(ConfigError) as info:
        VisionConfig(field_of_view=value)
    for w in words:
        assert w in str(info.value), (w, str(info.value))
    assert "vision" in str(info.value)
