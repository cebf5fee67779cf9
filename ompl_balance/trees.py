"""Tree storage and exact nearest neighbour for the planners.

Two stores with one interface, chosen by :mod:`ompl_balance.spaces`:

:class:`ArrayTree`
    real-vector states in one contiguous ``(capacity, dim)`` float64 array grown by
    doubling; nearest neighbour by one vectorised distance computation (exact).
:class:`StateTree`
    OMPL states of any space in a list; nearest neighbour by ``si.distance`` over all
    nodes (exact, slower: one call into OMPL per node).

Both keep, per node, the index of its parent (``-1`` for a root) and of its root, so
a path is read off by following parents. Node ``i`` is the ``i``-th state added.
"""

from __future__ import annotations

import math

import numpy as np
from ompl import base as ob

NO_PARENT = -1


class _Links:
    """Parent and root indices shared by both stores, grown by doubling."""

    def __init__(self, capacity: int) -> None:
        self.parents = np.full(capacity, NO_PARENT, dtype=np.int64)
        self.roots = np.zeros(capacity, dtype=np.int64)
        self.size = 0

    def _link(self, parent: int) -> int:
        index = self.size
        if index == len(self.parents):
            self.parents = np.concatenate([self.parents, np.full(index, NO_PARENT, dtype=np.int64)])
            self.roots = np.concatenate([self.roots, np.zeros(index, dtype=np.int64)])
        self.parents[index] = parent
        self.roots[index] = index if parent == NO_PARENT else self.roots[parent]
        self.size = index + 1
        return index

    def __len__(self) -> int:
        return self.size

    def parent(self, index: int) -> int:
        return int(self.parents[index])

    def root(self, index: int) -> int:
        return int(self.roots[index])

    def branch(self, index: int) -> list[int]:
        """Node indices from ``index`` up to its root, ``index`` first."""
        nodes = [index]
        while self.parents[nodes[-1]] != NO_PARENT:
            nodes.append(int(self.parents[nodes[-1]]))
        return nodes

    def reparent(self, subtree: np.ndarray, parent: int) -> None:
        """Hang a subtree under ``parent`` (RRT* rewiring).

        ``subtree``: indices of the subtree's top node (first) and all its descendants;
        their roots become ``parent``'s root.
        """
        self.parents[subtree[0]] = parent
        self.roots[subtree] = self.roots[parent]

    def near(self, state, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Indices of the nodes within ``radius`` of ``state`` (exact) and their distances."""
        distances = self.distances(state)
        within = np.flatnonzero(distances <= radius)
        return within, distances[within]

    def clear(self) -> None:
        self.size = 0


_EPS = float(np.finfo(float).eps)
_BRUTE_FORCE_SIZE = 256  # below this, plain squared distances beat the matrix-vector ranking


class ArrayTree(_Links):
    """Real-vector states of one tree, shape ``(len(tree), dim)``."""

    def __init__(self, dim: int, capacity: int = 1024) -> None:
        super().__init__(capacity)
        self._states = np.empty((capacity, dim))
        # |state|^2 per node for nearest() on large trees, filled in batches when needed
        self._squared_norms = np.empty(capacity)
        self._normed = 0  # nodes whose squared norm is filled in
        self._largest_norm = 0.0

    @property
    def states(self) -> np.ndarray:
        """The tree's states, ``(len(tree), dim)``; a view, valid until the next add."""
        return self._states[: self.size]

    def state(self, index: int) -> np.ndarray:
        return self._states[index]

    def add(self, state: np.ndarray, parent: int = NO_PARENT) -> int:
        """Add ``state`` (``(dim,)``) as a child of ``parent``; return its index."""
        index = self._link(parent)
        if index == len(self._states):
            self._states = np.concatenate([self._states, np.empty_like(self._states)])
            self._squared_norms = np.concatenate([self._squared_norms, np.empty_like(self._squared_norms)])
        self._states[index] = state
        return index

    def nearest(self, state: np.ndarray) -> tuple[int, float]:
        """Index of the node closest to ``state`` (Euclidean) and its distance (exact).

        Small trees: squared distances of all nodes. Larger trees: nodes ranked by
        ``|s|^2 - 2 s.q`` (one matrix-vector product, fewer temporaries), with
        near-ties within that expansion's rounding error settled by exact distances.
        """
        states = self._states[: self.size]
        if self.size <= _BRUTE_FORCE_SIZE:
            offsets = states - state
            squared = np.einsum("ij,ij->i", offsets, offsets)
            index = int(squared.argmin())
            return index, math.sqrt(squared[index])
        if self._normed < self.size:  # norms of the nodes added since the last large-tree query
            fresh = states[self._normed :]
            norms = np.einsum("ij,ij->i", fresh, fresh)
            self._squared_norms[self._normed : self.size] = norms
            self._largest_norm = max(self._largest_norm, math.sqrt(float(norms.max())))
            self._normed = self.size
        scores = self._squared_norms[: self.size] - 2.0 * (states @ state)
        index = int(scores.argmin())
        reach = self._largest_norm + math.sqrt(float(state @ state))
        near_ties = scores <= scores[index] + 16.0 * len(state) * _EPS * reach * reach
        if np.count_nonzero(near_ties) > 1:
            ties = near_ties.nonzero()[0]
            offsets = states[ties] - state
            index = int(ties[np.einsum("ij,ij->i", offsets, offsets).argmin()])
        offset = states[index] - state
        return index, math.sqrt(float(offset @ offset))

    def clear(self) -> None:
        super().clear()
        self._normed = 0
        self._largest_norm = 0.0

    def distances(self, state: np.ndarray) -> np.ndarray:
        """Euclidean distance from every node to ``state``, ``(len(tree),)``."""
        offsets = self._states[: self.size] - state
        return np.sqrt(np.einsum("ij,ij->i", offsets, offsets))


class StateTree(_Links):
    """OMPL states of one tree, for any state space; nearest by ``si.distance``."""

    def __init__(self, si: ob.SpaceInformation, capacity: int = 1024) -> None:
        super().__init__(capacity)
        self._distance = si.distance
        self._alloc = si.allocState
        self._copy = si.copyState
        self._states: list[ob.State] = []

    @property
    def states(self) -> list[ob.State]:
        return self._states

    def state(self, index: int) -> ob.State:
        return self._states[index]

    def add(self, state: ob.State, parent: int = NO_PARENT) -> int:
        """Add a copy of ``state`` as a child of ``parent``; return its index."""
        copy = self._alloc()
        self._copy(copy, state)
        self._states.append(copy)
        return self._link(parent)

    def nearest(self, state: ob.State) -> tuple[int, float]:
        distance = self._distance
        distances = [distance(node, state) for node in self._states]
        index = int(np.argmin(distances))
        return index, distances[index]

    def distances(self, state: ob.State) -> np.ndarray:
        """``si.distance`` from every node to ``state``, ``(len(tree),)``."""
        distance = self._distance
        return np.array([distance(node, state) for node in self._states], dtype=float)

    def clear(self) -> None:
        super().clear()
        self._states = []
