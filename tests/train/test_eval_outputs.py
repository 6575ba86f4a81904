"""``mimo-social eval`` outputs: every path and the MP4 encoder are tried before anything is
loaded, and a video that fails while the episodes run leaves the recording, the frames and the
numbers written (the command says what failed, exit code 1)."""

from __future__ import annotations

import importlib.util
import json
import sys

import numpy as np
import pytest
import torch

from mimo_social import cli
from mimo_social.train import TrainInputError, VideoUnavailable, evaluate, evaluation, train

torch.set_num_threads(1)

needs_encoder = pytest.mark.skipif(importlib.util.find_spec("imageio_ffmpeg") is None,
                                   reason="imageio's ffmpeg plugin is not installed")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("runs") / "reach_ppo"
    train("reach", "ppo", 64, 0, out, eval_every=64, eval_episodes=1, checkpoint_every=0,
          progress=False, env_kwargs={"max_steps": 12},
          algo_kwargs={"n_steps": 64, "batch_size": 32, "n_epochs": 1})
    return out


@pytest.fixture
def loads(monkeypatch):
    """Every model load and env made by evaluate, recorded (none may happen before a check)."""
    seen = []
    real_class, real_env = evaluation.algo_class, evaluation.make_env
    monkeypatch.setattr(evaluation, "algo_class", lambda *a: seen.append("model") or
                        real_class(*a))
    monkeypatch.setattr(evaluation, "make_env", lambda *a, **k: seen.append("env") or
                        real_env(*a, **k))
    return seen


def _no_encoder(monkeypatch):
    monkeypatch.setitem(sys.modules, "imageio", None)          # import imageio: ImportError
    monkeypatch.setitem(sys.modules, "imageio.v2", None)
    monkeypatch.setattr(evaluation.shutil, "which", lambda name: None)


def test_without_an_encoder_eval_stops_before_loading_and_writes_nothing(run, tmp_path,
                                                                          loads, monkeypatch,
                                                                          capsys):
    _no_encoder(monkeypatch)
    rrd, mp4 = tmp_path / "ep.rrd", tmp_path / "ep.mp4"
    assert cli.main(["eval", str(run), "--episodes", "1", "--record", str(rrd),
                     "--video", str(mp4), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"mimo-social eval: error: cannot write {mp4}: "
                                               "no MP4 encoder on this machine")
    assert "--frames DIR" in err[0] and "probe" not in err[0]
    assert loads == []                                  # nothing loaded, nothing run
    assert not rrd.exists() and not mp4.exists()
    assert not (run / "eval_results.json").exists()


@pytest.mark.parametrize("name, where, says", [
    ("record", "file/x.rrd", "is a file, not a folder"),
    ("video", "folder", "is a folder; allowed: a file to write"),
    ("frames", "file", "is a file; allowed: a folder to write into"),
])
def test_every_output_path_is_checked_before_loading(name, where, says, run, tmp_path, loads):
    (tmp_path / "file").write_text("x")
    (tmp_path / "folder").mkdir()
    with pytest.raises(TrainInputError, match=f"^{name} {tmp_path / where}: .*{says}"):
        evaluate(run, episodes=1, **{name: tmp_path / where})
    assert loads == []


@needs_encoder
def test_the_encoder_is_tried_on_a_test_video_before_loading(tmp_path, monkeypatch):
    import imageio.v2 as imageio

    class Broken:
        def append_data(self, frame):
            raise OSError("the encoder died")

        def close(self):
            pass
    monkeypatch.setattr(imageio, "get_writer", lambda *a, **k: Broken())
    with pytest.raises(VideoUnavailable, match=r"cannot write .*v\.mp4: the MP4 encoder failed on "
                                               r"a test video \(OSError: the encoder died\)"):
        evaluation.check_outputs(video=tmp_path / "v.mp4")
    assert list(tmp_path.iterdir()) == []


@needs_encoder
def test_a_video_that_fails_midway_leaves_the_recording_frames_and_numbers(run, tmp_path,
                                                                           monkeypatch, capsys):
    import imageio.v2 as imageio
    real = imageio.get_writer
    frames_given = []

    class DiesAfterThree:
        """The episode's writer: three frames, then a full disk (the test video passes)."""

        def __init__(self, *a, **k):
            self.inner = real(*a, **k)

        def append_data(self, frame):
            frames_given.append(frame.shape)
            if len(frames_given) > 3:
                raise OSError(28, "No space left on device")
            self.inner.append_data(frame)

        def close(self):
            self.inner.close()
    monkeypatch.setattr(imageio, "get_writer",
                        lambda path, **k: (real if "probe" in str(path) else DiesAfterThree)(
                            path, **k))
    rrd, mp4, pngs = tmp_path / "ep.rrd", tmp_path / "ep.mp4", tmp_path / "frames"
    code = cli.main(["eval", str(run), "--episodes", "2", "--deterministic", "--record",
                     str(rrd), "--video", str(mp4), "--frames", str(pngs), "--frame-every", "4",
                     "--no-progress"])
    out, err = capsys.readouterr()
    assert code == 1
    assert err.strip() == (f"mimo-social eval: error: --video: cannot write {mp4}: OSError: "
                           "[Errno 28] No space left on device (episode 0, step 12); the other "
                           "outputs were written")
    assert rrd.stat().st_size > 0 and f"wrote {rrd}" in out and f"wrote {mp4}" not in out
    assert "2 episodes, mean action" in out
    res = json.loads((run / "eval_results.json").read_text())
    assert res["episodes"] == 2 and "video" not in res and res["video_error"].startswith(
        f"cannot write {mp4}: OSError")
    assert res["record"] == str(rrd)
    # the frames went on after the video stopped: both episodes', every 4th step
    names = sorted(p.name for p in pngs.glob("*.png"))
    assert names[0] == "ep000_00000.png" and any(n.startswith("ep001_") for n in names)
    assert len(frames_given) == 4 and all(np.prod(s) > 16 * 16 * 3 for s in frames_given)


@needs_encoder
def test_eval_writes_the_video_and_the_recording(run, tmp_path, capsys):
    import imageio.v2 as imageio
    rrd, mp4 = tmp_path / "ep.rrd", tmp_path / "ep.mp4"
    assert cli.main(["eval", str(run), "--episodes", "1", "--deterministic", "--record",
                     str(rrd), "--video", str(mp4), "--frame-every", "3", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert f"wrote {rrd}" in out and f"wrote {mp4}" in out
    assert rrd.stat().st_size > 0
    reader = imageio.get_reader(str(mp4))
    try:
        n = sum(1 for _ in reader)
    finally:
        reader.close()
    assert n == 5                                     # steps 0, 3, 6, 9, 12 of 12
