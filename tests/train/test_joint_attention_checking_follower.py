"""The checking follower (scripts/joint_attention_checking_follower.py): it watches the partner's
face, turns to the toy read there, and looks back; with the partner's head turn as the cue to
look back it does the task (issue 30's measure of the strategy a seeing learner could clone)."""

from __future__ import annotations

import functools

import numpy as np

from mimo_social.train.demonstrations import Demonstrator
from mimo_social.train.envs import make_env


def test_it_alternates_between_the_face_and_the_toy_and_succeeds(load_script):
    script = load_script("joint_attention_checking_follower")
    env = make_env("joint_attention", per_agent=[{"vision": {"width": 8, "height": 8}}, {}])
    teacher = Demonstrator(functools.partial(script.CheckingFollower, look_s=2.0,
                                             peripheral_deg=3.0), env)
    modes, on_face = [], []
    try:
        obs, info = env.reset(seed=1000)
        teacher.reset(env, "infant_0", np.random.default_rng(1000))
        core, done = teacher.core, False
        while not done:
            obs, _, term, trunc, info = env.step(teacher.act(env, "infant_0", obs))
            done = term or trunc
            modes.append(teacher.controller.mode)
            on_face.append(teacher.controller.on_face(core.world.data))
    finally:
        env.close()
    switches = sum(a != b for a, b in zip(modes, modes[1:]))
    assert switches >= 4                          # face -> toy -> face -> toy ...
    face = np.array(modes) == "face"
    assert np.mean(np.array(on_face)[face]) > 0.3     # watching: on the face, once turned there
    assert info["is_success"] and info["on_target_fraction"] >= 0.6
