"""Threads, fork and the process's GL context.

The eyes and ``env.render()`` share one GL context per process. It is current only while a
renderer draws (under a process-wide lock), so an env made and reset on one thread can be
stepped and rendered on another. A process forked after OpenGL was used makes its own context
on a new EGL display (the inherited one hangs): a new env and an env inherited from the parent
render there the same images as the parent; where no new display can be had it raises a
RuntimeError naming the cause and the fix, within a bounded time.
"""

from __future__ import annotations

import gc
import os
import signal
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import numpy as np
import pytest

from mimo_social.envs import free_play_v0
from mimo_social.render import eye_renderer

SIZE = 24


def _env():
    return free_play_v0.parallel_env(n_agents=2, vision={"width": SIZE, "height": SIZE},
                                     max_steps=50, render_mode="rgb_array",
                                     render_size=(48, 64))


def _actions(env, n, seed=0):
    for k, a in enumerate(env.possible_agents):
        env.action_space(a).seed(seed * 100 + k)
    return [{a: env.action_space(a).sample() for a in env.possible_agents} for _ in range(n)]


def _run(env, actions):
    """Step through ``actions``; the eye images of every step and a final scene image."""
    eyes = []
    for act in actions:
        obs, *_ = env.step(act)
        eyes.append({a: (obs[a]["eye_left"].copy(), obs[a]["eye_right"].copy()) for a in obs})
    return eyes, env.render()


def _in_thread(fn, *args):
    box = {}

    def target():
        try:
            box["value"] = fn(*args)
        except BaseException as e:  # noqa: BLE001 - handed to the test thread
            box["error"] = e

    t = threading.Thread(target=target)
    t.start()
    t.join(120)
    assert not t.is_alive(), "the rendering thread hung"
    if "error" in box:
        raise box["error"]
    return box["value"]


def _same(a, b):
    eyes_a, scene_a = a
    eyes_b, scene_b = b
    assert len(eyes_a) == len(eyes_b)
    for sa, sb in zip(eyes_a, eyes_b):
        for agent in sa:
            for x, y in zip(sa[agent], sb[agent]):
                np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(scene_a, scene_b)


def test_env_reset_on_main_thread_steps_and_renders_on_another_thread():
    ref = _env()
    ref.reset(seed=3)
    acts = _actions(ref, 6)
    expected = _run(ref, acts)            # everything on the main thread
    first = expected[0][0]
    assert all(img.std() > 0 for pair in first.values() for img in pair)   # eyes see things

    env = _env()
    env.reset(seed=3)                     # first render on the main thread
    got = _in_thread(_run, env, acts[:3])  # then steps and env.render() on another one
    more = _run(env, acts[3:])            # and back on the main thread
    _same((got[0] + more[0], more[1]), expected)
    ref.close()
    env.close()


def test_two_threads_render_two_envs_at_once_as_one_thread_does():
    envs = [_env(), _env()]
    for k, env in enumerate(envs):
        env.reset(seed=k)
    acts = [_actions(env, 5, seed=k) for k, env in enumerate(envs)]
    results = [None, None]

    def work(k):
        results[k] = _run(envs[k], acts[k])

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert results[0] is not None and results[1] is not None
    for k in range(2):
        ref = _env()
        ref.reset(seed=k)
        _same(results[k], _run(ref, acts[k]))
        ref.close()
        envs[k].close()


def test_a_renderer_dropped_without_close_frees_its_gl_objects(monkeypatch):
    gc.collect()
    freed = []
    real = eye_renderer._free_now
    monkeypatch.setattr(eye_renderer, "_free_now", lambda con: (freed.append(con), real(con)))
    env = _env()
    env.reset(seed=0)
    env.render()
    del env
    gc.collect()
    assert len(freed) == 2   # the eyes' MjrContext and env.render()'s


