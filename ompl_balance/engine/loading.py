"""Compiling (or loading from numba's disk cache) the compiled engine without making a solve wait.

numba compiles :func:`ompl_balance.engine.loop.run` once per kind of check view (a box world
with OMPL's discrete motions, a robot with certified motions, ...) and caches the machine
code on disk, so only the first use after an install compiles (tens of seconds); later
processes load it (about a second, most of it numba's own start-up). :class:`EngineLoader`
does either in a background thread: ``engine=auto`` solves on the Python engine until the
compiled one is ready, ``engine=compiled`` waits for it, with a message on standard error
when the wait exceeds a second. A process does not exit in the middle of it (the work is
kept in numba's cache).
"""

from __future__ import annotations

import atexit
import os
import pickle
import sys
import threading
import time
from collections.abc import Callable, Hashable
from typing import Any

import numpy as np

#: Seconds a solve waits for the compiled engine before it says that it is compiling.
QUIET_WAIT = 1.0
#: Seconds a process about to exit waits for the engine's loading before it says so (loading
#: from numba's cache takes a second or two; compiling, tens of seconds).
EXIT_QUIET_WAIT = 3.0


def view_key(value: Any) -> Any:
    """What numba compiles a specialization of the engine for, as a hashable key: the classes of
    named tuples with the keys of their fields, arrays by dtype, dimensions and layout, scalars by type.

    The keys of the last views asked about are remembered (a solve asks about the same views
    again); a plain tuple is keyed item by item, so ``(view, layout)`` finds both remembered.
    (Told apart by class first: a planner's setup keys a new view of some twenty fields.)
    """
    kind = type(value)
    if issubclass(kind, np.ndarray):
        flags = value.flags
        return (value.dtype, value.ndim, flags.c_contiguous, flags.writeable)
    if not issubclass(kind, tuple):
        return kind
    if not hasattr(kind, "_fields"):
        return tuple(map(view_key, value))
    known = _KEYS.get(id(value))
    if known is not None and known[0] is value:
        return known[1]
    key = _Key((kind, tuple(map(view_key, value))))
    key = _INTERNED.setdefault(key, key)  # one object per distinct key: later lookups compare by identity
    if len(_KEYS) >= 64:
        _KEYS.pop(next(iter(_KEYS)))
    _KEYS[id(value)] = (value, key)
    return key


_KEYS: dict[int, tuple[Any, Any]] = {}  # id -> (the value, its key), the value kept so its id is not reused
_INTERNED: dict[Any, Any] = {}  # each distinct named-tuple key, once (as many as kinds of view in use)


class _Key:
    """A named tuple's key with its hash worked out once: a robot view's key holds hundreds of
    items, and a solve looks it up in several tables."""

    __slots__ = ("_hash", "items")

    def __init__(self, items: tuple[Any, ...]) -> None:
        self.items = items
        self._hash = hash(items)

    def __hash__(self) -> int:
        return self._hash

    def __eq__(self, other: object) -> bool:
        return self is other or (isinstance(other, _Key) and self._hash == other._hash and self.items == other.items)


class EngineLoader:
    """Background compilation of the engine's specializations, one thread per kind of view."""

    def __init__(self) -> None:
        self._ready: set[Hashable] = set()
        self._threads: dict[Hashable, threading.Thread] = {}
        self._errors: dict[Hashable, BaseException] = {}
        self._lock = threading.Lock()

    def ready(self, key: Hashable) -> bool:
        """Whether the engine for ``key`` is compiled and loaded in this process."""
        return key in self._ready

    def failure(self, key: Hashable) -> BaseException | None:
        """Why compiling the engine for ``key`` failed, if it did."""
        return self._errors.get(key)

    def start(self, key: Hashable, warm: Callable[[], None]) -> bool:
        """Compile or load the engine for ``key`` in the background (``warm()`` does it), unless
        under way or done; ``True`` when this call started it."""
        with self._lock:
            if key in self._ready or key in self._threads:
                return False
            thread = threading.Thread(target=self._warm, args=(key, warm), name="ompl_balance-engine", daemon=True)
            self._threads[key] = thread
        thread.start()
        return True

    def wait(self, key: Hashable, warm: Callable[[], None], what: str) -> None:
        """Make the engine for ``key`` ready now (compiled, or loaded from numba's cache), saying on
        standard error when that takes more than a second."""
        self.start(key, warm)
        began = time.perf_counter()
        message = (
            f"preparing the planning engine for {what} (numba compiles it on first use, tens "
            "of seconds; later processes load it from numba's cache, a second or two)"
        )
        if _join_saying([self._threads[key]], QUIET_WAIT, message):
            sys.stderr.write(f"ompl_balance: planning engine ready after {time.perf_counter() - began:.0f} s\n")
        if key in self._errors:
            raise RuntimeError(f"the compiled engine for {what} failed to compile") from self._errors[key]

    def finish(self) -> None:
        """Wait for every background compilation (a process must not fork in the middle of one)."""
        for thread in list(self._threads.values()):
            thread.join()

    def finish_before_exit(self) -> None:
        """Let a background compilation end before the interpreter does, saying so on standard
        error when that takes more than :data:`EXIT_QUIET_WAIT`. A thread cut off at exit would
        leave numba's work undone (the next process compiles again) and OMPL objects alive while
        Python shuts down, which nanobind reports as leaks."""
        message = "waiting for the planning engine to finish loading before exit (numba keeps it for later processes)"
        _join_saying(list(self._threads.values()), EXIT_QUIET_WAIT, message)

    def _warm(self, key: Hashable, warm: Callable[[], None]) -> None:
        try:
            try:
                warm()
            except (AttributeError, ImportError, EOFError, pickle.UnpicklingError):
                # numba's cache index names classes by module: one written by another version
                # of the package may name what no longer exists. Forget the package's cached
                # kernels (numba compiles them again) and try once more.
                forget_cached_kernels()
                warm()
        except BaseException as error:  # reported by wait(); auto keeps the Python engine
            self._errors[key] = error
            return
        self._ready.add(key)


def _join_saying(threads: list[threading.Thread], quiet: float, message: str) -> bool:
    """Wait for ``threads`` to end; if they run longer than ``quiet`` seconds, say ``message`` on
    standard error first. Whether it was said."""
    began = time.perf_counter()
    for thread in threads:
        thread.join(max(0.0, quiet - (time.perf_counter() - began)))
    if not any(thread.is_alive() for thread in threads):
        return False
    sys.stderr.write(f"ompl_balance: {message}...\n")
    sys.stderr.flush()
    for thread in threads:
        thread.join()
    return True


def forget_cached_kernels() -> None:
    """Empty numba's on-disk cache index of every compiled function of the package loaded so far."""
    from numba.core.dispatcher import Dispatcher

    for name, module in list(sys.modules.items()):
        if not name.startswith("ompl_balance") or module is None:
            continue
        for value in list(vars(module).values()):
            cache = getattr(value, "_cache", None) if isinstance(value, Dispatcher) else None
            if cache is not None:
                cache.flush()


LOADER = EngineLoader()
os.register_at_fork(before=LOADER.finish)
atexit.register(LOADER.finish_before_exit)
