"""OMPL's ``DiscreteMotionValidator`` on flat states: the :class:`DiscreteMotions` check view.

``checkMotion(a, b)`` (``src/ompl/base/src/DiscreteMotionValidator.cpp``) takes ``a`` as valid
and tests ``b`` first, then, with ``n = validSegmentCount(a, b)``, the states at ``j / n`` of
the way for ``j = 1 .. n - 1`` in breadth-first bisection order: the middle of the range
``[1, n - 1]``, then the middles of its two halves, and so on. It stops at the first invalid
state. :class:`DiscreteMotions` is that rule around a validity checker's compiled state view;
every kernel that checks a motion by the rule (this view's, and a batch of states handed to
Python at once, :mod:`ompl_balance.core.exit_checks`) takes the order from
:func:`~ompl_balance.core.discrete_motion_kernels.bisection_order`, so they all test the same
states in the same order as OMPL and as each other.

The view is a plain named tuple (this module does not import numba); its kernels are in
:mod:`ompl_balance.core.discrete_motion_kernels`.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from .checks import kernels_in
from .layout import SpaceLayout


@kernels_in("ompl_balance.core.discrete_motion_kernels")
class DiscreteMotions(NamedTuple):
    """OMPL's ``DiscreteMotionValidator`` around the compiled view ``states`` of a validity checker.

    ``test`` (dim,) is scratch space; ``queue`` (rows, 2) and ``order`` (rows,) the bisection's;
    the motions count in ``counts`` (the validity checker's own counter, which also counts its states).
    """

    states: Any
    layout: SpaceLayout
    test: np.ndarray
    queue: np.ndarray
    order: np.ndarray
    counts: np.ndarray


def longest_motion(extent: float, layout: SpaceLayout) -> int:
    """States OMPL's discrete rule tests on the longest motion of a space of maximum extent
    ``extent`` (``validSegmentCount`` of a motion across it), plus two (two for a space not set
    up yet, whose valid segment length is still 0: kernels make room for longer motions)."""
    return max(int(f) * math.ceil(extent / g) if g > 0.0 else 0 for f, g in zip(layout.factor, layout.segment)) + 2


def bisection_scratch(extent: float, layout: SpaceLayout) -> tuple[np.ndarray, np.ndarray]:
    """The bisection's ``queue`` (rows, 2) and ``order`` (rows,) for the longest motion of the space."""
    longest = longest_motion(extent, layout)
    return np.empty((longest, 2), dtype=np.int64), np.empty(longest, dtype=np.int64)


def discrete_motions(states: Any, layout: SpaceLayout, extent: float) -> DiscreteMotions:
    """OMPL's discrete rule around the compiled state view ``states`` (counting in its ``counts``),
    in a space of ``layout`` and maximum extent ``extent``."""
    queue, order = bisection_scratch(extent, layout)
    return DiscreteMotions(states, layout, np.empty(layout.dim), queue, order, states.counts)
