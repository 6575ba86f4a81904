"""Recording resources and faults: N successive recordings (``Recorder``, ``RecordingParallelEnv``)
cost a constant number of OS threads and file descriptors and no memory that grows with N, each
file complete with its own recording id; a path that cannot be written fails at creation, a disk
that fills up during a recording fails at the next flush, both naming the file and the cause (and
the process still exits); the Gymnasium adapter (and ``gym.make``'s wrappers around it) is
accepted."""

import inspect
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import rerun_bindings

from mimo_social.envs import free_play_v0
from mimo_social.recording import (
    Recorder,
    RecordingFileError,
    RecordingParallelEnv,
    record_episode,
    summarize,
)
from mimo_social.util.checks import ConfigError

pytestmark = pytest.mark.skipif(not Path("/proc/self/task").is_dir(),
                                reason="counts threads and descriptors through Linux's /proc")

N_RECORDINGS = 20
STEPS = 5
ROOT = Path(__file__).resolve().parents[2]


def os_threads() -> int:
    """OS threads of this process (Rerun's are native: ``threading`` does not see them)."""
    return len(os.listdir("/proc/self/task"))


def open_fds() -> int:
    return len(os.listdir("/proc/self/fd"))


def rss_mb() -> float:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    raise AssertionError("no VmRSS")


@pytest.fixture(scope="module")
def env():
    e = free_play_v0.parallel_env(n_agents=2, max_steps=STEPS)
    yield e
    e.close()


def zero(env):
    """The zero action of every agent (motors at rest, neutral face)."""
    out = {}
    for a in env.possible_agents:
        space = env.action_space(a)
        motors = np.zeros(space["motors"].shape, np.float32)
        out[a] = {"motors": motors, "expression": 0}
    return out


def check_files(paths, ids=None):
    """Every file is complete (footer), holds STEPS + 1 pose rows and its own recording id."""
    seen = []
    for path in paths:
        assert rerun_bindings.check_for_rrd_footer(str(path)), path
        s = summarize(path)
        assert s["complete"] and s["pose_rows"] == STEPS + 1, (path, s["pose_rows"])
        assert len(s["recordings"]) == 1
        seen.append(s["recordings"][0]["recording_id"])
    assert len(set(seen)) == len(seen), "two files share a recording id"
    if ids is not None:
        assert seen == ids


def assert_bounded(threads, fds, rss):
    # the first recordings may start Rerun's process-wide threads (runtime, allocator); after
    # that, a recording must give back all it took
    assert max(threads[2:]) <= threads[1], f"OS threads after each recording: {threads}"
    assert max(fds[2:]) <= fds[1], f"open file descriptors after each recording: {fds}"
    # leaked streams kept ~4 MB each (60 MB here); what is left is the allocator's sawtooth
    # (~1 MB up per recording, ~10 MB down now and then)
    growth = float(np.median(rss[-5:]) - np.median(rss[2:7]))
    assert growth < 15, f"RSS (MB) after each recording: {rss}"


def test_successive_recorders_keep_threads_descriptors_and_memory_bounded(env, tmp_path):
    a = zero(env)
    threads, fds, rss, ids, paths = [], [], [], [], []
    for i in range(N_RECORDINGS):
        path = tmp_path / f"r{i:02d}.rrd"
        with Recorder(env, path) as rec:
            obs, _ = env.reset(seed=i)
            rec.log_reset(obs)
            while env.agents:
                obs, rewards, *_ = env.step(a)
                rec.log_step(a, rewards, obs)
        ids.append(rec.recording_id)
        paths.append(path)
        threads.append(os_threads())
        fds.append(open_fds())
        rss.append(round(rss_mb(), 1))
    print(f"after each recording: threads {threads}, fds {fds}, RSS (MB) {rss}")
    assert_bounded(threads, fds, rss)
    check_files(paths, ids)


def test_recording_wrapper_every_episode_keeps_threads_descriptors_and_memory_bounded(tmp_path):
    env = RecordingParallelEnv(free_play_v0.parallel_env(n_agents=2, max_steps=STEPS),
                               tmp_path / "ep{episode:03d}.rrd", every_k_episodes=1)
    a = zero(env)
    threads, fds, rss = [], [], []
    for i in range(N_RECORDINGS):
        env.reset(seed=i)
        while env.agents:
            env.step(a)
        threads.append(os_threads())
        fds.append(open_fds())
        rss.append(round(rss_mb(), 1))
    env.close()
    assert_bounded(threads, fds, rss)
    assert len(env.paths) == N_RECORDINGS
    check_files(env.paths)


