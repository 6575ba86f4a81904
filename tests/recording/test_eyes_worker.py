"""Eye images in recordings: encoded on a worker thread, logged at 25 Hz by default, every
logged frame in the file at the time and step it was taken (read back with Rerun's reader)."""

import threading
import warnings
import zlib

import numpy as np
import pyarrow as pa
import pytest
from rerun.chunk import RrdReader

from mimo_social.envs import free_play_v0
from mimo_social.recording import Recorder
from mimo_social.recording.eyes import EYE_BATCH_STEPS, EYE_LOG_HZ, eye_every_k_steps

N_STEPS = 41               # eyes logged at steps 0 (reset), 4, ..., 40: 11 times


def decode_png(blob: bytes) -> np.ndarray:
    """The pixels of an 8-bit RGB PNG whose rows use filter 0 (none) or 2 (up)."""
    assert blob[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, size = 8, b"", None
    while pos < len(blob):
        n, kind = int.from_bytes(blob[pos:pos + 4], "big"), blob[pos + 4:pos + 8]
        if kind == b"IHDR":
            size = (int.from_bytes(blob[pos + 8:pos + 12], "big"),
                    int.from_bytes(blob[pos + 12:pos + 16], "big"))
        elif kind == b"IDAT":
            idat += blob[pos + 8:pos + 8 + n]
        pos += 12 + n
    w, h = size
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(h, 1 + 3 * w)
    assert set(raw[:, 0].tolist()) <= {0, 2}
    out = np.zeros((h, 3 * w), np.uint8)
    for r in range(h):
        out[r] = raw[r, 1:] + (out[r - 1] if r and raw[r, 0] == 2 else 0)
    return out.reshape(h, w, 3)


def eye_rows(path, agent: str, eye: str) -> list[tuple[int, int, bytes]]:
    """(step, sim_time in ns, PNG bytes) of every eye image of ``agent``, by step."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # a file not closed has no footer
        chunks = RrdReader(path).stream().to_chunks()
    out = []
    for c in chunks:
        if c.entity_path != f"/agents/{agent}/eyes/{eye}" or c.is_static:
            continue
        b = c.to_record_batch()
        blobs = b.column("EncodedImage:blob").to_pylist()
        steps = b.column("step").to_pylist()
        times = b.column("sim_time").cast(pa.int64()).to_pylist()
        out += [(s, t, bytes(v[0])) for s, t, v in zip(steps, times, blobs) if v is not None]
    return sorted(out)


@pytest.fixture(scope="module")
def vision_env():
    try:
        env = free_play_v0.parallel_env(n_agents=2, vision={"width": 32, "height": 32})
        env.reset(seed=0)
    except Exception as exc:   # no GL here
        pytest.skip(f"vision does not build here: {type(exc).__name__}: {exc}")
    yield env
    env.close()


def run(env, path, n_steps=N_STEPS, flush_at=None, close=True, **options):
    """Record ``n_steps`` random steps; return the recorder, the observations per step and the
    names of the threads alive while recording."""
    rng = np.random.default_rng(1)
    obs, _ = env.reset(seed=0)
    seen = [obs]
    rec = Recorder(env, path, **options)
    rec.log_reset(obs)
    threads = set()
    for k in range(1, n_steps + 1):
        actions = {a: {"motors": rng.uniform(-1, 1, 44).astype(np.float32), "expression": 0}
                   for a in env.agents}
        obs, rewards, *_ = env.step(actions)
        rec.log_step(actions, rewards, obs)
        seen.append(obs)
        threads |= {t.name for t in threading.enumerate()}
        if k == flush_at:
            rec.flush()
    if close:
        rec.close()
    return rec, seen, threads


def test_default_rate_is_25_hz_and_every_frame_is_at_its_time(vision_env, tmp_path):
    env, path = vision_env, tmp_path / "eyes.rrd"
    assert EYE_LOG_HZ == 25.0 and eye_every_k_steps(env.dt, 1) == 4
    assert eye_every_k_steps(env.dt, 3) == 6 and eye_every_k_steps(env.dt, 1, 1) == 1
    rec, seen, threads = run(env, path)
    assert rec.eye_every_k_steps == 4 and EYE_BATCH_STEPS < 11
    # encoded off the main thread (the frames of EYE_BATCH_STEPS logged steps at a time)
    assert any(name.startswith("mimo-eye-encoder") for name in threads)
    assert not any(t.name.startswith("mimo-eye-encoder") for t in threading.enumerate())
    logged = list(range(0, N_STEPS + 1, 4))
    assert rec.eye_frames == 2 * len(logged) == 22
    for agent in env.possible_agents:
        for eye in ("left", "right"):
            got = eye_rows(path, agent, eye)
            assert [s for s, _, _ in got] == logged
            assert [t for _, t, _ in got] == [round(s * env.dt * 1e9) for s in logged]
            for step, _, blob in got:
                np.testing.assert_array_equal(decode_png(blob), seen[step][agent][f"eye_{eye}"])


def test_every_frame_on_request_and_the_callers_arrays_may_change(vision_env, tmp_path):
    env, path = vision_env, tmp_path / "all.rrd"
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=0)
    kept = []
    with Recorder(env, path, eye_every_k_steps=1) as rec:
        rec.log_reset(obs)
        for _ in range(5):
            actions = {a: {"motors": rng.uniform(-1, 1, 44).astype(np.float32),
                           "expression": 0} for a in env.agents}
            obs, rewards, *_ = env.step(actions)
            rec.log_step(actions, rewards, obs)
            kept.append(obs["infant_0"]["eye_left"].copy())
            obs["infant_0"]["eye_left"][:] = 7          # the recorder took its own copy
    got = eye_rows(path, "infant_0", "left")
    assert [s for s, _, _ in got] == list(range(6))
    for (step, _, blob), want in zip(got[1:], kept):
        np.testing.assert_array_equal(decode_png(blob), want)


def test_a_run_that_stops_without_close_keeps_the_flushed_frames(vision_env, tmp_path):
    env, path = vision_env, tmp_path / "crash.rrd"
    rec, _, _ = run(env, path, n_steps=10, flush_at=9, close=False, eye_every_k_steps=1)
    try:
        assert rec.flushed_step == 9
        got = eye_rows(path, "infant_1", "right")        # no footer: the run "crashed" here
        assert [s for s, _, _ in got] == list(range(10))
    finally:
        rec.close()
    assert [s for s, _, _ in eye_rows(path, "infant_1", "right")] == list(range(11))
