"""The geometry of flat state spaces, compiled: distance, interpolation, sampling and tree scans.

The same formulas as :mod:`ompl_balance.core.layout` (OMPL's metric and interpolation, leaf
by leaf), compiled with numba for the compiled engine, operation for operation: sums run
over the coordinates in order, so for real-vector spaces both compute the same numbers to
the last bit (SO(2) and SO(3) leaves call the C library's ``acos``/``sin``, which numpy's
vectorised versions may round differently in the last bit).

Scans read the rows ``states[:size]`` of a C-contiguous ``(capacity, dim)`` float64 array
(:class:`~ompl_balance.core.trees.ArrayTree`'s storage). The Euclidean scans are compiled
for one fixed signature, so that a process compiles (or loads from numba's cache) them
once, at import, and Python callers skip numba's type dispatch; importing this module
therefore takes about half a second the first time in a process, which is why
:mod:`ompl_balance.core.trees` loads it in the background. The annotations are for readers:
numba compiles the signatures given to ``njit``.
"""

import math

import numpy as np

from .kernel_cache import njit, njit_borrowing
from .layout import QUATERNION_TOLERANCE, Leaf, SpaceLayout

_EPS = float(np.finfo(np.float64).eps)
_REAL, _SO2, _SO3 = int(Leaf.REAL), int(Leaf.SO2), int(Leaf.SO3)


@njit(cache=True, inline="always")
def _squared_distance(states: np.ndarray, row: int, query: np.ndarray) -> float:  # pragma: no cover (compiled)
    squared = 0.0
    for k in range(query.shape[0]):
        offset = states[row, k] - query[k]
        squared += offset * offset
    return squared


@njit("Tuple((int64, float64))(float64[:, ::1], int64, float64[:])", cache=True)
def euclidean_nearest(states: np.ndarray, size: int, query: np.ndarray) -> tuple[int, float]:  # pragma: no cover
    """Index of the row of ``states[:size]`` closest to ``query`` (the first on ties) and its squared distance."""
    best, best_squared = 0, np.inf
    for i in range(size):
        squared = _squared_distance(states, i, query)
        if squared < best_squared:
            best, best_squared = i, squared
    return best, best_squared


@njit("int64(float64[:, ::1], int64, float64[:], float64, int64[::1], float64[::1])", cache=True)
def euclidean_within(  # pragma: no cover (compiled)
    states: np.ndarray, size: int, query: np.ndarray, radius: float, indices: np.ndarray, distances: np.ndarray
) -> int:
    """Rows of ``states[:size]`` within ``radius`` of ``query``, written to ``indices`` and
    ``distances`` in index order; returns how many."""
    count = 0
    limit = radius * radius
    for i in range(size):
        squared = _squared_distance(states, i, query)
        if squared <= limit:
            indices[count] = i
            distances[count] = math.sqrt(squared)
            count += 1
    return count


@njit(cache=True, inline="always")
def is_euclidean(layout: SpaceLayout) -> bool:  # pragma: no cover (compiled)
    """One real-vector leaf of weight 1 (:attr:`SpaceLayout.euclidean`)."""
    return len(layout.kind) == 1 and layout.kind[0] == _REAL and layout.weight[0] == 1.0


@njit(cache=True, inline="always")
def leaf_distance(
    layout: SpaceLayout, leaf: int, states: np.ndarray, row: int, b: np.ndarray
) -> float:  # pragma: no cover
    """OMPL's distance of ``states[row]`` and ``b`` in leaf ``leaf``'s own space (unweighted).

    (A row index rather than a row: a row would be a new array, counted in and out of
    numba's reference counts, for each of the many distances a scan takes.)
    """
    start = layout.offset[leaf]
    kind = layout.kind[leaf]
    if kind == _REAL:
        squared = 0.0
        for k in range(start, start + layout.size[leaf]):
            offset = b[k] - states[row, k]
            squared += offset * offset
        return math.sqrt(squared)
    if kind == _SO2:
        d = abs(states[row, start] - b[start])
        return 2.0 * math.pi - d if d > math.pi else d
    dot = states[row, start] * b[start]
    for k in range(start + 1, start + 4):
        dot += states[row, k] * b[k]
    dot = abs(dot)
    return 0.0 if dot > 1.0 - QUATERNION_TOLERANCE else math.acos(dot)


@njit(cache=True, inline="always")
def row_distance(layout: SpaceLayout, states: np.ndarray, row: int, b: np.ndarray) -> float:  # pragma: no cover
    """OMPL's distance of ``states[row]`` and flat state ``b``: the weighted sum over the leaves."""
    total = 0.0
    for leaf in range(len(layout.kind)):
        total += layout.weight[leaf] * leaf_distance(layout, leaf, states, row, b)
    return total


@njit_borrowing
def distance(layout: SpaceLayout, a: np.ndarray, b: np.ndarray) -> float:  # pragma: no cover (compiled)
    """OMPL's distance of flat states ``a`` and ``b``."""
    return row_distance(layout, a[None, :], 0, b)


