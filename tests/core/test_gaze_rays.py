"""``gaze_rays``: an agent's line of sight from its two eye cameras, the one computation the
joint-attention task, its followers and the partners' cues share."""

from __future__ import annotations

import mujoco
import numpy as np

from mimo_social.body.sight import gaze_rays
from mimo_social.core.kinematics import LookAt
from mimo_social.envs import joint_attention_v0


def test_the_line_of_sight_ends_on_the_point_the_eyes_fixate_and_batches_over_agents():
    env = joint_attention_v0.parallel_env(per_agent=[{"vision": {"width": 8, "height": 8}}] * 2)
    try:
        env.reset(seed=3)
        w = env.unwrapped.world
        m, d = w.model, w.data
        toys = env.unwrapped.task.toy_bodies
        for i, toy in ((0, toys[0]), (1, toys[-1])):
            look = LookAt(w, i)                      # every head and eye joint of agent i
            d.qpos[look.qpos] = look(m, d, "body", int(toy))
        mujoco.mj_forward(m, d)
        cams = np.array([a.eye_cameras for a in w.agents])
        origin, direction = gaze_rays(d, cams)
        assert origin.shape == direction.shape == (2, 3)
        np.testing.assert_allclose(np.linalg.norm(direction, axis=1), 1.0, atol=1e-12)
        for i, toy in ((0, toys[0]), (1, toys[-1])):
            to = d.xpos[toy] - origin[i]
            off = np.degrees(np.arccos(min(1.0, direction[i] @ to / np.linalg.norm(to))))
            assert off < 3.0, (i, off)                    # on the fixated toy
            one = gaze_rays(d, cams[i])                   # one agent: (3,) each
            np.testing.assert_allclose(one[0], origin[i])
            np.testing.assert_allclose(one[1], direction[i])
        to_other = d.xpos[toys[-1]] - origin[0]
        assert np.degrees(np.arccos(direction[0] @ to_other / np.linalg.norm(to_other))) > 10
    finally:
        env.close()