@pytest.mark.slow
def test_many_recorded_episodes_do_not_grow_memory(tmp_path):
    """200 recorded episodes of 100 steps (20k steps): RSS flat after the first few."""
    env = RecordingParallelEnv(free_play_v0.parallel_env(n_agents=2, max_steps=100),
                               tmp_path / "ep{episode:03d}.rrd", every_k_episodes=1)
    for k, ag in enumerate(env.possible_agents):
        env.action_space(ag).seed(k)
    rss = []
    for i in range(200):
        env.reset(seed=i)
        while env.agents:
            env.step({ag: env.action_space(ag).sample() for ag in env.agents})
        if i % 20 == 19:
            rss.append(round(rss_mb(), 1))
        os.remove(env.paths[-1])
    env.close()
    print(f"RSS (MB) every 20 recorded episodes of 100 steps: {rss}")
    assert rss[-1] - rss[1] < 10, f"RSS (MB) every 20 episodes: {rss}"


def test_closing_a_recorder_keeps_the_users_own_rerun_recording(env, tmp_path):
    """The cleanup that frees closed streams (Rerun's, as ``rr.init`` runs it) must leave the
    global recording the user made alone."""
    import rerun as rr

    rr.init("user_app", recording_id="user-recording")
    rr.save(tmp_path / "user.rrd")
    try:
        a = zero(env)
        for i in range(2):
            with Recorder(env, tmp_path / f"r{i}.rrd") as rec:
                obs, _ = env.reset(seed=i)
                rec.log_reset(obs)
                env.step(a)
        user = rr.get_global_data_recording()
        assert user is not None and user.get_recording_id() == "user-recording"
        rr.log("/note", rr.TextLog("still here"))
    finally:
        rr.disconnect()
        rr.set_global_data_recording(None)
    assert "/note" in summarize(tmp_path / "user.rrd")["entities"]


# -- paths that cannot be written ----------------------------------------------------------------

def _unwritable_cases(tmp_path):
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    cases = [(tmp_path, "is a directory"),
             (a_file / "x.rrd", "is a file, not a folder"),
             (Path("/proc/mimo_social_nowhere/x.rrd"), "No such file or directory")]
    if os.path.exists("/dev/full"):
        cases.append((Path("/dev/full"), "No space left on device"))   # every write: ENOSPC
    if os.geteuid() != 0:
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o500)
        cases.append((locked / "x.rrd", "Permission denied"))
    return cases


def test_a_path_that_cannot_be_written_fails_at_creation_naming_file_and_cause(env, tmp_path):
    threads = os_threads()
    for path, cause in _unwritable_cases(tmp_path):
        with pytest.raises(RecordingFileError) as info:
            Recorder(env, path)
        text = str(info.value)
        assert str(path) in text and cause in text, text
        assert isinstance(info.value, OSError) and info.value.filename == str(path)
    assert os_threads() <= threads


_FILL_SCRIPT = """
import json, os, resource, signal, sys
import numpy as np
if sys.argv[2] == "fsize":            # the file-size limit stands in for a disk that fills up
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (2_000_000, resource.RLIM_INFINITY))
from mimo_social.envs import free_play_v0
from mimo_social.recording import Recorder, record_episode, summarize
from mimo_social.recording.streams import stuck_streams
flush_each_step = sys.argv[3] == "1"      # a flush racing the writer's failure: Rerun's stream
env = free_play_v0.parallel_env(n_agents=2)  # stays blocked (it is kept, the process exits)
a = {ag: {"motors": np.zeros(env.action_space(ag)["motors"].shape, np.float32),
          "expression": 0} for ag in env.possible_agents}
out = {"error": None}
rec = Recorder(env, sys.argv[1], flush_every_s=0.05)
obs, _ = env.reset(seed=0)
rec.log_reset(obs)
try:
    for step in range(20000):
        if not env.agents:
            env.reset()
        obs, rewards, *_ = env.step(a)
        rec.log_step(a, rewards, obs)
        if flush_each_step:
            rec.flush()
    rec.close()
except OSError as e:
    out = {"error": str(e), "type": type(e).__name__, "errno": e.errno,
           "flushed_step": rec.flushed_step}
try:
    rec.log_step(a)
except OSError as e:
    out["again"] = str(e)
rec.close()                                       # quiet once failed
out["stuck"] = stuck_streams()
after = record_episode(env, sys.argv[4], seed=0, max_steps=3)   # elsewhere, small: fits
out["after_rows"] = summarize(after["path"])["pose_rows"]
print(json.dumps(out))
"""


