"""``mimo-social view`` (issue 32): one line and exit code 2 without a display, argparse's errors
for bad arguments, and the real-time stepping loop run headless with a stand-in viewer."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mimo_social import cli
from mimo_social.experiments import viewer

ROOT = Path(__file__).resolve().parents[2]


def run_cli(args, **env_changes):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.update(env_changes)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    return subprocess.run([sys.executable, "-m", "mimo_social.cli", "view", *args], env=env,
                          cwd=ROOT, capture_output=True, text=True)


def test_without_a_display_one_line_says_why_and_what_to_do_exit_2():
    proc = run_cli(["reach"])
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("mimo-social view: error: no display")
    assert "DISPLAY" in lines[0] and "mimo-social demo" in lines[0]
    assert "Traceback" not in proc.stderr and proc.stdout == ""


def test_a_display_that_cannot_be_opened_is_one_line_exit_2():
    pytest.importorskip("glfw")
    proc = run_cli(["reach", "--steps", "3"], DISPLAY=":987")
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("mimo-social view: error: "), proc.stderr
    assert "mimo-social demo" in lines[0] and "Traceback" not in proc.stderr


@pytest.mark.parametrize("args,words", [
    (["nosuchtask"], ["argument task: invalid choice: 'nosuchtask'", "'reach'", "'still_face'"]),
    (["reach", "--age", "40"], ["argument --age: 40 not allowed", "months from 0 to 33"]),
    (["reach", "--age", "-1"], ["argument --age: -1 not allowed", "months from 0 to 33"]),
    (["reach", "--age", "old"], ["argument --age: 'old' is not a number", "months from 0"]),
    (["reach", "--control", "smart"], ["argument --control: invalid choice: 'smart'",
                                       "'scripted', 'zero', 'random'"]),
    (["reach", "--steps", "0"], ["argument --steps: 0 not allowed", "a positive integer"]),
    (["reach", "--seed", "-3"], ["argument --seed: -3 not allowed"]),
])
def test_bad_arguments_are_argparse_errors_naming_the_value_and_what_is_allowed(args, words,
                                                                               capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.main(["view", *args])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    line = err.strip().splitlines()[-1]
    assert line.startswith("mimo-social view: error: ")
    for w in words:
        assert w in line, (w, line)


class FakeViewer:
    """What the loop needs of ``mujoco.viewer.launch_passive``'s handle, counting its calls."""

    def __init__(self, env, runs_for=None):
        self.env, self.runs_for = env, runs_for
        self.syncs, self.locks, self.times = 0, 0, []

    def is_running(self):
        return self.runs_for is None or self.syncs <= self.runs_for

    def sync(self):
        self.syncs += 1
        self.times.append(float(self.env.unwrapped.world.data.time))

    @contextlib.contextmanager
    def lock(self):
        self.locks += 1
        yield


def test_scripted_control_advances_the_state_and_resets_at_episode_end():
    setup = viewer.view_env("reach", "scripted", max_steps=5)
    env = setup.env
    data = env.unwrapped.world.data
    handle = FakeViewer(env)
    out = viewer.run_viewer(setup, handle, seed=3, steps=12, realtime=False)
    assert (out.steps, handle.locks, handle.syncs) == (12, 12, 13)   # + the sync at the start
    assert out.episodes == 3 and out.seeds == [3, 4, 5]              # reset after steps 5, 10
    dt = env.unwrapped.dt
    # time advances one control step a sync and starts again after each reset
    assert handle.times[:5] == pytest.approx([0, dt, 2 * dt, 3 * dt, 4 * dt])
    assert handle.times[5] == pytest.approx(0) and handle.times[10] == pytest.approx(0)
    assert handle.times[12] == pytest.approx(2 * dt)
    # the viewer shows the env's own model and data throughout (reset keeps them)
    assert env.unwrapped.world.data is data
    # the scripted controller moves the arm: the state differs from the zero-action run
    zero = viewer.view_env("reach", "zero", max_steps=5)
    viewer.run_viewer(zero, FakeViewer(zero.env), seed=3, steps=4, realtime=False)
    scripted = viewer.view_env("reach", "scripted", max_steps=5)
    viewer.run_viewer(scripted, FakeViewer(scripted.env), seed=3, steps=4, realtime=False)
    q0, q1 = zero.env.unwrapped.world.data.qpos, scripted.env.unwrapped.world.data.qpos
    assert np.abs(q0 - q1).max() > 1e-4
    for s in (setup, zero, scripted):
        s.env.close()


def test_the_loop_stops_when_the_window_closes_and_keeps_real_time():
    setup = viewer.view_env("free_play", "random", n_agents=1)
    handle = FakeViewer(setup.env, runs_for=4)
    now, slept = [0.0], []

    def clock():
        now[0] += 0.001          # each look at the clock: 1 ms of work
        return now[0]

    out = viewer.run_viewer(setup, handle, seed=0, sleep=slept.append, clock=clock)
    assert out.steps == 4 and out.episodes == 1
    dt = setup.env.unwrapped.dt
    assert slept == pytest.approx([dt - 0.001] * 4)
    setup.env.close()


def test_social_tasks_script_the_partner_and_age_only_the_infants():
    setup = viewer.view_env("still_face", "scripted", age_months=6)
    assert setup.env.possible_agents == ["infant_0"]          # the caregiver is scripted
    assert [c.age for c in setup.env.unwrapped.agent_configs] == [6.0, None]
    out = viewer.run_viewer(setup, FakeViewer(setup.env), steps=3, realtime=False)
    assert out.steps == 3
    setup.env.close()
    both = viewer.view_env("still_face", "zero", age_months=3)
    assert both.env.possible_agents == ["infant_0", "caregiver_0"]
    assert set(both.policies) == {"infant_0", "caregiver_0"}
    assert [c.age for c in both.env.unwrapped.agent_configs] == [3.0, None]
    both.env.close()


def test_a_task_without_a_controller_falls_back_to_zero_actions_with_a_note():
    setup = viewer.view_env("free_play", "scripted", n_agents=1)
    assert setup.notes == ["free_play has no scripted controller: its agents take zero actions"]
    setup.env.close()
    with pytest.raises(ValueError, match="control 'fast' not allowed; allowed: scripted, zero"):
        viewer.view_env("reach", "fast")


def test_open_viewer_without_a_display_raises_viewer_unavailable(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(viewer.ViewerUnavailable, match="no display .* 'mimo-social demo'"):
        viewer.open_viewer(None, None)
    assert viewer.display_problem({"WAYLAND_DISPLAY": "wayland-0"}) is None


def test_frame_agents_points_the_free_camera_at_the_agents():
    import mujoco

    setup = viewer.view_env("still_face", "zero")
    handle = FakeViewer(setup.env)
    handle.cam = mujoco.MjvCamera()
    viewer.frame_agents(handle, setup.env)
    world = setup.env.unwrapped.world
    roots = np.array([world.data.xpos[a.root_body] for a in world.agents])
    assert np.allclose(handle.cam.lookat, roots.mean(axis=0)) and handle.locks == 1
    assert handle.cam.distance > 1.5
    setup.env.close()
