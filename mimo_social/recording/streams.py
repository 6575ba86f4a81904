"""Rerun file streams that give their threads back when closed, and write errors that say which
file and why.

Rerun 0.41 keeps every ``RecordingStream`` (two OS threads each: its batcher and its forwarder,
plus ``file_writer`` while the file is open) in a process-wide registry. A stream nobody
references any more is only moved to an "orphaned" list there; its threads and buffers are freed
by ``flush_and_cleanup_orphaned_recordings`` (what ``rr.init`` calls). A default blueprint given
to ``save`` is logged through a second stream whose memory sink refers back to it, so that one is
never freed at all. :class:`FileStream` logs the blueprint through its own stream and disconnects
it right after, and :meth:`FileStream.close` finishes the file, drops the stream and runs the
cleanup (keeping the user's global recording), so N recordings cost no more threads than one.

Write failures: the path is checked when the stream opens (a directory, a parent that cannot be
made, a file that cannot be created or written: :class:`RecordingFileError` at once). When the
disk fills up (or another write fails) later, Rerun's writer thread logs the error and stops, and
a flush then either fails or waits forever; :meth:`FileStream.wait_written` waits in short slices,
watches the writer thread and, when it is gone, raises :class:`RecordingFileError` naming the file
and the cause (found by writing a probe file next to it). A stream whose flush was cut off by the
failure stays blocked inside Rerun for good: it is kept (dropping it would block) and, from then
on, orphaned streams are no longer cleaned up in this process and Rerun's exit hook (which would
wait on it) is replaced by one that finishes the recordings still open.
"""

from __future__ import annotations

import atexit
import errno
import os
import resource
import tempfile
import threading
import time
import uuid
import weakref
from pathlib import Path

import rerun as rr
import rerun.blueprint as rrb
import rerun_bindings as bindings

__all__ = ["FileStream", "RecordingFileError", "WRITE_TIMEOUT_S", "stuck_streams"]

#: how long :meth:`FileStream.wait_written` waits for a live writer thread before giving up (s)
WRITE_TIMEOUT_S = 120.0
_SLICE_S = 0.5             # one wait; between two, the writer thread is looked at

_LOCK = threading.RLock()
_STUCK: list[rr.RecordingStream] = []          # blocked inside Rerun for good: never dropped
_OPEN: weakref.WeakSet = weakref.WeakSet()     # FileStreams not closed yet


class RecordingFileError(OSError):
    """A recording file that cannot be created or written (full disk, no permission, ...);
    ``errno``, ``strerror`` (the cause) and ``filename`` are set where known."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else super().__str__()


class _KeptStream(rr.RecordingStream):
    """A stuck stream, kept: dropping one (at exit too) would disconnect it, which blocks."""

    def __del__(self) -> None:
        pass


def stuck_streams() -> int:
    """How many streams of this process are blocked inside Rerun after a write failure (0: the
    streams of closed recordings are freed)."""
    return len(_STUCK)


# -- diagnosis ------------------------------------------------------------------------------------

def _writer_threads() -> set[int] | None:
    """The ids of Rerun's ``file_writer`` threads of this process (None: no /proc to ask)."""
    try:
        tids = os.listdir("/proc/self/task")
    except OSError:
        return None
    out = set()
    for tid in tids:
        try:
            with open(f"/proc/self/task/{tid}/comm") as f:
                if f.read().strip() == "file_writer":
                    out.add(int(tid))
        except OSError:
            pass
    return out


def _size(path: Path) -> int | None:
    try:
        return path.stat().st_size
    except OSError:
        return None


def write_problem(path: Path) -> tuple[int | None, str]:
    """Why writing ``path`` fails now, as (errno, text), found by writing a probe file next to
    it; (None, "") when nothing is found."""
    size = _size(path)
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    if size is not None and soft != resource.RLIM_INFINITY and size >= soft * 0.9:
        return errno.EFBIG, (f"File too large: the file ({size} bytes) reached this process's "
                             f"file-size limit (ulimit -f) of {soft} bytes")
    try:
        with tempfile.TemporaryFile(dir=path.parent) as f:
            f.write(b"\0" * 65536)
            f.flush()
            os.fsync(f.fileno())
    except OSError as e:
        return e.errno, (f"{e.strerror or e} (a probe file in {str(path.parent)!r} cannot be "
                         "written either)")
    try:
        st = os.statvfs(path.parent)
        if st.f_bavail == 0:
            return errno.ENOSPC, "No space left on device (0 bytes free)"
    except OSError:
        pass
    return None, ""


def _error(path: Path, what: str, code: int | None, cause: str) -> RecordingFileError:
    err = RecordingFileError(f"recording {str(path)!r}: {what}: {cause}")
    err.errno, err.strerror, err.filename = code, cause, str(path)
    return err


def _check_path(path: Path) -> None:
    """A clear error now if ``path`` cannot be a recording file (made or written)."""
    if path.is_dir():
        raise _error(path, "cannot create the file", errno.EISDIR, "it is a directory")
    for folder in reversed(path.parents):
        if folder.exists() and not folder.is_dir():
            raise _error(path, f"cannot create its folder {str(path.parent)!r}", errno.ENOTDIR,
                         f"{str(folder)!r} is a file, not a folder")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise _error(path, f"cannot create its folder {str(path.parent)!r}", e.errno,
                     e.strerror or str(e)) from None
    try:
        with open(path, "wb") as f:   # Rerun truncates it again
            f.write(b"\0" * 4096)
            f.flush()
            f.truncate(0)
    except OSError as e:
        raise _error(path, "cannot write the file", e.errno, e.strerror or str(e)) from None


# -- exit: Rerun's own hook would wait forever on a stuck stream ----------------------------------

