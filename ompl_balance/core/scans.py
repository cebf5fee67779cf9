"""Compiled scans over a tree's states: the nearest node, and the nodes within a radius.

Both read the rows ``states[:size]`` of a C-contiguous ``(capacity, dim)`` float64
array (:class:`~ompl_balance.core.trees.ArrayTree`'s storage) and compare squared
Euclidean distances exactly, one row at a time. Compiled with numba for one fixed
signature, so a process compiles (or loads from numba's cache) each kernel once, at
import; importing this module therefore takes about half a second the first time in
a process, which is why :mod:`ompl_balance.core.trees` loads it in the background, and
only once a tree is large enough for it to pay (smaller trees scan with numpy, to the
same last bit). The annotations are for readers: numba compiles the signatures given
to ``njit``.
"""

import math

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _squared_distance(states: np.ndarray, row: int, query: np.ndarray) -> float:  # pragma: no cover (compiled)
    squared = 0.0
    for k in range(query.shape[0]):
        offset = states[row, k] - query[k]
        squared += offset * offset
    return squared


@njit("Tuple((int64, float64))(float64[:, ::1], int64, float64[:])", cache=True)
def nearest(states: np.ndarray, size: int, query: np.ndarray) -> tuple[int, float]:  # pragma: no cover (compiled)
    """Index of the row of ``states[:size]`` closest to ``query`` and its squared distance."""
    best, best_squared = 0, np.inf
    for i in range(size):
        squared = _squared_distance(states, i, query)
        if squared < best_squared:
            best, best_squared = i, squared
    return best, best_squared


@njit("int64(float64[:, ::1], int64, float64[:], float64, int64[::1], float64[::1])", cache=True)
def within(  # pragma: no cover (compiled)
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
