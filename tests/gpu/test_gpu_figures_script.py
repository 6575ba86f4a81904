"""``scripts/gpu_figures.sh``, the GPU figures in one run, checked in its quick form on Warp's CPU
device: every part runs, writes its JSON (which names the device: no GPU here) or its run
folder, and the script exits 0."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

ROOT = Path(__file__).resolve().parents[2]


def test_the_gpu_figures_script_runs_every_part(tmp_path):
    env = dict(os.environ, QUICK="1", PATH=f"{Path(sys.executable).parent}:{os.environ['PATH']}")
    done = subprocess.run(["bash", str(ROOT / "scripts" / "gpu_figures.sh"), str(tmp_path)],
                          env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    status = (tmp_path / "status.txt").read_text().split("\n")
    assert [s.split(":")[0] for s in status if s] == [
        "bench", "bench_no_touch", "bench_eyes64", "bench_task", "bench_task_bank",
        "ppo_high_five"]
    for name, key, value in (("bench", "touch", True), ("bench_no_touch", "touch", False),
                             ("bench_eyes64", "eyes", 64), ("bench_task", "task", True),
                             ("bench_task_bank", "reset_bank", 2)):
        out = json.loads((tmp_path / f"{name}.json").read_text())
        assert out["device_name"] and all(r[key] == value for r in out["results"]), name
    assert len((tmp_path / "ppo_high_five" / "progress.csv").read_text().splitlines()) >= 2
