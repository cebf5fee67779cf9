"""The compiled kernels of :class:`~ompl_balance.core.exit_checks.ExitChecks`: states and motions
checked by Python, a motion's states in one exit."""

from __future__ import annotations

import numpy as np

from .check_overloads import register_kernels
from .checks import Count
from .compiled_spaces import interpolate, segment_count
from .discrete_motion_kernels import bisection_order
from .exit_checks import ExitChecks, Query
from .function_pointers import call_exit
from .kernel_cache import njit

_STATES, _MOTION = int(Query.STATES), int(Query.MOTION)


@njit(cache=True)
def _ask(view: ExitChecks, kind: int, count: int) -> int:  # pragma: no cover (compiled)
    """One exit to the view's target about ``view.rows[:count]`` (counted); -1, with the view's
    RAISED flag set, when it raised."""
    view.counts[Count.EXITS] += 1
    answer = call_exit(view.address, view.handle, kind, count)
    if answer < 0:
        view.counts[Count.RAISED] = 1
    return answer


@njit(cache=True)
def exit_state_free(view: ExitChecks, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Whether ``q`` is valid: one exit (a state counted here where the view is batched)."""
    rows = view.rows
    for i in range(q.shape[0]):
        rows[0, i] = q[i]
    if view.batched:
        view.counts[Count.STATES] += 1
    return _ask(view, _STATES, 1) == 1


@njit(cache=True)
def exit_motion_free(view: ExitChecks, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover
    """Whether the motion ``a -> b`` is valid (``a`` taken as valid).

    Batched: the states OMPL's discrete rule tests (``b``, then those between in its order,
    :mod:`~ompl_balance.core.discrete_motions`), written into ``view.rows`` and handed to Python
    in one exit (in as many as the rows need, each stopping at the first invalid state),
    counting the motion and the states decided. Otherwise one exit that asks for the motion.
    """
    layout, rows, queue, order = view.layout, view.rows, view.queue, view.order
    if not view.batched:
        for i in range(a.shape[0]):
            rows[0, i], rows[1, i] = a[i], b[i]
        return _ask(view, _MOTION, 2) == 1
    view.counts[Count.MOTIONS] += 1
    n = max(segment_count(layout, a, b), 1)
    if order.shape[0] < n:  # a motion longer than the scratch was sized for
        queue, order = np.empty((n, 2), dtype=np.int64), np.empty(n, dtype=np.int64)
    bisection_order(n, queue, order)
    done = 0  # states tested so far: b is the first
    while done < n:
        count = min(n - done, rows.shape[0])
        for k in range(count):
            if done + k == 0:
                for i in range(b.shape[0]):
                    rows[0, i] = b[i]
            else:
                interpolate(layout, a, b, order[done + k - 1] / n, rows[k])
        first_invalid = _ask(view, _STATES, count)
        if first_invalid < 0:
            return False
        view.counts[Count.STATES] += min(first_invalid + 1, count)
        if first_invalid < count:
            return False
        done += count
    return True


register_kernels(ExitChecks, state=exit_state_free, motion=exit_motion_free)
