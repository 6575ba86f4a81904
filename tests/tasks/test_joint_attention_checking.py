"""The checking follower (``CheckingFollowController``, joint attention's second controller): it
reads the partner only while it watches the partner's face, turns to the toy read there and
looks back; with the partner's head turn as the cue to look back it does the task (issue 30:
the strategy a learner with eyes could clone, ``bc_kwargs`` ``demonstrator = "checking"``)."""

from __future__ import annotations

import functools

import mujoco
import numpy as np
import pytest

from mimo_social.core.kinematics import LookAt
from mimo_social.envs.catalog import entry
from mimo_social.tasks.joint_attention import CheckingFollowController, GazeFollowController
from mimo_social.train.demonstrations import Demonstrator
from mimo_social.train.envs import make_env
from mimo_social.util.checks import ConfigError

def play(seed: int, fov: float | None = None, **kwargs):
    """One episode of the checking follower (eyes of ``fov`` degrees, None: 60): per step its
    mode, its gaze's angle to the face, the toy read from the partner's gaze, and the last info."""
    vision = {"width": 8, "height": 8, "field_of_view": fov}
    env = make_env("joint_attention", per_agent=[{"vision": vision}, {}])
    teacher = Demonstrator(functools.partial(CheckingFollowController, **kwargs), env)
    modes, to_face, read = [], [], []
    try:
        obs, info = env.reset(seed=seed)
        teacher.reset(env, "infant_0", np.random.default_rng(seed))
        core, c, done = teacher.core, teacher.controller, False
        while not done:
            to_face.append(c.gaze_to_face_deg(core.world.data))
            read.append(c.read_now(core))
            obs, _, term, trunc, info = env.step(teacher.act(env, "infant_0", obs))
            done = term or trunc
            modes.append(c.mode)
    finally:
        env.close()
    return np.array(modes), np.array(to_face), read, info, float(core.dt)


def runs(modes: np.ndarray, mode: str) -> list[int]:
    """Lengths (steps) of each run of ``mode``, the last one (cut by the episode's end) left out."""
    edges = np.flatnonzero(np.diff((modes == mode).astype(int)))
    starts, ends = edges[::2] + 1, edges[1::2] + 1
    if modes[0] == mode:
        starts, ends = np.r_[0, edges[1::2] + 1], edges[::2] + 1
    return [int(e - s) for s, e in zip(starts, ends)]


def test_it_alternates_between_the_face_and_the_toy_and_succeeds():
    modes, to_face, _, info, _ = play(1000, look_s=2.0, peripheral_deg=3.0)
    switches = int(np.sum(modes[1:] != modes[:-1]))
    assert switches >= 4                          # face -> toy -> face -> toy ...
    assert np.mean(to_face[1:][modes[:-1] == "face"] <= 5.0) > 0.3   # watching, once there
    assert info["is_success"] and info["on_target_fraction"] >= 0.6


def test_it_turns_to_a_toy_only_after_reading_it_while_watching_the_face():
    modes, to_face, read, _, dt = play(1001, look_s=1.0, settle_s=0.05, peripheral_deg=0.0)
    turns = np.flatnonzero((modes[1:] == "toy") & (modes[:-1] == "face")) + 1
    assert len(turns) >= 2
    settle = int(np.ceil(0.05 / dt - 1e-9))
    for t in turns:                 # the settle steps before: watching, the same toy read
        assert all(to_face[t - k] <= 5.0 for k in range(settle))
        assert len({read[t - k] for k in range(settle + 1)}) == 1 and read[t] is not None


def test_on_a_timer_alone_each_look_at_a_toy_lasts_look_s_and_a_head_turn_ends_it_early():
    timer, *_ , dt = play(1002, look_s=1.0, peripheral_deg=0.0)
    looks = runs(timer, "toy")
    assert looks and all(n == round(1.0 / dt) for n in looks)
    cued, *_ = play(1002, look_s=1.0, peripheral_deg=3.0, head_turn_seen="anywhere")
    assert min(runs(cued, "toy")) < round(1.0 / dt)      # back at the partner's head turn
    # seen only in view: out of a 60-degree eye's view while it looks at a toy, as the timer
    unseen, *_ = play(1002, look_s=1.0, peripheral_deg=3.0)
    assert np.array_equal(unseen, timer)
    wide, *_ = play(1002, fov=150.0, look_s=1.0, peripheral_deg=3.0)
    assert min(runs(wide, "toy")) < round(1.0 / dt)      # a 150-degree eye sees it


def test_the_partner_s_head_is_in_view_on_the_face_and_out_of_a_60_degree_view_on_a_toy():
    env = make_env("joint_attention", per_agent=[{"vision": {"width": 8, "height": 8}}, {}])
    c = CheckingFollowController()
    seen = {}
    try:
        env.reset(seed=1000)
        core = env.unwrapped.parallel.unwrapped
        w = core.world
        m, d = w.model, w.data
        look, start = LookAt(w, 0), d.qpos.copy()
        for fov in (60.0, 150.0):
            m.cam_fovy[list(w.agents[0].eye_cameras)] = fov     # as field_of_view sets it
            c.reset(core, "infant_0", np.random.default_rng(0))
            for name, kind, obj in [("face", "site", int(w.agents[1].head_site))] + [
                    (f"toy {k}", "body", int(t)) for k, t in enumerate(core.task.toy_bodies)]:
                d.qpos[:] = start
                d.qpos[look.qpos] = look(m, d, kind, obj)
                mujoco.mj_forward(m, d)
                seen[fov, name] = c.head_in_view(d)
    finally:
        env.close()
    toys = [k for k in seen if k[1] != "face"]
    assert seen[60.0, "face"] and seen[150.0, "face"]
    assert not any(seen[k] for k in toys if k[0] == 60.0), seen
    assert any(seen[k] for k in toys if k[0] == 150.0), seen


def test_the_checking_follower_is_the_task_s_named_demonstrator():
    e = entry("joint_attention")
    assert e.demonstrator_names() == ("scripted", "checking", "sensed")
    assert e.controller_class("checking") is CheckingFollowController
    assert e.controller_class(None) is e.controller_class("scripted") is GazeFollowController
    with pytest.raises(ValueError,
                       match=r"demonstrator='watch'.*\['scripted', 'checking', 'sensed'\]"):
        e.controller_class("watch")
    with pytest.raises(ValueError, match="demonstrator='checking'.*'scripted'"):
        entry("reach").controller_class("checking")
    with pytest.raises(ValueError, match="none"):
        entry("free_play").controller_class(None)


@pytest.mark.parametrize("kwargs, words", [
    ({"look_s": 0}, ["look_s=0", "0.05 to 60"]),
    ({"settle_s": -0.1}, ["settle_s=-0.1", "0 to 10"]),
    ({"on_face_deg": float("nan")}, ["on_face_deg=nan", "0.5 to 45"]),
    ({"peripheral_deg": 100}, ["peripheral_deg=100", "0 to 90", "no early look back"]),
    ({"look_s": True}, ["look_s=True"]),
    ({"head_turn_seen": "near"}, ["head_turn_seen='near'", "in_view", "anywhere"]),
])
def test_bad_settings_are_refused_with_the_setting_named(kwargs, words):
    with pytest.raises(ConfigError) as info:
        CheckingFollowController(**kwargs)
    for w in words:
        assert w in str(info.value), (w, str(info.value))
    assert "CheckingFollowController" in str(info.value)


def test_acting_before_reset_is_refused():
    with pytest.raises(RuntimeError, match="before reset"):
        CheckingFollowController().act(None, "infant_0", None)
