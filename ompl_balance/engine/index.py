"""An exact nearest-neighbour index for the compiled engine's trees: a k-d tree over positions
and rotations.

A linear scan costs each query one distance per node; for trees of tens of thousands of
nodes that dominates an iteration. The index applies where a space's metric has a position
part (a real-vector leaf of 2 or 3 coordinates, weight ``w_p``) or a rotation part (an SO(2)
or SO(3) leaf, weight ``w_r``): R^2, R^3, SO(2), SO(3), SE(2), SE(3) and compounds with such
leaves. Each node gets up to seven *index coordinates*: its position, and its rotation as a
point whose distances are chords of the rotation distance:

* SO(2), an angle ``a``: ``(cos a, sin a)``; two angles ``d`` apart (the shorter arc) are a
  chord ``2 sin(d / 2) <= d`` apart (as far as OMPL's distance of angles is one: angles less
  than ``2 pi`` apart);
* SO(3), a unit quaternion ``q``: ``|q|`` taken coordinate by coordinate, which makes ``q`` and
  ``-q`` (one rotation) the same point; OMPL's distance ``d = acos(|q1 . q2|)`` has chord
  ``min(||q1 - q2||, ||q1 + q2||) = 2 sin(d / 2) <= d``, and ``||(|q1| - |q2|)||`` is at most that.

So every distance is at least ``w_p`` times the distance of the positions plus ``w_r`` times
that of the rotation points (less :data:`CHORD_SLACK`, for OMPL's tolerance that calls nearly
equal quaternions 0 apart and for rounding); the other leaves add non-negative terms.

:class:`KDIndex` keeps the nodes' index coordinates in a few static k-d trees (Bentley and
Saxe's logarithmic method): the built nodes ``0 .. BUILT - 1`` fall into consecutive blocks
whose sizes are :data:`BLOCK` times the powers of two in ``BUILT / BLOCK``, largest first, each
its own k-d tree; the fewer than :data:`BLOCK` nodes added since are scanned. When
:data:`BLOCK` more nodes arrive, the blocks that the binary count changes are built again as
one (as a binary counter carries), so each node is rebuilt at most ``log2(n / BLOCK)`` times
and a query searches at most that many k-d trees. (In the 7 coordinates of SE(3) a small
block's search costs nearly what the largest one's does: fewer blocks make faster queries,
rarer builds slower ones.) Each k-d tree
splits its nodes at the median until :data:`LEAF` or fewer are left, and keeps each subtree's
bounding box (the least and greatest index coordinates of its nodes). A query descends each
block towards its own coordinates first, skips a subtree whose box lies farther than the best
distance found, and scans a leaf's few nodes. The answer is the linear scan's, node for
node: the least distance, and the lowest index among equal ones (subtrees are skipped only
when strictly farther). A quaternion not of unit length (to :data:`UNIT_TOLERANCE`) leaves
the rotation out of the bounds of that build or query.
"""

from __future__ import annotations

import enum
import math
from typing import NamedTuple

import numpy as np

from ..core.compiled_spaces import is_euclidean, nearest, row_distance
from ..core.kernel_cache import njit, njit_borrowing
from ..core.layout import Leaf, SpaceLayout

#: Trees with fewer nodes are scanned (the index does not pay).
INDEX_FROM = 256
#: Nodes per unit of the logarithmic method: the built blocks are this many times a power of
#: two, and a query scans fewer than this many nodes added since the last build.
BLOCK = 64
#: Nodes a k-d tree leaves unsplit: a query scans them (cheaper than descending to each). In
#: SE(3) 16 makes a query at 20,000 nodes some 10 % cheaper than 8 (fewer boxes tested, the
#: nodes mostly refused on their position); in R^2 and R^3 it makes no difference.
LEAF = 16
#: Depth of a query's stack: the nodes added since the last build (one entry), the blocks'
#: subtrees pending (one per block, at most 62) and one path down a k-d tree of up to 2**62 nodes.
STACK = 128
#: Taken off the rotation's chord bound: OMPL's distance of quaternions ``|q1 . q2| > 1 - 1e-9``
#: is 0 where their chord is up to 4.5e-5, and rounding.
CHORD_SLACK = 1e-4
#: How far a quaternion's squared norm may be from 1 for the rotation to count in the bounds.
UNIT_TOLERANCE = 1e-12
NONE = -1