def _run_fill(path: Path, how: str, wrap=(), flush_each_step=False) -> dict:
    proc = subprocess.run([*wrap, sys.executable, "-c", _FILL_SCRIPT, str(path), how,
                           str(int(flush_each_step)), str(path.parent.parent / "after.rrd")],
                          capture_output=True, text=True, timeout=240, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _check_fill(out: dict, path: Path, cause: str):
    assert out["error"] is not None, "the recording never failed"
    assert out["type"] == "RecordingFileError"
    assert str(path) in out["error"] and cause in out["error"], out["error"]
    assert "prematurely" not in out["error"]
    assert out["again"] == out["error"]
    assert out["flushed_step"] > 0
    assert out["after_rows"] == 4, "a recording after the failure does not work"


@pytest.mark.parametrize("flush_each_step", [False, True], ids=["at-interval", "every-step"])
def test_a_file_that_cannot_grow_fails_at_the_next_flush_naming_file_and_cause(
        tmp_path, flush_each_step):
    """The process's file-size limit makes writes fail part-way like a full disk; the recorder
    raises (no hang, no 'thread shut down prematurely'), later calls say the same, a new
    recording works and the process exits (with a flush after every step, Rerun's stream is
    mostly left blocked, sometimes with a flush per interval too, and Rerun's own exit hook would
    wait for it forever)."""
    path = tmp_path / "limited" / "big.rrd"     # the next recording goes to tmp_path
    out = _run_fill(path, "fsize", flush_each_step=flush_each_step)
    _check_fill(out, path, "File too large")


def _unshare_tmpfs() -> bool:
    if not shutil.which("unshare"):
        return False
    r = subprocess.run(["unshare", "-rm", "sh", "-c", "mount -t tmpfs -o size=64k tmpfs /mnt"],
                       capture_output=True, timeout=30)
    return r.returncode == 0


@pytest.mark.skipif(not _unshare_tmpfs(),
                    reason="cannot mount a small tmpfs (no user namespaces here)")
def test_a_full_disk_fails_at_the_next_flush_naming_file_and_cause(tmp_path):
    """A 2 MB file system of its own (a user namespace: no root needed) fills up mid-recording."""
    mount = tmp_path / "disk"
    mount.mkdir()
    path = mount / "full.rrd"
    wrap = ["unshare", "-rm", "sh", "-c",
            f'mount -t tmpfs -o size=2m tmpfs "{mount}" && exec "$0" "$@"']
    out = _run_fill(path, "disk", wrap)
    _check_fill(out, path, "No space left on device")


# -- the Gymnasium adapter, documented settings, bad seeds ----------------------------------------

def test_the_gymnasium_adapter_from_gym_make_is_recorded(tmp_path):
    for i, genv in enumerate([gym.make("mimo_social/Reach-v0"),
                              gym.wrappers.TimeLimit(gym.make("mimo_social/Reach-v0"), 100)]):
        path = tmp_path / f"gym{i}.rrd"
        sent = []
        with Recorder(genv, path) as rec:
            obs, _ = genv.reset(seed=0)
            rec.log_reset(obs)
            for _ in range(STEPS):
                action = genv.action_space.sample()
                obs, reward, *_ = genv.step(action)
                rec.log_step(action, reward, obs)
                sent.append(reward)
        s = summarize(path)
        assert s["pose_rows"] == STEPS + 1 and s["agents"] == [genv.unwrapped.agent]
        info = record_episode(genv, tmp_path / f"episode{i}.rrd", seed=1, max_steps=STEPS)
        assert info["steps"] == STEPS and summarize(info["path"])["pose_rows"] == STEPS + 1
        genv.close()
    with pytest.raises(TypeError, match="MimoParallelEnv"):
        Recorder(gym.make("CartPole-v1"), tmp_path / "cartpole.rrd")


def test_readme_states_the_default_flush_interval():
    default = inspect.signature(Recorder).parameters["flush_every_s"].default
    readme = (ROOT / "README.md").read_text()
    said = re.findall(r"flushed every (\S+) simulated second", readme)
    assert said and all(float(x) == default for x in said), (said, default)


@pytest.mark.parametrize("seed", [-1, 1.5, "0", True])
def test_record_episode_names_a_bad_seed(env, tmp_path, seed):
    with pytest.raises(ConfigError, match="seed"):
        record_episode(env, tmp_path / "x.rrd", seed=seed)
    assert not (tmp_path / "x.rrd").exists()
