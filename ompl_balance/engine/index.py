"""An exact nearest-neighbour index for the compiled engine's trees: a k-d tree over positions.

A linear scan costs each query one distance per node; for trees of tens of thousands of
nodes that dominates an iteration. Where a space's metric has a position part, a real-vector
leaf of 2 or 3 coordinates with weight ``w`` (R^2, R^3, SE(2), SE(3) and compounds with such a
leaf), every distance is at least ``w`` times the Euclidean distance of the positions (the
other leaves add non-negative terms, and in floating point a sum of non-negative terms is
never below one of them). :class:`KDIndex` keeps the nodes' positions in a k-d tree, rebuilt
as the tree grows, plus the nodes added since the last build, which a query scans. A query
descends towards its own position first and skips a subtree whose splitting plane is farther
than the best distance found (``w`` times the distance to the plane bounds every node beyond
it from below). The answer is the linear scan's, node for node: the least distance, and the
lowest index among equal ones (subtrees are skipped only when strictly farther).
"""

from __future__ import annotations

import enum
from typing import NamedTuple

import numpy as np
from numba import njit

from ..core.compiled_spaces import is_euclidean, nearest, row_distance
from ..core.layout import Leaf, SpaceLayout

#: Trees with fewer nodes are scanned (the index does not pay).
INDEX_FROM = 256
#: The nodes added since the last build that a query scans before the index is built again:
#: at most this fraction of the built nodes (and at least INDEX_FROM).
UNBUILT_FRACTION = 1 / 32
#: Depth of a query's stack: enough for a k-d tree of 2**62 nodes.
STACK = 128
NONE = -1


class Setting(enum.IntEnum):
    """The index's integers (:attr:`KDIndex.ints`)."""

    OFFSET = 0  # the position leaf's first coordinate (-1: no position leaf: scan)
    AXES = 1  # its coordinates, 2 or 3
    BUILT = 2  # nodes 0 .. BUILT - 1 are in the k-d tree
    COUNT = 3


class KDIndex(NamedTuple):
    """One tree's k-d tree over node positions.

    ``order`` (capacity,): node indices in k-d layout (the subtree of ``order[lo:hi]`` has its
    splitting node at ``order[(lo + hi) // 2]``, smaller coordinates before it, larger after);
    ``points`` (capacity, 3): their positions in the same order (a query walks them, not the
    tree's scattered states); ``axis`` (capacity,): the splitting axis at the middle of each
    subtree of two nodes or more;
    ``stack`` (STACK, 2) and ``gaps`` (STACK, 3): a query's pending subtrees and, per axis, how far
    the query lies outside each (their distance from it is at least the norm of that);
    ``weight`` (1,): the position leaf's weight.
    """

    order: np.ndarray
    points: np.ndarray
    axis: np.ndarray
    stack: np.ndarray
    gaps: np.ndarray
    ints: np.ndarray
    weight: np.ndarray


def position_leaf(layout: SpaceLayout) -> int:
    """The leaf the index keeps: the first real-vector leaf of 2 or 3 coordinates with a
    positive weight; -1 when there is none (the tree is scanned)."""
    for leaf in range(len(layout.kind)):
        if layout.kind[leaf] == Leaf.REAL and layout.size[leaf] in (2, 3) and layout.weight[leaf] > 0.0:
            return leaf
    return NONE


def new_index(layout: SpaceLayout, capacity: int) -> KDIndex:
    """An empty index for a tree of ``capacity`` nodes in ``layout``."""
    ints = np.zeros(Setting.COUNT, dtype=np.int64)
    leaf = position_leaf(layout)
    ints[Setting.OFFSET] = NONE if leaf == NONE else layout.offset[leaf]
    ints[Setting.AXES] = 0 if leaf == NONE else layout.size[leaf]
    weight = np.array([0.0 if leaf == NONE else layout.weight[leaf]])
    return KDIndex(
        np.zeros(capacity, dtype=np.int64),
        np.zeros((capacity, 3)),
        np.zeros(capacity, dtype=np.int64),
        np.zeros((STACK, 2), dtype=np.int64),
        np.zeros((STACK, 3)),
        ints,
        weight,
    )


