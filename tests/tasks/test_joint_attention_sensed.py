"""The sensed follower (``SensedFollowController``, joint attention's third controller): it reads
the partner's gaze only while its ``faces`` sense sees the partner's face, keeps the toy read while
the face is out of view, looks back after ``look_back_s``; the demonstrator of the recipe's
recurrent learner (``bc_kwargs`` ``demonstrator = "sensed"``)."""

from __future__ import annotations

import numpy as np
import pytest

from mimo_social.core.episodes import run_episodes
from mimo_social.envs import joint_attention_v0
from mimo_social.envs.catalog import entry
from mimo_social.tasks.joint_attention import SensedFollowController


def play(faces, episodes=3, **kw):
    env = joint_attention_v0.scripted_env(per_agent=[{"vision": False, "faces": faces}, {}])
    looked = []
    eps = run_episodes(env, {"infant_0": SensedFollowController(**kw)}, episodes, 1000,
                       on_step=lambda e, o, r, te, tr, i: looked.append(i["infant_0"]["looked_at"]))
    return [e.last_infos["infant_0"] for e in eps], looked


def test_with_a_160_degree_face_perception_it_follows():
    infos, _ = play({"field_of_view": 160})
    assert all(i["is_success"] for i in infos), infos
    assert min(i["on_target_fraction"] for i in infos) >= 0.6


def test_a_face_it_never_sees_it_never_follows():
    # turn_deg 0: no face is ever turned exactly at it, so the partner's gaze is never read
    infos, looked = play({"turn_deg": 0.0}, episodes=1)
    assert not infos[0]["is_success"]
    assert set(looked) == {-1.0}, set(looked)        # it watches the face, never a toy


def test_it_looks_back_only_after_the_face_was_gone_for_look_back_s():
    never, _ = play({"field_of_view": 160}, episodes=3, look_back_s=60.0)
    soon, _ = play({"field_of_view": 160}, episodes=3, look_back_s=0.5)
    # without looking back it stays on a toy once the face is out of view: it follows less
    assert np.mean([i["on_target_fraction"] for i in never]) < np.mean(
        [i["on_target_fraction"] for i in soon])


def test_it_is_the_task_s_named_demonstrator_and_refuses_bad_settings():
    assert entry("joint_attention").controller_class("sensed") is SensedFollowController
    with pytest.raises(ValueError, match="look_back_s=-1"):
        SensedFollowController(look_back_s=-1)
