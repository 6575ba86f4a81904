"""Stopping a run cleanly on Ctrl-C (SIGINT) or SIGTERM.

:class:`StopSignals` is a context manager: while it is active, the first SIGINT or SIGTERM only
sets :attr:`StopSignals.signum`; the training loops check :attr:`StopSignals.requested` between
two env steps (an SB3 callback's ``_on_step`` returning False ends ``learn()``; the independent
mode's stepping thread raises :class:`Interrupted`) and the run then saves its model, its CSVs,
its curve and ``config.json`` with ``"interrupted": true``. A second signal raises
``KeyboardInterrupt`` at once. The previous handlers are restored on exit. Signals reach the main
thread only: installed from another thread, the context manager installs nothing (and the run
cannot be stopped this way).

The command line exits with :func:`exit_code` (130 for SIGINT, 143 for SIGTERM).

:class:`stop_with_parent` is for a run in a spawned process of its own (``--jobs``): if the
process that started it ends (killed by SIGTERM, SIGKILL or a crash, none of which reach the
child), the run is sent SIGTERM and saves and stops as above, instead of training on unseen and
writing into directories its parent's user may have moved or reused.
"""

from __future__ import annotations

import os
import signal
import threading

__all__ = ["StopSignals", "Interrupted", "exit_code", "workers_ignore_sigint",
           "stop_with_parent"]


class Interrupted(Exception):
    """Raised in a training loop that cannot return False to stop (the independent mode)."""


def exit_code(signum: int) -> int:
    """The shell's exit code of a process ended by ``signum`` (128 + its number)."""
    return 128 + int(signum)


class StopSignals:
    """SIGINT and SIGTERM set a flag instead of killing the run (module docstring)."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self):
        self.signum: int | None = None
        self.previous: dict[int, object] = {}

    @property
    def requested(self) -> bool:
        return self.signum is not None

    def handle(self, signum, frame) -> None:
        if self.signum is not None:
            raise KeyboardInterrupt(f"signal {signum} received twice")
        self.signum = int(signum)

    def __enter__(self) -> "StopSignals":
        if threading.current_thread() is threading.main_thread():
            for s in self.SIGNALS:
                self.previous[s] = signal.getsignal(s)
                signal.signal(s, self.handle)
        return self

    def __exit__(self, *exc) -> None:
        for s, handler in self.previous.items():
            signal.signal(s, handler if handler is not None else signal.SIG_DFL)
        self.previous = {}


class workers_ignore_sigint:  # noqa: N801 (a context manager used like a function)
    """Processes started inside ``with workers_ignore_sigint():`` ignore SIGINT (an ignored
    signal is inherited through ``spawn`` and Python keeps it ignored), so that Ctrl-C in a
    terminal, which reaches the whole process group, stops the run through its parent instead of
    killing its env workers under it."""

    def __enter__(self):
        self.previous = None
        if threading.current_thread() is threading.main_thread():
            self.previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
        return self

    def __exit__(self, *exc) -> None:
        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)


class stop_with_parent:  # noqa: N801 (a context manager used like a function)
    """While inside ``with stop_with_parent(parent):``, a daemon thread checks every
    ``every_s`` seconds whether this process's parent is still ``parent`` (a pid; an orphan is
    handed to another); once it is not, it sends this process SIGTERM (once), which a
    :class:`StopSignals` in the main thread turns into a clean stop. ``getppid``: the function
    that names the parent (``os.getppid``; a test can give another)."""

    def __init__(self, parent: int, every_s: float = 1.0, getppid=os.getppid):
        self.parent, self.every_s, self.getppid = int(parent), float(every_s), getppid
        self.done = threading.Event()
        self.signalled = False

    def _watch(self) -> None:
        # this thread takes SIGTERM even where the main thread blocks it (a library may), so
        # the signal is not left pending: the main thread's Python handler runs either way
        if hasattr(signal, "pthread_sigmask"):
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})
        while not self.done.wait(self.every_s):
            if self.getppid() != self.parent:
                self.signalled = True
                os.kill(os.getpid(), signal.SIGTERM)
                return

    def __enter__(self) -> "stop_with_parent":
        threading.Thread(target=self._watch, name="stop_with_parent", daemon=True).start()
        return self

    def __exit__(self, *exc) -> None:
        self.done.set()