def _finish_open_streams() -> None:
    with _LOCK:
        streams = list(_OPEN)
    for stream in streams:
        try:
            stream.close()
        except Exception:   # noqa: BLE001  (at exit: finish what can be finished)
            pass
    for get in (rr.get_global_data_recording, rr.get_thread_local_data_recording):
        rec = get()             # the user's (never one of ours, so never a stuck one)
        if rec is not None:
            try:
                bindings.finalize_deferred_sinks(recording=rec.to_native())
            except Exception:  # noqa: BLE001
                pass


def _mark_stuck(rec: rr.RecordingStream) -> None:
    rec.__class__ = _KeptStream
    with _LOCK:
        if not _STUCK:
            rr.unregister_shutdown()
            atexit.register(_finish_open_streams)
        _STUCK.append(rec)


def release_dropped() -> None:
    """Free the threads and buffers of every Rerun stream of this process that nobody refers to
    (blocking flush of the live ones first: Rerun's own cleanup). The global recording set by
    the user (``rr.init``) stays. Nothing is done once a stream is stuck, or while an open one
    has lost its writer (that would block)."""
    with _LOCK:
        if _STUCK or any(stream.writer_alive() is False for stream in list(_OPEN)):
            return             # a writer died under an open recording: its flush could block
        previous = rr.get_global_data_recording()
        bindings.flush_and_cleanup_orphaned_recordings()
        if previous is not None:
            rr.set_global_data_recording(previous)


# -- the stream ---------------------------------------------------------------------------------

class FileStream:
    """One ``.rrd`` file written by its own Rerun recording stream (:attr:`rec`, a new recording
    id) with an optional default blueprint; see the module docstring."""

    def __init__(self, path: str | Path, application_id: str,
                 default_blueprint: rrb.Blueprint | None = None,
                 write_timeout_s: float = WRITE_TIMEOUT_S):
        self.path = Path(path)
        self.write_timeout_s = float(write_timeout_s)
        self.failed: RecordingFileError | None = None
        _check_path(self.path)
        self.rec = rr.RecordingStream(application_id, recording_id=uuid.uuid4())
        self.rec.set_log_tick_enabled(False)
        self.rec.set_log_time_enabled(False)
        storage, bp_stream = None, None
        if default_blueprint is not None:
            bp_stream = rr.RecordingStream._from_native(bindings.new_blueprint(
                application_id=application_id, make_default=False, make_thread_default=False,
                default_enabled=True))
            bp_stream.set_time("blueprint", sequence=0)
            default_blueprint.to_blueprint()._log_to_stream(bp_stream)
            storage = bp_stream.memory_recording().storage
        with _LOCK:
            before = _writer_threads()
            try:
                bindings.save(path=str(self.path), default_blueprint=storage,
                              recording=self.rec.to_native(), write_footer=True)
                failure = None
            except RuntimeError as e:
                failure = e
            if bp_stream is not None:
                bp_stream.disconnect()     # its memory sink refers back to it: cut that
                del storage, bp_stream
            after = _writer_threads()
        if failure is not None:
            code, cause = write_problem(self.path)
            self._drop()
            raise _error(self.path, "cannot write the file", code, cause or str(failure))
        new = (after - before) if before is not None and after is not None else set()
        self._writer = next(iter(new)) if len(new) == 1 else None
        with _LOCK:
            _OPEN.add(self)

    def writer_alive(self) -> bool | None:
        """Whether Rerun's file-writer thread of this stream still runs (``None``: unknown, when
        the thread could not be told apart or the threads cannot be listed)."""
        if self._writer is None:
            return None
        threads = _writer_threads()
        return None if threads is None else self._writer in threads

    def wait_written(self) -> None:
        """Block until everything sent is in the file; :class:`RecordingFileError` when the file
        cannot be written any more (or nothing got written for ``write_timeout_s``)."""
        if self.failed is not None:
            raise self.failed
        deadline = time.monotonic() + self.write_timeout_s
        while True:
            try:
                self.rec.flush(timeout_sec=_SLICE_S)
                return
            except RuntimeError as e:
                message = str(e)
            timed_out = "timed out" in message
            alive = self.writer_alive()
            if timed_out and alive is not False and time.monotonic() < deadline:
                continue
            self._fail(message, stuck=timed_out)

    def _fail(self, message: str, stuck: bool) -> None:
        code, cause = write_problem(self.path)
        if not cause:
            alive = self.writer_alive()
            cause = (f"nothing got written for {self.write_timeout_s:g} s" if alive
                     else "Rerun's file writer stopped (its error is on stderr)")
            cause += f" ({message})"
        size = _size(self.path)
        self.failed = _error(self.path, f"writing failed after {size} bytes", code, cause)
        with _LOCK:
            _OPEN.discard(self)
        if stuck:   # Rerun's forwarding thread waits for the dead writer: leave it alone
            _mark_stuck(self.rec)
            self.rec = None
        else:
            try:
                self.rec.disconnect()
            finally:
                self._drop()
        raise self.failed

    def close(self) -> None:
        """Wait until everything is written, write the footer and free the stream's threads;
        :class:`RecordingFileError` when that fails."""
        if self.rec is None:
            return
        self.wait_written()
        self.rec.disconnect()          # the writer writes the footer and ends
        with _LOCK:
            _OPEN.discard(self)
        self._drop()
        if not bindings.check_for_rrd_footer(str(self.path)):
            code, cause = write_problem(self.path)
            self.failed = _error(self.path, "the footer could not be written", code,
                                 cause or "the file ends without one")
            raise self.failed

    def _drop(self) -> None:
        rec, self.rec = self.rec, None
        del rec
        release_dropped()
