"""What keeps a sweep in charge of its output folder and its process: the errors it raises,
the lock ``OUT/.sweep.lock`` and the SIGINT / SIGTERM handling (:mod:`.sweep`).

The lock is created exclusively, refreshed by a heartbeat thread and removed on exit; the lock
of a dead run (same host: pid gone; other host: no heartbeat for :data:`LOCK_STALE_SECONDS`)
is taken over. While a sweep runs in the main thread, SIGINT / SIGTERM raise
:class:`SweepInterrupted` (exit code 130 / 143).
"""
from __future__ import annotations

import contextlib
import datetime as _dt
import json
import os
import signal
import socket
import threading
import time
from pathlib import Path

__all__ = ["SweepError", "SweepInterrupted", "LOCK_NAME", "LOCK_STALE_SECONDS"]

#: lock file of a running sweep, inside the output folder
LOCK_NAME = ".sweep.lock"
#: a lock from another host whose heartbeat is older than this [s] is stale
LOCK_STALE_SECONDS = 120.0
_HEARTBEAT_SECONDS = 5.0
_EXIT_CODES = {signal.SIGINT: 130, signal.SIGTERM: 143}


class SweepError(ValueError):
    """Bad sweep input or an output folder in use (the CLI reports it in one line, exit 2)."""


class SweepInterrupted(KeyboardInterrupt):
    """SIGINT / SIGTERM ended a sweep; ``exit_code`` is 130 / 143 and ``str()`` one line."""

    def __init__(self, message, exit_code):
        super().__init__(message)
        self.exit_code = exit_code


def _utc_now():
    """Now in UTC, ISO 8601 to the second (the manifest's and the lock's timestamps)."""
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


# ============================================================================ the lock
def _process_start(pid):
    """Start time of process ``pid`` (clock ticks since boot, Linux), or None if unknown."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            return int(fh.read().rsplit(b")", 1)[1].split()[19])
    except (OSError, ValueError, IndexError):
        return None


def _alive(info):
    """Whether the process that wrote lock ``info`` may still run."""
    if info.get("host") != socket.gethostname():
        return time.time() - float(info.get("heartbeat", 0.0)) < LOCK_STALE_SECONDS
    pid = int(info.get("pid", -1))
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    start = _process_start(pid)
    return info.get("start") is None or start is None or start == info.get("start")


class _Lock:
    """``OUT/.sweep.lock``: created exclusively, heartbeat every few seconds, removed on exit;
    a stale lock (dead owner) is taken over."""

    def __init__(self, outdir, log):
        self.path = Path(outdir) / LOCK_NAME
        self.log = log
        self._stop = threading.Event()
        self._thread = None
        self.info = {"pid": os.getpid(), "host": socket.gethostname(),
                     "start": _process_start(os.getpid()), "since": _utc_now()}

    def _write_new(self):
        self.info["heartbeat"] = time.time()
        fd = os.open(self.path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        with os.fdopen(fd, "w") as fh:
            json.dump(self.info, fh)

    def acquire(self):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        for _ in range(3):
            try:
                self._write_new()
                break
            except FileExistsError:
                try:
                    other = json.loads(self.path.read_text() or "{}")
                except (OSError, ValueError):
                    other = {}
                if other and _alive(other):
                    raise SweepError(
                        f"output folder {str(self.path.parent)!r} is in use by another sweep "
                        f"(pid {other.get('pid')} on {other.get('host')} since "
                        f"{other.get('since')}; lock {self.path.name}): wait for it to finish "
                        f"or use another -o") from None
                stale = self.path.with_name(f"{LOCK_NAME}.stale.{os.getpid()}")
                with contextlib.suppress(FileNotFoundError):
                    os.replace(self.path, stale)
                    stale.unlink()
                self.log(f"note: took over the stale lock of a dead sweep (pid "
                         f"{other.get('pid')} on {other.get('host')})")
        else:
            raise SweepError(f"output folder {str(self.path.parent)!r}: cannot take the lock "
                             f"{self.path.name} (another sweep is starting there)")
        self._thread = threading.Thread(target=self._beat, daemon=True)
        self._thread.start()
        return self

    def _beat(self):
        while not self._stop.wait(_HEARTBEAT_SECONDS):
            self.info["heartbeat"] = time.time()
            with contextlib.suppress(OSError):
                tmp = self.path.with_name(f"{LOCK_NAME}.{os.getpid()}.tmp")
                tmp.write_text(json.dumps(self.info))
                os.replace(tmp, self.path)

    def release(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        with contextlib.suppress(OSError, ValueError):
            if json.loads(self.path.read_text()).get("pid") == os.getpid():
                self.path.unlink()


# ============================================================================ signals
@contextlib.contextmanager
def _signal_handlers(handler):
    """SIGINT and SIGTERM go to ``handler`` while inside, then back to their former handlers
    (in the main thread; elsewhere, where Python cannot set handlers, nothing changes)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = {s: signal.signal(s, handler) for s in _EXIT_CODES}
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)


class _Held:
    """State of :func:`_held_interrupts` (main thread only: signal handlers run there)."""
    depth = 0
    pending = None


def _interrupted(signum):
    return SweepInterrupted(signal.Signals(signum).name, _EXIT_CODES[signum])


def _raise_interrupted(signum, frame):
    """Signal handler: raise :class:`SweepInterrupted` named for the signal — at once, or,
    inside :func:`_held_interrupts`, when that ends (a second signal there raises at once)."""
    if _Held.depth > 0 and _Held.pending is None:
        _Held.pending = signum
        return
    _Held.pending = None
    raise _interrupted(signum)


@contextlib.contextmanager
def _held_interrupts():
    """Hold a SIGINT / SIGTERM until the block ends, then raise it.

    For the driver's blocking Dask calls (``Future.result``, starting the client):
    ``distributed.utils.sync`` answers a KeyboardInterrupt raised inside its wait by
    scheduling a ``cancel`` callback that can run before its coroutine has created the
    future it cancels, and tornado then prints that callback's ``NameError`` traceback
    (distributed 2026.8). Raised here, between Dask calls, the interrupt stays one line."""
    _Held.depth += 1
    try:
        yield
    finally:
        _Held.depth -= 1
        if _Held.depth == 0 and _Held.pending is not None:
            signum, _Held.pending = _Held.pending, None
            raise _interrupted(signum)


def _interrupts():
    """SIGINT / SIGTERM raise :class:`SweepInterrupted` in the main thread while inside."""
    _Held.depth, _Held.pending = 0, None
    return _signal_handlers(_raise_interrupted)


def _ignore_signals():
    """A second Ctrl-C while the cluster shuts down must not leave it half-closed."""
    return _signal_handlers(signal.SIG_IGN)
