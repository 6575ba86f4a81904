"""``mimo-social bench gpu --with-task``: the command times the task's logic and autoresets
(``measure(..., with_task=True)``), says so, and counts the episodes that ended."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social import cli  # noqa: E402
from mimo_social.bench import gpu  # noqa: E402


@pytest.mark.parametrize("with_task", [False, True])
def test_gpu_bench_command_with_task_times_the_tasks_logic(with_task, tmp_path, capsys,
                                                           monkeypatch):
    seen = []
    real = gpu.measure

    def spy(*a, **k):
        seen.append(k.get("with_task"))
        return real(*a, **k)

    monkeypatch.setattr(gpu, "measure", spy)
    path = tmp_path / "gpu.json"
    argv = ["bench", "gpu", "--worlds", "2", "--steps", "1", "--warmup", "0", "--device",
            "cpu", "--json", str(path)] + (["--with-task"] if with_task else [])
    assert cli.main(argv) == 0
    assert seen == [with_task]
    printed = capsys.readouterr().out
    saved = json.loads(path.read_text())
    assert saved["results"][0]["task"] is with_task
    assert ("with the task's logic and resets" in printed) is with_task
    assert ("episodes ended" in printed) is with_task