@njit(cache=True)
def _select(order: np.ndarray, states: np.ndarray, column: int, lo: int, hi: int, k: int) -> None:  # pragma: no cover
    """Reorder ``order[lo:hi]`` so that ``order[k]`` has the k-th smallest ``states[., column]``,
    none after it smaller and none before it larger (Hoare's selection)."""
    while hi - lo > 1:
        pivot = states[order[(lo + hi) // 2], column]
        i, j = lo, hi - 1
        while i <= j:
            while states[order[i], column] < pivot:
                i += 1
            while states[order[j], column] > pivot:
                j -= 1
            if i <= j:
                order[i], order[j] = order[j], order[i]
                i += 1
                j -= 1
        if k <= j:
            hi = j + 1
        elif k >= i:
            lo = i
        else:
            return


@njit(cache=True)
def _build(index: KDIndex, states: np.ndarray, size: int) -> None:  # pragma: no cover (compiled)
    """The k-d tree of nodes ``0 .. size - 1``: each subtree split at its median along its
    widest axis."""
    order, offset, axes = index.order, index.ints[Setting.OFFSET], index.ints[Setting.AXES]
    for node in range(size):
        order[node] = node
    stack = index.stack
    stack[0, 0], stack[0, 1] = 0, size
    depth = 1
    while depth > 0:
        depth -= 1
        lo, hi = stack[depth, 0], stack[depth, 1]
        if hi - lo < 2:
            continue
        widest, spread = 0, -1.0
        for axis in range(axes):
            smallest, largest = np.inf, -np.inf
            for i in range(lo, hi):
                value = states[order[i], offset + axis]
                smallest, largest = min(smallest, value), max(largest, value)
            if largest - smallest > spread:
                widest, spread = axis, largest - smallest
        middle = (lo + hi) // 2
        _select(order, states, offset + widest, lo, hi, middle)
        index.axis[middle] = widest
        stack[depth, 0], stack[depth, 1] = lo, middle
        stack[depth + 1, 0], stack[depth + 1, 1] = middle + 1, hi
        depth += 2
    for i in range(size):
        for axis in range(axes):
            index.points[i, axis] = states[order[i], offset + axis]
    index.ints[Setting.BUILT] = size


@njit(cache=True, inline="always")
def _key(
    layout: SpaceLayout,
    euclidean: bool,
    states: np.ndarray,
    node: int,
    query: np.ndarray,
    offset: int,
    axes: int,
    weight: float,
    best: float,
) -> float:  # pragma: no cover (compiled)
    """What nodes are compared by: the squared distance (Euclidean spaces, as the scan compares)
    or the distance, computed in full only when the position's share alone (coordinates
    ``offset .. offset + axes``, weight ``weight``) is not above ``best``. (Scalars rather
    than the index: passing its arrays costs more, per node, than the distance.)"""
    if euclidean:
        squared = 0.0
        for k in range(query.shape[0]):
            gap = states[node, k] - query[k]
            squared += gap * gap
        return squared
    squared = 0.0
    for k in range(offset, offset + axes):
        gap = states[node, k] - query[k]
        squared += gap * gap
    share = weight * np.sqrt(squared)
    return share if share > best else row_distance(layout, states, node, query)


@njit(cache=True)
def indexed_nearest(
    index: KDIndex, layout: SpaceLayout, states: np.ndarray, size: int, query: np.ndarray
) -> tuple[int, float]:  # pragma: no cover (compiled)
    """The node of ``states[:size]`` nearest ``query`` and its distance, as the linear scan
    (:func:`~ompl_balance.core.compiled_spaces.nearest`) answers; through the k-d tree when it applies."""
    offset = index.ints[Setting.OFFSET]
    if offset == NONE or size < INDEX_FROM:
        return nearest(layout, states, size, query)
    built = index.ints[Setting.BUILT]
    if size - built > max(INDEX_FROM, int(built * UNBUILT_FRACTION)):
        _build(index, states, size)
        built = size
    euclidean = is_euclidean(layout)  # then keys are squared distances, and so are the bounds
    weight, axes = index.weight[0], index.ints[Setting.AXES]
    best, best_key = NONE, np.inf
    for node in range(built, size):  # added since the build
        key = _key(layout, euclidean, states, node, query, offset, axes, weight, best_key)
        if key < best_key:
            best, best_key = node, key
    order, points, stack, gaps = index.order, index.points, index.stack, index.gaps
    stack[0, 0], stack[0, 1] = 0, built
    gaps[0, 0] = gaps[0, 1] = gaps[0, 2] = 0.0
    depth = 1
    while depth > 0:
        depth -= 1
        lo, hi = stack[depth, 0], stack[depth, 1]
        outside = gaps[depth, 0] * gaps[depth, 0] + gaps[depth, 1] * gaps[depth, 1] + gaps[depth, 2] * gaps[depth, 2]
        bound = outside if euclidean else weight * np.sqrt(outside)
        if lo >= hi or bound > best_key:
            continue  # every node of the subtree is farther than the best (ties are looked at)
        middle = (lo + hi) // 2
        node = order[middle]
        squared = 0.0
        for k in range(axes):
            gap = points[middle, k] - query[offset + k]
            squared += gap * gap
        share = squared if euclidean else weight * np.sqrt(squared)
        if share <= best_key:
            key = _key(layout, euclidean, states, node, query, offset, axes, weight, best_key)
            if key < best_key or (key == best_key and node < best):
                best, best_key = node, key
        if hi - lo == 1:
            continue  # a leaf: no subtrees
        axis = index.axis[middle]
        gap = query[offset + axis] - points[middle, axis]
        near_lo, near_hi, far_lo, far_hi = (lo, middle, middle + 1, hi) if gap < 0.0 else (middle + 1, hi, lo, middle)
        g0, g1, g2 = gaps[depth, 0], gaps[depth, 1], gaps[depth, 2]
        if far_lo < far_hi:  # the far side first: the near side is popped first
            stack[depth, 0], stack[depth, 1] = far_lo, far_hi
            gaps[depth, 0], gaps[depth, 1], gaps[depth, 2] = g0, g1, g2
            gaps[depth, axis] = max(gaps[depth, axis], abs(gap))
            depth += 1
        if near_lo < near_hi:
            stack[depth, 0], stack[depth, 1] = near_lo, near_hi
            gaps[depth, 0], gaps[depth, 1], gaps[depth, 2] = g0, g1, g2
            depth += 1
    return best, np.sqrt(best_key) if euclidean else best_key
