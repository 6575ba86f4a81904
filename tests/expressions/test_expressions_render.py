"""Expressions: a change alters the pixels of that agent's face and of no other agent's."""

import mujoco
import numpy as np
import pytest

from mimo_social.envs import free_play_v0


def face_camera(env, i):
    d = env.world.data
    a = env.world.agents[i]
    head = d.site_xpos[a.head_site]
    forward = d.xmat[env.world.model.site_bodyid[a.head_site]].reshape(3, 3)[:, 0]
    cam = mujoco.MjvCamera()
    cam.lookat[:] = head
    cam.distance = 0.3
    # look at the face from in front of it
    cam.azimuth = float(np.degrees(np.arctan2(-forward[1], -forward[0])))
    cam.elevation = 0.0
    return cam


@pytest.fixture(scope="module")
def env():
    e = free_play_v0.parallel_env(n_agents=2, render_mode="rgb_array", render_size=(96, 96),
                                  info_text=True)   # the expressions by name
    e.reset(seed=0)
    yield e
    e.close()


def act(env, expressions):
    return {a: {"motors": np.zeros(44, np.float32), "expression": e}
            for a, e in zip(env.agents, expressions)}


def test_expression_changes_only_that_agents_face(env):
    env.reset(seed=0)
    cams = [face_camera(env, i) for i in range(2)]
    before = [env.render_rgb(c).astype(int) for c in cams]
    env.world.set_expression(0, 1)  # infant_0 smiles; the physics state is untouched
    after = [env.render_rgb(c).astype(int) for c in cams]
    changed0 = np.mean(np.any(before[0] != after[0], axis=2))
    changed1 = np.mean(np.any(before[1] != after[1], axis=2))
    assert changed0 > 0.01
    assert changed1 == 0.0


def test_expression_is_part_of_the_action_and_reported(env):
    env.reset(seed=0)
    _, _, _, _, infos = env.step(act(env, [3, 5]))
    assert infos["infant_0"]["expression"] == "surprised"
    assert infos["infant_1"]["expression"] == "angry"
    assert env.world.expression_of(0) == 3 and env.world.expression_of(1) == 5


def test_every_expression_looks_different(env):
    env.reset(seed=0)
    cam = face_camera(env, 1)
    images = []
    for e in range(7):
        env.world.set_expression(1, e)
        images.append(env.render_rgb(cam).astype(int))
    for i in range(7):
        for j in range(i + 1, 7):
            assert np.any(images[i] != images[j]), (i, j)
