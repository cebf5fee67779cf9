"""The compiled kernels of the engine's own check views (:mod:`ompl_balance.engine.views`)."""

from __future__ import annotations

import numpy as np
from numba import objmode

from ..core.check_overloads import register_kernels
from ..core.checks import Count, exit_handle, new_counts, state_free
from ..core.compiled_spaces import interpolate, segment_count
from ..core.kernel_cache import njit
from .views import DiscreteMotions, PythonChecks, call_check_motion, call_is_valid


@njit(cache=True, inline="always")
def _discrete_motion_free(view: DiscreteMotions, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover
    """OMPL's ``DiscreteMotionValidator::checkMotion(s1, s2)``: ``b`` first, then the states
    ``a + (j / n) (b - a)`` in the order of its queue of index ranges (the middle of each
    range, then its halves). (The view's fields read once, first, as
    :func:`~ompl_balance.worlds.box_kernels.box_state_free` does.)"""
    states, layout, test, queue = view.states, view.layout, view.test, view.queue
    view.counts[Count.MOTIONS] += 1
    if not state_free(states, b):
        return False
    n = segment_count(layout, a, b)
    if n < 2:
        return True
    if queue.shape[0] < n:
        queue = np.empty((2 * n, 2), dtype=np.int64)
    head, tail = 0, 1
    queue[0, 0], queue[0, 1] = 1, n - 1
    while head != tail:
        first, last = queue[head, 0], queue[head, 1]
        head = (head + 1) % queue.shape[0]
        middle = (first + last) // 2
        interpolate(layout, a, b, middle / n, test)
        if not state_free(states, test):
            return False
        if first < middle:
            queue[tail, 0], queue[tail, 1] = first, middle - 1
            tail = (tail + 1) % queue.shape[0]
        if last > middle:
            queue[tail, 0], queue[tail, 1] = middle + 1, last
            tail = (tail + 1) % queue.shape[0]
    return True


@njit(cache=True)
def _python_state_free(view: PythonChecks, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    view.counts[Count.EXITS] += 1
    with objmode(free="boolean"):
        free = call_is_valid(view.handle, q)
    return free


@njit(cache=True)
def _python_motion_free(view: PythonChecks, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover (compiled)
    view.counts[Count.EXITS] += 1
    with objmode(free="boolean"):
        free = call_check_motion(view.handle, a, b)
    return free


@njit(cache=True, inline="always")
def _discrete_state_free(view: DiscreteMotions, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    return state_free(view.states, q)


register_kernels(DiscreteMotions, state=_discrete_state_free, motion=_discrete_motion_free)
register_kernels(PythonChecks, state=_python_state_free, motion=_python_motion_free)


class _AllFree:
    """An exit target answering every query "free" (for :func:`warm_exits`)."""

    def is_valid(self, q: np.ndarray) -> bool:
        return True

    def check_motion(self, a: np.ndarray, b: np.ndarray) -> bool:
        return True


def warm_exits() -> None:
    """Run the exits to Python once: numba makes a kernel's ``objmode`` code ready the first time
    it runs in a process (about a tenth of a second), which would otherwise fall in a solve."""
    target = _AllFree()
    view = PythonChecks(exit_handle(target), new_counts())
    q = np.zeros(1)
    _python_state_free(view, q)
    _python_motion_free(view, q, q)
