"""A run in a spawned process of its own (``--jobs``) stops when the process that started it
ends: ``stop_with_parent`` sends it SIGTERM, which ``StopSignals`` turns into a clean stop
(issue 30, sixth session: two recipe runs killed through their parent trained on as orphans,
saving by path into a directory a new run had taken over)."""

import os
import threading
import time

import pytest

from mimo_social.train import comparison
from mimo_social.train.interrupt import StopSignals, stop_with_parent

pytestmark = pytest.mark.skipif(threading.current_thread() is not threading.main_thread(),
                                reason="signals reach the main thread only")


_CHILD = """
import os, signal, sys, time
from mimo_social.train.interrupt import StopSignals, stop_with_parent
block = sys.argv[1] == "block"
if block:      # a library may block SIGTERM in the main thread: the watcher takes it itself
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
calls = {"n": 0}
parent = os.getppid()
def getppid():     # the parent is there for three checks, then the process is orphaned
    calls["n"] += 1
    return parent if calls["n"] <= 3 else 1
with StopSignals() as stop, stop_with_parent(parent, every_s=0.01, getppid=getppid) as w:
    t0 = time.monotonic()
    while not stop.requested and time.monotonic() - t0 < 120:
        time.sleep(0.01)
print("stopped", stop.signum == signal.SIGTERM, w.signalled, calls["n"])
"""


@pytest.mark.parametrize("mask", ["plain", "block"])
def test_the_run_is_signalled_once_its_parent_is_gone(mask):
    # in a fresh interpreter: inside the full suite's process the in-process version of this
    # test never saw its signal (with or without the watcher unblocking it; the cause in that
    # long session's signal state was not found), so the subject is tested where nothing else
    # has touched the process
    import subprocess
    import sys
    out = subprocess.run([sys.executable, "-c", _CHILD, mask], capture_output=True, text=True,
                         timeout=600)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["stopped", "True", "True", "4"], out.stdout + out.stderr


def test_no_signal_while_the_parent_lives_and_none_after_the_block():
    parent = os.getppid()
    with StopSignals() as stop:
        with stop_with_parent(parent, every_s=0.01) as w:
            time.sleep(0.2)
        assert not stop.requested and not w.signalled
        # orphaned, but the block is left before the first check: no signal, then or later
        with stop_with_parent(parent, every_s=5.0, getppid=lambda: 1) as gone:
            pass
        time.sleep(0.1)
        assert not stop.requested and not gone.signalled


def test_train_all_tells_each_spawned_run_who_its_parent_is(monkeypatch):
    seen = []

    class Pool:                              # the executor, without processes
        def __init__(self, *a, **k):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def map(self, fn, runs, parents):
            for kw, parent in zip(runs, parents):
                seen.append((kw["out"], parent))
                yield kw["out"], 0.0

    import concurrent.futures
    monkeypatch.setattr(concurrent.futures, "ProcessPoolExecutor", Pool)
    comparison.train_all([{"out": "a"}, {"out": "b"}], jobs=2, progress=False)
    assert seen == [("a", os.getpid()), ("b", os.getpid())]