class Setting(enum.IntEnum):
    """The index's integers (:attr:`KDIndex.ints`)."""

    POSITION = 0  # the position leaf's first coordinate (-1: none)
    POSITION_AXES = 1  # its coordinates: 0, 2 or 3
    ROTATION = 2  # the rotation leaf's first coordinate (-1: none)
    ROTATION_KIND = 3  # its Leaf kind (SO2 or SO3)
    AXES = 4  # index coordinates in all (0: no position or rotation leaf: the tree is scanned)
    BUILT = 5  # nodes 0 .. BUILT - 1 are in the blocks' k-d trees (a multiple of BLOCK)
    UNIT_ROTATIONS = 6  # 1 when the built nodes' rotations count in the bounds
    COUNT = 7


class KDIndex(NamedTuple):
    """One tree's k-d trees (one per block) over the nodes' index coordinates.

    ``order`` (capacity,): node indices in k-d layout, each block in its own rows (the subtree
    of ``order[lo:hi]`` has its splitting node at ``order[(lo + hi) // 2]``, smaller coordinates
    before it, larger after);
    ``points`` (capacity, axes): their index coordinates in the same order (a query walks them,
    not the tree's scattered states; ``axes``: up to 3 of a position and 4 of a rotation,
    ``ints[Setting.AXES]``); ``coordinates`` (capacity, axes): each node's, by node
    (the build's scratch); ``axis`` (capacity,): the splitting axis at the middle of each
    subtree of more than :data:`LEAF` nodes; ``low``, ``high`` (capacity, axes): the bounding
    box of each subtree's index coordinates, at its middle (no two subtrees share one);
    ``stack`` (STACK, 2): a query's pending subtrees; ``query`` (axes,): the query's index
    coordinates; ``weight`` (2,): the position's and the rotation's weights.
    """

    order: np.ndarray
    points: np.ndarray
    coordinates: np.ndarray
    axis: np.ndarray
    low: np.ndarray
    high: np.ndarray
    stack: np.ndarray
    query: np.ndarray
    ints: np.ndarray
    weight: np.ndarray


def _first_leaf(layout: SpaceLayout, kinds: tuple[Leaf, ...], sizes: tuple[int, ...]) -> int:
    """The first leaf of one of ``kinds`` (a real-vector one of one of ``sizes``) with a
    positive weight; -1 when there is none."""
    leaves = zip(layout.kind.tolist(), layout.weight.tolist(), layout.size.tolist())  # (Python numbers: faster)
    for leaf, (kind, weight, size) in enumerate(leaves):
        if kind in kinds and weight > 0.0 and (kind != Leaf.REAL or size in sizes):
            return leaf
    return NONE


def new_index(layout: SpaceLayout, capacity: int) -> KDIndex:
    """An empty index for a tree of ``capacity`` nodes in ``layout``."""
    ints = np.zeros(Setting.COUNT, dtype=np.int64)
    weight = np.zeros(2)
    position = _first_leaf(layout, (Leaf.REAL,), (2, 3))
    rotation = _first_leaf(layout, (Leaf.SO2, Leaf.SO3), ())
    ints[Setting.POSITION] = ints[Setting.ROTATION] = NONE
    if position != NONE:
        ints[Setting.POSITION], ints[Setting.POSITION_AXES] = layout.offset[position], layout.size[position]
        weight[0] = layout.weight[position]
    if rotation != NONE:
        ints[Setting.ROTATION], ints[Setting.ROTATION_KIND] = layout.offset[rotation], layout.kind[rotation]
        weight[1] = layout.weight[rotation]
    rotation_axes = 0 if rotation == NONE else (2 if layout.kind[rotation] == Leaf.SO2 else 4)
    axes = ints[Setting.AXES] = ints[Setting.POSITION_AXES] + rotation_axes
    rows = capacity if axes else 0  # (without axes the tree is scanned: no node arrays)
    return KDIndex(
        np.zeros(rows, dtype=np.int64),
        np.zeros((rows, axes)),
        np.zeros((rows, axes)),
        np.zeros(rows, dtype=np.int64),
        np.zeros((rows, axes)),
        np.zeros((rows, axes)),
        np.zeros((STACK, 2), dtype=np.int64),
        np.zeros(axes),
        ints,
        weight,
    )


