"""A run in a spawned process of its own (``--jobs``) stops when the process that started it
ends: ``stop_with_parent`` sends it SIGTERM, which ``StopSignals`` turns into a clean stop
(issue 30, sixth session: two recipe runs killed through their parent trained on as orphans,
saving by path into a directory a new run had taken over)."""

import os
import signal
import threading
import time

import pytest

from mimo_social.train import comparison
from mimo_social.train.interrupt import StopSignals, stop_with_parent

pytestmark = pytest.mark.skipif(threading.current_thread() is not threading.main_thread(),
                                reason="signals reach the main thread only")


def _wait_for(flag, limit_s=120.0):
    # polls; the limit only ends a broken test, it is far above any wait a loaded machine needs
    t0 = time.monotonic()
    while not flag() and time.monotonic() - t0 < limit_s:
        time.sleep(0.01)
    return flag()


def test_the_run_is_signalled_once_its_parent_is_gone():
    calls = {"n": 0}
    parent = os.getppid()

    def getppid():          # the parent is there for three checks, then the process is orphaned
        calls["n"] += 1
        return parent if calls["n"] <= 3 else 1

    with StopSignals() as stop, stop_with_parent(parent, every_s=0.01, getppid=getppid) as w:
        assert _wait_for(lambda: stop.requested)
    assert stop.signum == signal.SIGTERM and w.signalled and calls["n"] == 4
    # StopSignals restored the handler it replaced
    assert signal.getsignal(signal.SIGTERM) is not stop.handle


def test_the_signal_arrives_where_the_main_thread_blocks_sigterm():
    # a library may block SIGTERM in the main thread (the full suite met one): the watcher
    # takes the signal in its own thread and the main thread's handler still runs
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
    try:
        with StopSignals() as stop, stop_with_parent(os.getppid(), every_s=0.01,
                                                     getppid=lambda: 1) as w:
            assert _wait_for(lambda: stop.requested)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)
    assert stop.signum == signal.SIGTERM and w.signalled


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