@njit_borrowing
def segment_count(layout: SpaceLayout, a: np.ndarray, b: np.ndarray) -> int:  # pragma: no cover (compiled)
    """OMPL's ``validSegmentCount(a, b)``: the largest over the leaves of ``factor * ceil(d / segment)``."""
    count = 0
    rows = a[None, :]
    for leaf in range(len(layout.kind)):
        d = leaf_distance(layout, leaf, rows, 0, b)
        count = max(count, layout.factor[leaf] * math.ceil(d / layout.segment[leaf]))
    return count


@njit(cache=True, inline="always")
def interpolate(
    layout: SpaceLayout, a: np.ndarray, b: np.ndarray, t: float, out: np.ndarray
) -> None:  # pragma: no cover
    """Write the state a fraction ``t`` of the way from ``a`` to ``b`` (OMPL's interpolation) into ``out``.

    Inlined where it is called: a call that passes the layout's arrays costs more than the
    interpolation itself (some 150 ns against a few for a real-vector state).
    """
    for leaf in range(len(layout.kind)):
        start, size = layout.offset[leaf], layout.size[leaf]
        kind = layout.kind[leaf]
        if kind == _REAL:
            for k in range(start, start + size):
                out[k] = a[k] + t * (b[k] - a[k])
        elif kind == _SO2:
            diff = b[start] - a[start]
            if abs(diff) <= math.pi:
                out[start] = a[start] + diff * t
            else:
                diff = 2.0 * math.pi - diff if diff > 0.0 else -2.0 * math.pi - diff
                value = a[start] - diff * t
                if value > math.pi:
                    value -= 2.0 * math.pi
                elif value < -math.pi:
                    value += 2.0 * math.pi
                out[start] = value
        else:
            dot = a[start] * b[start] + a[start + 1] * b[start + 1] + a[start + 2] * b[start + 2]
            dot += a[start + 3] * b[start + 3]
            theta = 0.0 if abs(dot) > 1.0 - QUATERNION_TOLERANCE else math.acos(abs(dot))
            if theta <= _EPS:
                for k in range(start, start + 4):
                    out[k] = a[k]
                continue
            d = 1.0 / math.sin(theta)
            s0 = math.sin((1.0 - t) * theta)
            s1 = math.sin(t * theta)
            if dot < 0.0:
                s1 = -s1
            for k in range(start, start + 4):
                out[k] = (a[k] * s0 + b[k] * s1) * d


@njit_borrowing
def equal(layout: SpaceLayout, a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover (compiled)
    """OMPL's ``equalStates``: every leaf equal within its space's tolerance."""
    for leaf in range(len(layout.kind)):
        start, size = layout.offset[leaf], layout.size[leaf]
        kind = layout.kind[leaf]
        if kind == _REAL:
            for k in range(start, start + size):
                if abs(a[k] - b[k]) > 2.0 * _EPS:
                    return False
        elif kind == _SO2:
            if not abs(a[start] - b[start]) < 2.0 * _EPS:
                return False
        elif not leaf_distance(layout, leaf, a[None, :], 0, b) < _EPS:
            return False
    return True


@njit_borrowing
def samples_from_uniforms(layout: SpaceLayout, uniforms: np.ndarray, out: np.ndarray) -> None:  # pragma: no cover
    """Uniform samples of the space into ``out`` (rows, dim), one a row of ``uniforms`` (rows, total_draws).

    One call for a block of samples, the layout's arrays read once: a call per sample that
    passes the layout costs some 100 ns more than the sample itself.
    """
    kinds, offsets, sizes, draw_offsets = layout.kind, layout.offset, layout.size, layout.draw_offset
    lows, highs = layout.low, layout.high
    for row in range(out.shape[0]):
        for leaf in range(len(kinds)):
            start, size, first = offsets[leaf], sizes[leaf], draw_offsets[leaf]
            kind = kinds[leaf]
            if kind == _REAL:
                for k in range(start, start + size):
                    out[row, k] = lows[k] + (highs[k] - lows[k]) * uniforms[row, first + k - start]
            elif kind == _SO2:
                out[row, start] = -math.pi + (2.0 * math.pi) * uniforms[row, first]
            else:
                r1, r2 = math.sqrt(1.0 - uniforms[row, first]), math.sqrt(uniforms[row, first])
                t1, t2 = 2.0 * math.pi * uniforms[row, first + 1], 2.0 * math.pi * uniforms[row, first + 2]
                out[row, start] = math.sin(t1) * r1
                out[row, start + 1] = math.cos(t1) * r1
                out[row, start + 2] = math.sin(t2) * r2
                out[row, start + 3] = math.cos(t2) * r2


@njit_borrowing
def nearest(
    layout: SpaceLayout, states: np.ndarray, size: int, query: np.ndarray
) -> tuple[int, float]:  # pragma: no cover
    """Index of the row of ``states[:size]`` nearest ``query`` under the layout's metric (the first on ties) and its distance."""
    if is_euclidean(layout):
        best, squared = euclidean_nearest(states, size, query)
        return best, math.sqrt(squared)
    best, best_distance = 0, np.inf
    for i in range(size):
        d = row_distance(layout, states, i, query)
        if d < best_distance:
            best, best_distance = i, d
    return best, best_distance