def truncate(index: KDIndex, size: int) -> None:
    """``index`` for its tree cut back to ``size`` nodes (a planner's ``clear()`` empties its
    trees): where nodes it built are gone it forgets all it built, and the next query builds its
    blocks again."""
    if index.ints[Setting.BUILT] > size:
        index.ints[Setting.BUILT] = 0


def grown(index: KDIndex, capacity: int) -> KDIndex:
    """``index`` with room for ``capacity`` nodes (itself when it has that room, or when it has no
    axes: then the tree is scanned and the index's node arrays are never used)."""
    if len(index.order) >= capacity or index.ints[Setting.AXES] == 0:
        return index

    def more(array: np.ndarray) -> np.ndarray:
        bigger = np.zeros((capacity, *array.shape[1:]), dtype=array.dtype)
        bigger[: len(array)] = array
        return bigger

    return index._replace(
        order=more(index.order),
        points=more(index.points),
        coordinates=more(index.coordinates),
        axis=more(index.axis),
        low=more(index.low),
        high=more(index.high),
    )


@njit(cache=True, inline="always")
def _index_coordinates(index: KDIndex, state: np.ndarray, out: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """Write ``state``'s index coordinates (flat state (dim,)) into ``out`` (axes,); whether its
    rotation may count in the bounds (an angle; a quaternion of unit length)."""
    ints = index.ints
    position, axes = ints[Setting.POSITION], ints[Setting.POSITION_AXES]
    for k in range(axes):
        out[k] = state[position + k]
    rotation = ints[Setting.ROTATION]
    if rotation == NONE:
        return True
    if ints[Setting.ROTATION_KIND] == Leaf.SO2:
        angle = state[rotation]
        out[axes], out[axes + 1] = math.cos(angle), math.sin(angle)
        return True
    squared = 0.0
    for k in range(4):
        value = state[rotation + k]
        out[axes + k] = abs(value)
        squared += value * value
    return abs(squared - 1.0) <= UNIT_TOLERANCE


@njit(cache=True, inline="always")
def _bound(
    euclidean: bool, position_squared: float, rotation_squared: float, weight: np.ndarray, rotations: bool
) -> float:  # pragma: no cover (compiled)
    """The least key of a node whose index coordinates are at least these squared distances
    (position, rotation) from the query's: a squared distance (Euclidean spaces, as the scan
    compares) or a distance."""
    if euclidean:
        return position_squared
    bound = weight[0] * math.sqrt(position_squared)
    if rotations:
        bound += weight[1] * max(math.sqrt(rotation_squared) - CHORD_SLACK, 0.0)
    return bound


@njit_borrowing
def _select(order: np.ndarray, values: np.ndarray, column: int, lo: int, hi: int, k: int) -> None:  # pragma: no cover
    """Reorder ``order[lo:hi]`` so that ``order[k]`` has the k-th smallest ``values[., column]``,
    none after it smaller and none before it larger (Hoare's selection)."""
    while hi - lo > 1:
        pivot = values[order[(lo + hi) // 2], column]
        i, j = lo, hi - 1
        while i <= j:
            while values[order[i], column] < pivot:
                i += 1
            while values[order[j], column] > pivot:
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


@njit_borrowing
def _build(index: KDIndex, lo: int, hi: int) -> None:  # pragma: no cover (compiled)
    """The k-d tree of block ``lo .. hi - 1`` (nodes with their index coordinates worked out),
    in ``order[lo:hi]``, ``points[lo:hi]``, ``axis[lo:hi]``, ``low[lo:hi]``, ``high[lo:hi]``: each
    subtree's bounding box, and each subtree of more than :data:`LEAF` nodes split at its median
    along its widest axis (spreads weighted as their part of the distance)."""
    order, coordinates, ints = index.order, index.coordinates, index.ints
    axes, position_axes = ints[Setting.AXES], ints[Setting.POSITION_AXES]
    for node in range(lo, hi):
        order[node] = node
    stack = index.stack
    stack[0, 0], stack[0, 1] = lo, hi
    depth = 1
    while depth > 0:
        depth -= 1
        first, last = stack[depth, 0], stack[depth, 1]
        middle = (first + last) // 2
        widest, spread = 0, -1.0
        for axis in range(axes):
            smallest, largest = np.inf, -np.inf
            for i in range(first, last):
                value = coordinates[order[i], axis]
                smallest, largest = min(smallest, value), max(largest, value)
            index.low[middle, axis], index.high[middle, axis] = smallest, largest
            weighted = (largest - smallest) * index.weight[0 if axis < position_axes else 1]
            if weighted > spread:
                widest, spread = axis, weighted
        if last - first <= LEAF:
            continue  # a leaf: its nodes are scanned
        _select(order, coordinates, widest, first, last, middle)
        index.axis[middle] = widest
        stack[depth, 0], stack[depth, 1] = first, middle
        stack[depth + 1, 0], stack[depth + 1, 1] = middle + 1, last
        depth += 2
    for i in range(lo, hi):
        for axis in range(axes):
            index.points[i, axis] = coordinates[order[i], axis]


@njit_borrowing
def _add_blocks(index: KDIndex, states: np.ndarray, size: int) -> None:  # pragma: no cover (compiled)
    """Build the nodes up to the last whole :data:`BLOCK` of ``size`` into the index: their index
    coordinates worked out (once: a node's state never changes), then the blocks that the count
    of built units changes built again, as a binary counter carries."""
    ints = index.ints
    built = ints[Setting.BUILT]
    units, new_units = built // BLOCK, size // BLOCK
    unit = built == 0 or ints[Setting.UNIT_ROTATIONS] == 1
    for node in range(built, new_units * BLOCK):
        if not _index_coordinates(index, states[node], index.coordinates[node]):
            unit = False
    ints[Setting.UNIT_ROTATIONS] = 1 if unit else 0
    # The blocks of the bits above the highest that changed stay; those below it are new.
    changed = units ^ new_units
    high = 0
    while changed >> (high + 1):
        high += 1
    lo = ((new_units >> (high + 1)) << (high + 1)) * BLOCK
    for bit in range(high, -1, -1):
        if new_units >> bit & 1:
            _build(index, lo, lo + (BLOCK << bit))
            lo += BLOCK << bit
    ints[Setting.BUILT] = new_units * BLOCK


@njit_borrowing
def indexed_nearest(
    index: KDIndex, layout: SpaceLayout, states: np.ndarray, size: int, query: np.ndarray
) -> tuple[int, float]:  # pragma: no cover (compiled)
    """The node of ``states[:size]`` nearest ``query`` and its distance, as the linear scan
    (:func:`~ompl_balance.core.compiled_spaces.nearest`) answers; through the k-d trees when they apply."""
    ints = index.ints
    if ints[Setting.AXES] == 0 or size < INDEX_FROM:
        return nearest(layout, states, size, query)
    if size - ints[Setting.BUILT] >= BLOCK:
        _add_blocks(index, states, size)
    # (``euclidean`` a constant in each search: numba's code testing it node by node costs
    # several times more)
    if is_euclidean(layout):
        best, squared = _search(index, layout, states, size, query, True)
        return best, math.sqrt(squared)
    return _search(index, layout, states, size, query, False)


@njit(cache=True, inline="always")
def _box_gap(
    low: np.ndarray, high: np.ndarray, row: int, at: np.ndarray, first: int, last: int
) -> float:  # pragma: no cover (compiled)
    """The squared distance from index coordinates ``at`` (axes,) to the box ``low[row] ..
    high[row]`` over axes ``first .. last - 1``."""
    squared = 0.0
    for k in range(first, last):
        gap = max(low[row, k] - at[k], at[k] - high[row, k], 0.0)
        squared += gap * gap
    return squared


@njit(cache=True, inline="always")
def _point_gap(points: np.ndarray, row: int, at: np.ndarray, first: int, last: int) -> float:  # pragma: no cover
    """The squared distance from ``at`` to ``points[row]`` over coordinates ``first .. last - 1``
    (index coordinates, or a flat state and the tree's states)."""
    squared = 0.0
    for k in range(first, last):
        gap = points[row, k] - at[k]
        squared += gap * gap
    return squared


@njit(cache=True, inline="always")
def _search(
    index: KDIndex, layout: SpaceLayout, states: np.ndarray, size: int, query: np.ndarray, euclidean: bool
) -> tuple[int, float]:  # pragma: no cover (compiled)
    """The nearest node of ``states[:size]`` and what nodes are compared by: the squared distance
    (Euclidean spaces, as the scan compares) or the distance. Each block's k-d tree is descended
    (the largest first), then the nodes added since the last build are scanned. Boxes and nodes
    are tested on their position's share alone first, which decides most of them; a node's
    distance is worked out in full only where that share is not above the best found.

    (Nothing called per node takes the layout: in numba an inlined function that does, calling
    the distance only where a test passes, cost some 120 ns a call, taken or not, eighty times
    the position test it serves.)"""
    ints = index.ints
    axes, built = ints[Setting.AXES], ints[Setting.BUILT]
    weight, position, position_axes = index.weight, ints[Setting.POSITION], ints[Setting.POSITION_AXES]
    best, best_key = NONE, np.inf
    at = index.query
    rotations = _index_coordinates(index, query, at) and ints[Setting.UNIT_ROTATIONS] == 1
    order, points, stack, low, high = index.order, index.points, index.stack, index.low, index.high
    # the nodes added since the last build at the bottom of the stack, scanned last (the best
    # found being close, most fail on their position); above them the blocks, smallest first,
    # so that the largest (the likeliest to hold the nearest) is popped first
    stack[0, 0], stack[0, 1] = built, size
    depth, units, hi, bit = 1, built // BLOCK, built, 0
    while units >> bit:
        if units >> bit & 1:
            stack[depth, 0], stack[depth, 1] = hi - (BLOCK << bit), hi
            hi -= BLOCK << bit
            depth += 1
        bit += 1
    while depth > 0:
        depth -= 1
        lo, hi = stack[depth, 0], stack[depth, 1]
        scanned = lo >= built  # the nodes added since the last build, in no k-d tree
        middle = (lo + hi) // 2
        if not scanned:
            # every node of the subtree farther than the best: skipped (ties are looked at)
            position_squared = _box_gap(low, high, middle, at, 0, position_axes)
            if _bound(euclidean, position_squared, 0.0, weight, False) > best_key:
                continue
            rotation_squared = _box_gap(low, high, middle, at, position_axes, axes)
            if _bound(euclidean, position_squared, rotation_squared, weight, rotations) > best_key:
                continue
        # the nodes scanned, a leaf's nodes, or the splitting node of a larger subtree
        leaf = scanned or hi - lo <= LEAF
        first, last = (lo, hi) if leaf else (middle, middle + 1)
        for row in range(first, last):
            node = row if scanned else order[row]
            if not scanned:
                position_squared = _point_gap(points, row, at, 0, position_axes)
                if _bound(euclidean, position_squared, 0.0, weight, False) > best_key:
                    continue
                rotation_squared = _point_gap(points, row, at, position_axes, axes)
                if _bound(euclidean, position_squared, rotation_squared, weight, rotations) > best_key:
                    continue
            # the state's own position share (exact where the index coordinates round)
            key = _point_gap(states, node, query, position, position + position_axes)
            if not euclidean:  # (Euclidean: the position is the state, its square the key)
                # above the best where its square is by more than rounding: no root taken
                if key * (weight[0] * weight[0]) > best_key * best_key * (1.0 + 1e-9):
                    continue
                key = row_distance(layout, states, node, query)
            if key < best_key or (key == best_key and node < best):
                best, best_key = node, key
        if leaf:
            continue
        axis = index.axis[middle]
        if at[axis] < points[middle, axis]:  # the far side pushed first: the near side is popped first
            stack[depth, 0], stack[depth, 1] = middle + 1, hi
            stack[depth + 1, 0], stack[depth + 1, 1] = lo, middle
        else:
            stack[depth, 0], stack[depth, 1] = lo, middle
            stack[depth + 1, 0], stack[depth + 1, 1] = middle + 1, hi
        depth += 2
    return best, best_key
