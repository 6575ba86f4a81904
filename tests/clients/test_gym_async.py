"""Gymnasium's subprocess vector env on the envs with eyes, as most clients make it: the default
start method (``fork`` on Linux), after the parent process rendered. The workers make their own
GL context (on a new EGL display) and see what the parent sees.

Each case runs in its own Python process (a fork from pytest's process would copy whatever
threads and GL state the other tests left there)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from mimo_social.envs.catalog import CATALOG

pytestmark = pytest.mark.skipif(os.environ.get("MUJOCO_GL") != "egl",
                                reason="workers forked after rendering need MUJOCO_GL=egl")

#: the Gymnasium ids whose learner has eyes by default
VISION_IDS = ("mimo_social/Mirror-v0", "mimo_social/JointAttention-v0",
              "mimo_social/Contingency-v0", "mimo_social/StillFace-v0",
              "mimo_social/Imitation-v0")

SCRIPT = textwrap.dedent("""
    import sys
    import gymnasium as gym
    import numpy as np
    import mimo_social  # noqa: F401  (registers the ids)

    for gym_id in sys.argv[1:]:
        kw = {"vision": {"width": 16, "height": 16}, "max_steps": 6}
        parent = gym.make(gym_id, render_mode="rgb_array", render_size=(16, 16), **kw)
        obs, _ = parent.reset(seed=3)
        assert parent.render().shape == (16, 16, 3)     # the parent has used OpenGL
        # the most common client's default: AsyncVectorEnv(env_fns), start method not given
        venv = gym.vector.AsyncVectorEnv([lambda: gym.make(gym_id, **kw)] * 2)
        try:
            vobs, _ = venv.reset(seed=[3, 4])
            assert np.array_equal(vobs["eye_left"][0], obs["eye_left"]), gym_id
            for _ in range(3):
                vobs, *_ = venv.step(venv.action_space.sample())
            assert vobs["eye_right"].shape == (2, *obs["eye_right"].shape)
        finally:
            venv.close()
        made = gym.make_vec(gym_id, num_envs=2, vectorization_mode="async", **kw)
        try:
            mobs, _ = made.reset(seed=3)
            assert np.array_equal(mobs["eye_left"][0], obs["eye_left"]), gym_id
            made.step(made.action_space.sample())
        finally:
            made.close()
        parent.close()
        print("OK", gym_id, flush=True)
""")


def _run(tmp_path, ids):
    script = tmp_path / "async_vision.py"
    script.write_text(SCRIPT)
    root = str(Path(__file__).resolve().parents[2])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        p for p in (root, os.environ.get("PYTHONPATH")) if p)}
    proc = subprocess.Popen([sys.executable, str(script), *ids], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True, env=env)
    try:   # a guard against a hang only (forked GL used to hang): generous
        out, _ = proc.communicate(timeout=180 * len(ids))
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        pytest.fail(f"the async vector env hung:\n{out[-3000:]}")
    assert proc.returncode == 0, out[-3000:]
    assert [line.split()[1] for line in out.splitlines() if line.startswith("OK ")] == list(ids)


def test_vision_ids_are_the_catalogues_envs_with_eyes():
    import gymnasium as gym
    import mimo_social  # noqa: F401
    with_eyes = []
    for e in CATALOG:
        env = gym.make(e.gym_id)
        if "eye_left" in env.observation_space.spaces:
            with_eyes.append(e.gym_id)
        env.close()
    assert tuple(with_eyes) == VISION_IDS


def test_default_async_vector_env_after_the_parent_rendered(tmp_path):
    _run(tmp_path, VISION_IDS[:1])


@pytest.mark.slow
def test_default_async_vector_env_on_every_env_with_eyes(tmp_path):
    _run(tmp_path, VISION_IDS)
