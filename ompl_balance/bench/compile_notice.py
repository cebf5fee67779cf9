"""A line on standard error while numba compiles kernels, as it does once after installing.

numba keeps what it compiles in its on-disk cache; afterwards the same imports load the
kernels in a fraction of a second. It broadcasts a ``"numba:compile"`` event only when it
compiles (a cache miss), so :func:`compile_notice` speaks only then.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from numba.core import event


class _FirstCompile(event.Listener):
    """Says once, when numba has been compiling for ``quiet`` seconds, what is being compiled
    (a compilation of a moment, such as numba's object-mode wrappers made at every import, is
    not worth a line)."""

    def __init__(self, what: str, quiet: float) -> None:
        self.what = what
        self.began: float | None = None  # time.perf_counter() of the first compilation
        self._timer = threading.Timer(quiet, self._say)
        self._timer.daemon = True
        self.said = False

    def _say(self) -> None:
        self.said = True
        print(
            f"ompl-balance: compiling {self.what} with numba, once after installing (a minute or so) ...",
            file=sys.stderr,
            flush=True,
        )

    def on_start(self, event: Any) -> None:
        if self.began is None:
            self.began = time.perf_counter()
            self._timer.start()

    def on_end(self, event: Any) -> None:
        pass

    def stop(self) -> None:
        """End the wait for the notice (it is said no more)."""
        self._timer.cancel()


@contextmanager
def compile_notice(what: str, quiet: float = 1.0) -> Iterator[None]:
    """Within the block, a line naming ``what`` once numba has been compiling for ``quiet`` seconds,
    and one saying how long it took at the end of the block; nothing when every kernel comes from
    numba's cache or compiles in less."""
    listener = _FirstCompile(what, quiet)
    try:
        with event.install_listener("numba:compile", listener):
            yield
    finally:
        listener.stop()
    if listener.said and listener.began is not None:
        seconds = time.perf_counter() - listener.began
        print(f"ompl-balance: {what} compiled in {seconds:.0f} s (cached for later runs)", file=sys.stderr, flush=True)
