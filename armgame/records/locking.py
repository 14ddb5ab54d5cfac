"""The table's lock, on every platform: ``filelock``, which picks the platform's own kind.

On Linux and macOS that is ``fcntl.flock`` on the lock file (opened with ``O_NOFOLLOW``, never
truncated): the kernel drops it when its holder exits, even by SIGKILL, so there is no stale
lock to clean up. On Windows it is ``LockFileEx`` on a handle that refuses reparse points (a
planted symlink or junction). Where neither exists, ``filelock`` falls back to a marker file
created exclusively. The file is made readable and writable by everyone (``mode``), so that
classmates sharing one table folder can all take the lock whoever created it. A lock file another
user created read-only (older armgames did) is locked through a read-only descriptor, which
``flock`` allows, so a shared folder keeps working.
"""

from __future__ import annotations

import contextlib
import os
import stat
import time
import warnings
from collections.abc import Iterator
from pathlib import Path


class LockBusyError(Exception):
    """The lock was not free within the wait."""


class LockError(Exception):
    """The lock file cannot be opened or locked (the reason is the message)."""


@contextlib.contextmanager
def file_lock(path: Path, wait: float, mode: int = 0o666) -> Iterator[None]:
    """Hold the exclusive lock on ``path`` (created if need be) for the ``with`` block.

    Raises ``LockBusyError`` after ``wait`` seconds, ``LockError`` if the lock file cannot be opened;
    whatever the block raises passes through unchanged. ``mode``: the lock file's permissions (0o600 for a
    folder one program writes, such as a live class's, so nobody else can open the file to stall it).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "only soft file lock is available": said in the docs, not at every save
        import filelock

    lock = filelock.FileLock(str(path), timeout=wait, mode=mode, thread_local=False)
    try:
        lock.acquire(poll_interval=0.05)
    except filelock.Timeout:
        raise LockBusyError(str(path)) from None
    except PermissionError as exc:
        try:
            import fcntl
        except ImportError:
            raise LockError(exc.strerror or str(exc)) from None
        with _read_only_flock(fcntl, path, wait):
            yield
        return
    except (OSError, NotImplementedError) as exc:  # NotImplementedError: a file system without flock
        raise LockError(getattr(exc, "strerror", None) or str(exc) or type(exc).__name__) from None
    try:
        yield
    finally:
        lock.release()


@contextlib.contextmanager
def _read_only_flock(fcntl, path: Path, wait: float) -> Iterator[None]:
    """``flock`` through a read-only descriptor: for a lock file another user created without write access."""
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        raise LockError(exc.strerror or str(exc)) from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise LockError("not a regular file")
        deadline = time.monotonic() + wait
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() >= deadline:
                    raise LockBusyError(str(path)) from None
                time.sleep(0.05)
        yield
    finally:
        os.close(fd)  # closing drops the lock
