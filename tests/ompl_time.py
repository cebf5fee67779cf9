"""How long a solve took, on OMPL's clock and on the monotonic one.

OMPL measures its time limits on ``std::chrono::system_clock`` (``ompl/util/Time.h``): the wall
clock, which time synchronisation slews (by up to several per cent with chrony) or steps. So a
test that a solve lasted at least its limit reads the wall clock, as OMPL does, and a test that
it ended soon after reads the monotonic clock, which nothing adjusts.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass


@dataclass
class Took:
    """Seconds elapsed on OMPL's clock (``wall``) and on the monotonic clock (``monotonic``)."""

    wall: float = 0.0
    monotonic: float = 0.0


@contextmanager
def timed() -> Iterator[Took]:
    """``with timed() as took: ...``: ``took`` holds what the block took once it has ended."""
    took = Took()
    wall, monotonic = time.time(), time.perf_counter()
    try:
        yield took
    finally:
        took.monotonic = time.perf_counter() - monotonic
        took.wall = time.time() - wall
