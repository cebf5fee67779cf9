"""The compiled kernels of :class:`~ompl_balance.core.discrete_motions.DiscreteMotions`, and the order
in which OMPL's discrete rule tests a motion's states (:func:`bisection_order`,
:func:`order_between`, :func:`fraction_between`), which every kernel checking a motion by that
rule takes."""

from __future__ import annotations

import numpy as np

from .check_overloads import register_kernels
from .checks import Count, state_free
from .compiled_spaces import interpolate, segment_count
from .discrete_motions import DiscreteMotions
from .kernel_cache import njit, njit_borrowing


@njit_borrowing
def bisection_order(n: int, queue: np.ndarray, order: np.ndarray) -> None:  # pragma: no cover (compiled)
    """Write ``j = 1 .. n - 1`` into ``order[:n - 1]`` in the order OMPL tests the states at ``j / n``.

    ``queue`` (rows, 2) holds the index ranges in the order they are split, breadth first: each
    of the ``n - 1`` indices is the middle of exactly one range, so ``n - 1`` rows hold them all
    (no wrapping around); ``queue`` and ``order`` must have at least ``n`` rows (callers size
    them for the longest motion of their space, and make larger ones for a longer motion).
    """
    if n < 2:
        return
    queue[0, 0], queue[0, 1] = 1, n - 1
    tail = 1
    for head in range(n - 1):
        first, last = queue[head, 0], queue[head, 1]
        middle = (first + last) // 2
        order[head] = middle
        if first < middle:
            queue[tail, 0], queue[tail, 1] = first, middle - 1
            tail += 1
        if last > middle:
            queue[tail, 0], queue[tail, 1] = middle + 1, last
            tail += 1


@njit_borrowing
def order_between(n: int, queue: np.ndarray, order: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Ready the order in which the rule tests the states between the ends of a motion of ``n``
    segments (:func:`bisection_order` into ``order``); ``True`` where ``order`` has no room for
    it, a motion longer than the space's longest (an end outside the bounds), whose states
    between are then tested in order from its first end. :func:`fraction_between` reads it."""
    if order.shape[0] < n:
        return True
    bisection_order(n, queue, order)
    return False


@njit_borrowing
def fraction_between(k: int, n: int, in_order: bool, order: np.ndarray) -> float:  # pragma: no cover (compiled)
    """Where the ``k``-th state between a motion's ends that the rule tests lies (from 0), as a
    fraction of the motion (``in_order``, ``order``: see :func:`order_between`)."""
    return (k + 1 if in_order else order[k]) / n


@njit_borrowing
def discrete_motion_free(view: DiscreteMotions, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover
    """OMPL's ``DiscreteMotionValidator::checkMotion(a, b)`` with the state kernel of ``view.states``:
    ``b``, then the states between in its order (:mod:`ompl_balance.core.discrete_motions`) until
    the first invalid one. (The view's fields read once, first, as
    :func:`~ompl_balance.worlds.box_kernels.box_state_free` does.)"""
    states, layout, test, queue, order = view.states, view.layout, view.test, view.queue, view.order
    view.counts[Count.MOTIONS] += 1
    if not state_free(states, b):
        return False
    n = segment_count(layout, a, b)
    if n < 2:
        return True
    in_order = order_between(n, queue, order)
    for k in range(n - 1):
        interpolate(layout, a, b, fraction_between(k, n, in_order, order), test)
        if not state_free(states, test):
            return False
    return True


@njit(cache=True, inline="always")
def discrete_state_free(view: DiscreteMotions, q: np.ndarray) -> bool:  # pragma: no cover (compiled)
    return state_free(view.states, q)


register_kernels(DiscreteMotions, state=discrete_state_free, motion=discrete_motion_free)
