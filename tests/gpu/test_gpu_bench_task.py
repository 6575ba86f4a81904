"""``mimo_social.bench.gpu`` with the task's logic (``with_task=True``): the steps time the
rewards, terminations and the autoresets of the finished worlds, and count those resets."""

from __future__ import annotations

import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social.bench import gpu  # noqa: E402
from mimo_social.envs import high_five_v0  # noqa: E402


def test_gpu_bench_with_the_task_counts_its_resets():
    """Episodes of 2 steps: one warm-up step and 3 timed ones end every world twice."""
    r = gpu.measure_one(2, 3, warmup=1, device="cpu", with_task=True,
                        make_env=lambda: high_five_v0.parallel_env(max_steps=2))
    assert r["task"] is True and r["resets"] == 4 and r["agents"] == 2
    assert r["agent_steps_per_s"] == pytest.approx(2 * 2 * 3 / r["seconds"])
