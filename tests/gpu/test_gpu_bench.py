"""``mimo-social bench gpu`` and :mod:`mimo_social.bench.gpu` on Warp's CPU device: the
figures it reports, the device it names, and its refusals of bad options."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social import cli  # noqa: E402
from mimo_social.bench import gpu  # noqa: E402
from mimo_social.gpu import has_gpu  # noqa: E402


def test_gpu_bench_counts_agent_steps_of_every_world():
    out = gpu.measure([1, 3], steps=2, warmup=1, device="cpu")
    assert out["device"] == "cpu" and out["device_name"] == "no GPU: Warp's CPU device"
    assert [r["worlds"] for r in out["results"]] == [1, 3]
    for r in out["results"]:
        assert r["agents"] == 2 and r["steps"] == 2 and r["seconds"] > 0
        assert r["agent_steps_per_s"] == pytest.approx(r["worlds"] * 2 * 2 / r["seconds"])
        assert r["physics_steps_per_s"] == pytest.approx(2 * r["world_steps_per_s"])
    text = gpu.format_results(out)
    assert "device: cpu (no GPU: Warp's CPU device)" in text
    assert text.splitlines()[-1].startswith("no GPU: Warp's CPU device")
    assert all(r["touch"] for r in out["results"]) and "hand skins" in text


def test_gpu_bench_leaves_the_skins_out_when_told():
    out = gpu.measure([2], steps=1, warmup=0, device="cpu", touch=False)
    assert not out["results"][0]["touch"] and "no touch" in gpu.format_results(out)


@pytest.mark.skipif(has_gpu(), reason="checks the output without a GPU")
def test_gpu_bench_command_says_there_is_no_gpu_and_writes_its_json(tmp_path, capsys):
    path = tmp_path / "gpu.json"
    assert cli.main(["bench", "gpu", "--worlds", "2", "--steps", "1", "--warmup", "0",
                     "--json", str(path)]) == 0
    printed = capsys.readouterr().out
    assert "no GPU: Warp's CPU device" in printed and "agent-steps/s" in printed
    saved = json.loads(path.read_text())
    assert saved["device"] == "cpu" and saved["results"][0]["worlds"] == 2
    assert cli.main(["bench", "gpu", "--worlds", "2", "--steps", "1", "--warmup", "0",
                     "--no-touch"]) == 0
    assert "no touch" in capsys.readouterr().out


@pytest.mark.parametrize("argv, option", [(["--worlds", "0"], "--worlds"),
                                          (["--worlds", "1,x"], "--worlds"),
                                          (["--steps", "0"], "--steps"),
                                          (["--device", "tpu"], "--device")])
def test_gpu_bench_command_refuses_bad_options(argv, option, capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["bench", "gpu", *argv])
    assert e.value.code == 2
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert last.startswith("mimo-social bench gpu: error: argument") and option in last
