"""Recordings cut off mid-write (`mimo_social.recording.torn`): whatever byte a kill stops the
writer at, the whole frames before it read back with Rerun's own reader, as a gapless prefix of
the steps; the replay command summarises and salvages such files and refuses what is no
recording."""

import warnings

import numpy as np
import pytest
from rerun.chunk import RrdReader

from mimo_social import cli
from mimo_social.envs import free_play_v0
from mimo_social.recording import Recorder
from mimo_social.recording.summary import summarize
from mimo_social.recording.torn import readable_copy, salvage, whole_length

STEPS = 30


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A closed recording of 2 infants, flushed every 4 steps (many frames to cut through)."""
    path = tmp_path_factory.mktemp("torn") / "full.rrd"
    env = free_play_v0.parallel_env(n_agents=2)
    obs, _ = env.reset(seed=0)
    rng = np.random.default_rng(0)
    with Recorder(env, path, flush_every_s=0.08) as rec:
        rec.log_reset(obs)
        for _ in range(STEPS):
            actions = {a: {"motors": rng.uniform(-1, 1, 44).astype(np.float32), "expression": 1}
                       for a in env.agents}
            obs, rewards, *_ = env.step(actions)
            rec.log_step(actions, rewards, obs)
    return path


def head_steps(path) -> list[int]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")              # no footer
        chunks = RrdReader(path).stream().to_chunks()
    steps = set()
    for chunk in chunks:
        if chunk.entity_path != "/world/infant_0/head":
            continue
        batch = chunk.to_record_batch()
        if "step" in batch.schema.names:
            steps.update(batch.column("step").to_pylist())
    return sorted(steps)


def test_a_closed_file_is_whole(recording):
    size = recording.stat().st_size
    assert whole_length(recording) == size
    with readable_copy(recording) as (path, torn):
        assert path == recording and torn == 0
    assert head_steps(recording) == list(range(STEPS + 1))


def test_every_cut_reads_back_as_a_gapless_prefix(recording, tmp_path):
    data = recording.read_bytes()
    cuts = sorted(set(np.linspace(len(data) // 3, len(data) - 1, 40).astype(int))
                  | {len(data) - 1, len(data) - 20, len(data) - 40})   # in the footer as well
    cut_file, out = tmp_path / "cut.rrd", tmp_path / "whole.rrd"
    last, lengths, refused = [], [], 0
    for cut in cuts:
        cut_file.write_bytes(data[:cut])
        try:                                           # why this module exists
            head_steps(cut_file)
        except RuntimeError as e:
            assert "exceeds file size" in str(e)
            refused += 1
        dropped = salvage(cut_file, out)
        lengths.append(out.stat().st_size)
        assert dropped == cut - out.stat().st_size >= 0
        steps = head_steps(out)
        assert steps == list(range(len(steps))), cut       # gapless from step 0
        assert len(steps) >= len(last), cut                 # grows with the cut
        last = steps
        summary = summarize(cut_file)
        assert not summary["complete"] and summary["torn_bytes"] == dropped
        assert summary["steps"] == len(steps)
    assert lengths == sorted(lengths)
    assert refused > len(cuts) // 2                 # Rerun's reader refuses most cuts as they are
    assert len(last) >= STEPS - 4                 # the cut in the footer keeps nearly all rows


def test_the_replay_command_summarises_salvages_and_refuses(recording, tmp_path, capsys,
                                                              monkeypatch):
    data = recording.read_bytes()
    torn_file = tmp_path / "killed.rrd"
    torn_file.write_bytes(data[:len(data) * 2 // 3])
    torn = torn_file.stat().st_size - whole_length(torn_file)
    assert torn > 0

    assert cli.main(["replay", str(torn_file), "--summary"]) == 0
    out = capsys.readouterr().out
    assert "complete: no" in out and f"the last {torn} bytes" in out

    monkeypatch.setenv("DISPLAY", ":99")
    assert cli.main(["replay", str(torn_file)]) == 1           # Rerun would refuse it
    assert "--salvage" in capsys.readouterr().out

    assert cli.main(["replay", str(torn_file), "--salvage"]) == 0
    out = capsys.readouterr().out
    written = tmp_path / "killed.salvaged.rrd"
    assert str(written) in out and f"left out the last {torn} bytes" in out
    assert written.stat().st_size == torn_file.stat().st_size - torn
    assert len(head_steps(written)) > 0

    assert cli.main(["replay", str(torn_file), "--salvage", str(torn_file)]) == 2
    assert "the recording itself" in capsys.readouterr().err

    text = tmp_path / "notes.rrd"
    text.write_text("not a recording")
    assert cli.main(["replay", str(text), "--summary"]) == 2
    assert "not a Rerun recording" in capsys.readouterr().err
