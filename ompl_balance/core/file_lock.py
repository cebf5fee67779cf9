"""A lock shared by the processes of a machine: ``flock`` on a file."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path


@contextlib.contextmanager
def file_lock(path: str | Path, shared: bool = False) -> Iterator[None]:
    """Hold a lock on the file ``path`` (made if missing) while the block runs: exclusive, or with
    ``shared`` alongside other shared holders (readers waiting out a writer). Nothing is locked
    where the system has no ``flock`` or the file cannot be opened (a folder that is not writable):
    the block then runs as it would have without the lock."""
    try:
        import fcntl
    except ImportError:
        fcntl = None  # type: ignore[assignment]
    try:
        lock = None if fcntl is None else open(path, "a")  # noqa: SIM115 (closed below)
    except OSError:
        lock = None
    if lock is None:
        yield
        return
    with lock:
        fcntl.flock(lock, fcntl.LOCK_SH if shared else fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)