FORK_SCRIPT = textwrap.dedent("""
    import multiprocessing as mp
    import queue
    import sys
    import numpy as np
    from mimo_social.envs import free_play_v0
    from mimo_social.render import eye_renderer

    def make():
        return free_play_v0.parallel_env(n_agents=1, vision={"width": 24, "height": 24},
                                         max_steps=20, render_mode="rgb_array",
                                         render_size=(24, 32))

    def child(q, env):
        try:
            env = env or make()
            obs, _ = env.reset(seed=1)
            q.put(("ok", obs[env.agents[0]]["eye_left"], env.render()))
        except BaseException as e:
            q.put(("error", f"{type(e).__name__}: {e}", None))

    def fork_and_step(env=None):
        ctx = mp.get_context("fork")
        q = ctx.Queue()
        p = ctx.Process(target=child, args=(q, env))
        p.start()
        try:
            return q.get(timeout=60)
        except queue.Empty:
            return ("hang", None, None)
        finally:
            p.join(10)
            if p.is_alive():
                p.kill()

    if __name__ == "__main__":
        if sys.argv[1] == "no-new-display":   # as with OSMesa: no new display after a fork
            eye_renderer.fresh_display_after_fork = lambda: False
        # forked before this process used OpenGL: the child renders, and right
        before = fork_and_step()
        assert before[0] == "ok", before
        env = make()
        obs, _ = env.reset(seed=1)
        frame = env.render()
        assert np.array_equal(before[1], obs[env.agents[0]]["eye_left"])
        print("BEFORE-OK")
        # forked after: a new env and the inherited one
        for inherited in (None, env):
            kind, eye, child_frame = fork_and_step(inherited)
            if kind == "ok":
                assert np.array_equal(eye, obs[env.agents[0]]["eye_left"])
                assert np.array_equal(child_frame, frame)
                print("AFTER-OK")
            else:
                print("AFTER", kind, eye)
        env.reset(seed=2)                     # the parent still renders
        print("PARENT-OK")
""")


def _run_script(path, *args, guard=240):
    """Run a script in its own session; a hang (beyond ``guard`` seconds) fails the test."""
    root = str(Path(__file__).resolve().parents[2])      # this checkout's package
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        p for p in (root, os.environ.get("PYTHONPATH")) if p)}
    proc = subprocess.Popen([sys.executable, str(path), *args], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True, env=env)
    try:
        out, _ = proc.communicate(timeout=guard)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        pytest.fail(f"{path.name} {' '.join(args)} hung:\n{out[-3000:]}")
    return proc.returncode, out


needs_egl = pytest.mark.skipif(os.environ.get("MUJOCO_GL") != "egl",
                               reason="a new display after fork needs MUJOCO_GL=egl")


@needs_egl
def test_fork_after_rendering_renders_in_the_child(tmp_path):
    script = tmp_path / "fork_gl.py"
    script.write_text(FORK_SCRIPT)
    code, out = _run_script(script, "egl")
    assert code == 0, out[-3000:]
    assert "BEFORE-OK" in out and "PARENT-OK" in out
    assert out.count("AFTER-OK") == 2, out[-3000:]   # a new env and the inherited one


def test_fork_without_a_new_display_is_a_clear_error_not_a_hang(tmp_path):
    script = tmp_path / "fork_gl.py"
    script.write_text(FORK_SCRIPT)
    code, out = _run_script(script, "no-new-display")
    assert code == 0, out[-3000:]
    assert "BEFORE-OK" in out
    errors = [line for line in out.splitlines() if line.startswith("AFTER")]
    assert len(errors) == 2, out[-3000:]
    for line in errors:
        assert "RuntimeError" in line and "forked from process" in line, line
        assert "spawn" in line and "forkserver" in line


SUPERSUIT_SCRIPT = textwrap.dedent("""
    import supersuit as ss
    from mimo_social.envs import free_play_v0

    env = free_play_v0.parallel_env(n_agents=2, vision={"width": 24, "height": 24},
                                    max_steps=20)
    obs, _ = env.reset(seed=0)          # the parent renders the eyes, then forks its workers
    venv = ss.concat_vec_envs_v1(ss.pettingzoo_env_to_vec_env_v1(env), 2, num_cpus=2,
                                 base_class="gymnasium")
    try:
        out, _ = venv.reset(seed=0)
        print("RESET-OK", sorted(out))
    except RuntimeError as e:
        print("ERROR", e)
    finally:
        venv.close()
""")


@needs_egl
def test_supersuit_forked_workers_after_the_parent_rendered_render(tmp_path):
    pytest.importorskip("supersuit")
    script = tmp_path / "ss_fork.py"
    script.write_text(SUPERSUIT_SCRIPT)
    code, out = _run_script(script, guard=120)
    assert "RESET-OK" in out, out[-3000:]
