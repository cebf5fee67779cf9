"""A line on standard error while numba compiles kernels, as it does once after installing.

numba keeps what it compiles in its on-disk cache; afterwards the same imports load the
kernels in a fraction of a second. It broadcasts a ``"numba:compile"`` event only when it
compiles (a cache miss), so :func:`compile_notice` speaks only then.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from numba.core import event


class _FirstCompile(event.Listener):
    """Says once, when numba starts compiling the first kernel, what is being compiled."""

    def __init__(self, what: str) -> None:
        self.what = what
        self.began: float | None = None  # time.perf_counter() of the first compilation

    def on_start(self, event: Any) -> None:
        if self.began is None:
            self.began = time.perf_counter()
            print(
                f"ompl-balance: compiling {self.what} with numba, once after installing (a minute or so) ...",
                file=sys.stderr,
                flush=True,
            )

    def on_end(self, event: Any) -> None:
        pass


@contextmanager
def compile_notice(what: str) -> Iterator[None]:
    """Within the block, a line naming ``what`` when numba starts compiling, and one saying how
    long it took at the end of the block; nothing when every kernel comes from numba's cache."""
    listener = _FirstCompile(what)
    with event.install_listener("numba:compile", listener):
        yield
    if listener.began is not None:
        seconds = time.perf_counter() - listener.began
        print(f"ompl-balance: {what} compiled in {seconds:.0f} s (cached for later runs)", file=sys.stderr, flush=True)
