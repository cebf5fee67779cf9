"""Tree storage and exact nearest neighbour for the planners.

Two stores with one interface (:class:`Tree`), chosen by :mod:`ompl_balance.core.spaces`:

:class:`ArrayTree`
    flat states (:mod:`ompl_balance.core.layout`: real-vector spaces, SO(2), SO(3), SE(2),
    SE(3) and compounds of them) in one contiguous ``(capacity, dim)`` float64 array grown
    by doubling; nearest and near neighbours by a scan of all nodes (exact): numpy while
    the process's trees are small, the compiled kernels of :mod:`ompl_balance.core.compiled_spaces`
    once a tree has reached :data:`COMPILED_SCANS_FROM` nodes and they have loaded in a
    background thread (so that no solve waits for numba), or, for Euclidean trees, once the
    compiled engine has imported them; the same answers either way.
:class:`StateTree`
    OMPL states of any space in a list; nearest neighbour by ``si.distance`` over all
    nodes (exact, slower: one call into OMPL per node).

Both keep, per node, the index of its parent (``-1`` for a root) and of its root, so
a path is read off by following parents. Node ``i`` is the ``i``-th state added (until
:meth:`Tree.compact` removes nodes and renumbers the rest in order).
"""

from __future__ import annotations

import math
import os
import sys
import threading
from types import ModuleType
from typing import Any, NamedTuple, Protocol

import numpy as np
from ompl import base as ob

from .layout import SpaceLayout, distances, squared_distances

NO_PARENT = -1


class Tree(Protocol):
    """What planners ask of a tree: nodes with parents and roots, and exact neighbour queries.

    Points are ``(dim,)`` arrays (:class:`ArrayTree`) or OMPL states (:class:`StateTree`).
    """

    parents: np.ndarray  # (capacity,) parent index per node, NO_PARENT for a root

    def __len__(self) -> int: ...
    def state(self, index: int) -> Any: ...
    def add(self, state: Any, parent: int = NO_PARENT) -> int: ...
    def parent(self, index: int) -> int: ...
    def root(self, index: int) -> int: ...
    def branch(self, index: int) -> list[int]: ...
    def reparent(self, subtree: np.ndarray, parent: int) -> None: ...
    def compact(self, keep: np.ndarray) -> np.ndarray: ...
    def nearest(self, state: Any) -> tuple[int, float]: ...
    def near(self, state: Any, radius: float) -> tuple[np.ndarray, np.ndarray]: ...
    def distances(self, state: Any) -> np.ndarray: ...
    def clear(self) -> None: ...


class _Links:
    """Parent and root indices shared by both stores, grown by doubling."""

    def __init__(self, capacity: int) -> None:
        self.parents = np.full(capacity, NO_PARENT, dtype=np.int64)
        self.roots = np.zeros(capacity, dtype=np.int64)
        self.size = 0

    def _link(self, parent: int) -> int:
        index = self.size
        if index == len(self.parents):
            self._grow_links(2 * index)
        self.parents[index] = parent
        self.roots[index] = index if parent == NO_PARENT else self.roots[parent]
        self.size = index + 1
        return index

    def _grow_links(self, capacity: int) -> None:
        grown = len(self.parents)
        capacity = max(capacity, 2 * grown)
        self.parents = np.concatenate([self.parents, np.full(capacity - grown, NO_PARENT, dtype=np.int64)])
        self.roots = np.concatenate([self.roots, np.zeros(capacity - grown, dtype=np.int64)])

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

    def compact(self, keep: np.ndarray) -> np.ndarray:
        """Keep only the nodes where ``keep`` (``(len(tree),)`` bool) is true, renumbered in
        order; every kept node's parent must be kept. Returns each old node's new index
        (``NO_PARENT`` for a removed node)."""
        kept = np.flatnonzero(keep[: self.size])
        new_index = np.full(self.size, NO_PARENT, dtype=np.int64)
        new_index[kept] = np.arange(len(kept))
        parents = self.parents[kept]
        if np.any((parents != NO_PARENT) & (new_index[np.maximum(parents, 0)] == NO_PARENT)):
            raise ValueError("compact() would keep a node whose parent it removes")
        self.parents[: len(kept)] = np.where(parents == NO_PARENT, NO_PARENT, new_index[np.maximum(parents, 0)])
        self.roots[: len(kept)] = new_index[self.roots[kept]]
        self._keep_states(kept)
        self.size = len(kept)
        return new_index

    def _keep_states(self, kept: np.ndarray) -> None:
        """Keep the states of nodes ``kept`` (ascending), as nodes ``0 .. len(kept) - 1``."""
        raise NotImplementedError

    def clear(self) -> None:
        self.size = 0


#: Tree size at which an :class:`ArrayTree` starts loading the compiled kernels in the
#: background; until they are loaded, every tree scans with numpy (a Euclidean one only until
#: the compiled engine imports them), afterwards every tree with the kernels
#: (``benchmarks/bench_rrtc.py --scans`` measures the trade-off).
COMPILED_SCANS_FROM = 1024


class _ScanLoader:
    """Loads the compiled scans once per process: now (:meth:`load`) or in the background
    (:meth:`loaded`)."""

    def __init__(self) -> None:
        self.scans: ModuleType | None = None
        self.thread: threading.Thread | None = None

    def load(self) -> ModuleType:
        from . import compiled_spaces

        self.scans = compiled_spaces
        return compiled_spaces

    def loaded(self) -> ModuleType | None:
        if self.scans is None and self.thread is None:
            if self.imported() is not None:
                return self.load()
            # (or being imported, e.g. by the compiled engine's loader: waiting for that
            # import here would stall a solve, so the background thread does)
            self.thread = threading.Thread(target=self.load, name="ompl_balance-load-scans")
            self.thread.start()
        return self.scans

    @staticmethod
    def imported() -> ModuleType | None:
        """The compiled scans where something else has imported them already (the compiled
        engine, a forkserver's preload), else ``None``; loads nothing."""
        module = sys.modules.get("ompl_balance.core.compiled_spaces")
        if module is None or getattr(module.__spec__, "_initializing", False):
            return None
        return module

    def finish(self) -> None:
        """Wait for a background load (a process must not fork in the middle of an import)."""
        if self.thread is not None:
            self.thread.join()


_LOADER = _ScanLoader()
os.register_at_fork(before=_LOADER.finish)


def load_scans() -> ModuleType:
    """The compiled scans (:mod:`ompl_balance.core.compiled_spaces`), loaded now.

    The first call in a process imports numba and loads the kernels (about half a second).
    """
    return _LOADER.load()


def compiled_scans() -> ModuleType | None:
    """The compiled scans if they are loaded, else ``None`` (and their loading started in a
    background thread, so that no solve waits for it)."""
    return _LOADER.loaded()


class TreeStorage(NamedTuple):
    """An :class:`ArrayTree`'s arrays, for compiled code that adds nodes in place: ``states``
    (capacity, dim), ``parents`` and ``roots`` (capacity,); rows ``[0, len(tree))`` are nodes."""

    states: np.ndarray
    parents: np.ndarray
    roots: np.ndarray


class ArrayTree(_Links):
    """Flat states of one tree, shape ``(len(tree), dim)``, with the metric of ``layout``
    (:mod:`ompl_balance.core.layout`; ``None``: Euclidean).

    Nearest and near queries scan all nodes (exact): with numpy until the compiled kernels
    are loaded (a tree of :data:`COMPILED_SCANS_FROM` nodes starts their loading; a Euclidean
    tree takes them as soon as the compiled engine has imported them), then in one compiled
    loop (for the tree sizes sampling planners reach, faster than any index would be from
    Python). For real-vector states both scans return the same answers to the last bit.
    """

    def __init__(self, dim: int, capacity: int = 1024, layout: SpaceLayout | None = None) -> None:
        super().__init__(capacity)
        self._states = np.empty((capacity, dim))
        self._layout = None if layout is None or layout.euclidean else layout
        # scratch output of the compiled near(), one slot per node
        self._near_indices = np.empty(capacity, dtype=np.int64)
        self._near_distances = np.empty(capacity)

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
            self._grow_states(2 * index)
        self._states[index] = state
        return index

    def reserve(self, capacity: int) -> None:
        """Make room for ``capacity`` nodes (doubling), so compiled code can add nodes in place."""
        if capacity > len(self.parents):
            self._grow_links(capacity)
        if capacity > len(self._states):
            self._grow_states(len(self.parents))

    def storage(self) -> TreeStorage:
        """The arrays behind the tree (valid until it grows); see :meth:`adopt`."""
        return TreeStorage(self._states, self.parents, self.roots)

    def adopt(self, size: int) -> None:
        """Take rows ``[len(tree), size)`` of :meth:`storage`, written by compiled code, as new nodes."""
        if not self.size <= size <= len(self._states):
            raise ValueError(f"adopt({size}): the tree has {self.size} nodes and room for {len(self._states)}")
        self.size = size

    def _grow_states(self, capacity: int) -> None:
        grown = np.empty((capacity, self._states.shape[1]))
        grown[: len(self._states)] = self._states
        self._states = grown
        self._near_indices = np.empty(capacity, dtype=np.int64)
        self._near_distances = np.empty(capacity)

    def _compiled(self) -> ModuleType | None:
        """The compiled scans once loaded, whatever the tree's size (their loading starts when a
        tree first reaches :data:`COMPILED_SCANS_FROM` nodes), and for a Euclidean tree as soon
        as the compiled engine has imported them: their Euclidean scans are compiled at import,
        so nothing waits for numba (a call costs about 1 us against numpy's 4-6 us at a few
        hundred nodes; another metric's scan compiles at its first call)."""
        scans = _LOADER.scans
        if scans is None:
            if self.size >= COMPILED_SCANS_FROM:
                scans = compiled_scans()
            elif self._layout is None:
                scans = _LOADER.imported()
        return scans

    def nearest(self, state: np.ndarray) -> tuple[int, float]:
        """Index of the node closest to ``state`` (the first on ties) and its distance."""
        if self.size == 0:
            raise ValueError("nearest() of an empty tree: add a root first")
        scans = self._compiled()
        if self._layout is not None:
            if scans is None:
                all_distances = distances(self._layout, self._states[: self.size], state)
                index = int(all_distances.argmin())
                return index, float(all_distances[index])
            index, nearest_distance = scans.nearest(self._layout, self._states, self.size, state)
            return index, nearest_distance
        if scans is None:
            squared = squared_distances(self._states[: self.size], state)
            index = int(squared.argmin())
            return index, math.sqrt(squared[index])
        index, nearest_squared = scans.euclidean_nearest(self._states, self.size, state)
        return index, math.sqrt(nearest_squared)

    def near(self, state: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Indices of the nodes within ``radius`` of ``state`` (exact, ascending) and their distances."""
        if self._layout is not None:
            all_distances = self.distances(state)
            indices = np.flatnonzero(all_distances <= radius)
            return indices, all_distances[indices]
        scans = self._compiled()
        if scans is None:
            squared = squared_distances(self._states[: self.size], state)
            indices = np.flatnonzero(squared <= radius * radius)
            return indices, np.sqrt(squared[indices])
        count = scans.euclidean_within(self._states, self.size, state, radius, self._near_indices, self._near_distances)
        return self._near_indices[:count].copy(), self._near_distances[:count].copy()

    def distances(self, state: np.ndarray) -> np.ndarray:
        """The distance from every node to ``state``, ``(len(tree),)``."""
        if self._layout is not None:
            return distances(self._layout, self._states[: self.size], state)
        return np.sqrt(squared_distances(self._states[: self.size], state))

    def _keep_states(self, kept: np.ndarray) -> None:
        self._states[: len(kept)] = self._states[kept]


#: Pivots whose distances to every node a :class:`StateTree` in a metric space keeps.
PIVOTS = 8
#: Trees with fewer nodes are scanned whole.
PIVOTED_FROM = 64


class StateTree(_Links):
    """OMPL states of one tree, for any state space; nearest by ``si.distance``.

    In a metric space (``space.isMetricSpace()``) the tree keeps each node's distance to a few
    *pivots* (its first :data:`PIVOTS` nodes), so that by the triangle inequality
    ``|d(q, p) - d(x, p)|`` bounds ``d(q, x)`` from below for every node ``x`` at once, in numpy;
    a query computes exact distances (one call into OMPL each) only for nodes in the order of
    those bounds, until the next bound exceeds the best distance found. The answers are the
    full scan's (the first node among equally near ones). In other spaces every query scans.
    """

    def __init__(self, si: ob.SpaceInformation, capacity: int = 1024) -> None:
        super().__init__(capacity)
        self._distance = si.distance
        self._alloc = si.allocState
        self._copy = si.copyState
        self._states: list[ob.State] = []
        self._metric = bool(si.getStateSpace().isMetricSpace())
        self._to_pivots = np.zeros((capacity, PIVOTS))  # node x pivot distances

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
        index = self._link(parent)
        if self._metric:
            self._measure(index)
        return index

    def _measure(self, index: int) -> None:
        """Node ``index``'s distances to the pivots (and, for a pivot, the earlier nodes' to it)."""
        if index == len(self._to_pivots):
            self._to_pivots = np.concatenate([self._to_pivots, np.zeros_like(self._to_pivots)])
        state, pivots = self._states[index], self._states[:PIVOTS]
        self._to_pivots[index, : len(pivots)] = [self._distance(state, pivot) for pivot in pivots]
        if index < PIVOTS:
            self._to_pivots[:index, index] = [self._distance(node, state) for node in self._states[:index]]

    def nearest(self, state: ob.State) -> tuple[int, float]:
        """Index of the node closest to ``state`` (the first on ties) and its distance."""
        size = len(self._states)
        if not self._metric or size < PIVOTED_FROM:
            distances = self.distances(state)
            index = int(np.argmin(distances))
            return index, float(distances[index])
        distance = self._distance
        bounds = self._lower_bounds(state)
        best, best_distance = -1, math.inf
        for node in np.argsort(bounds, kind="stable").tolist():
            if bounds[node] > best_distance * (1.0 + 1e-12) + 1e-300:
                break  # every node left is farther than the best (beyond the bounds' rounding)
            d = distance(self._states[node], state)
            if d < best_distance or (d == best_distance and node < best):
                best, best_distance = node, d
        return best, best_distance

    def distances(self, state: ob.State) -> np.ndarray:
        """``si.distance`` from every node to ``state``, ``(len(tree),)``."""
        distance = self._distance
        return np.array([distance(node, state) for node in self._states], dtype=float)

    def near(self, state: ob.State, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Indices of the nodes within ``radius`` of ``state`` (exact, ascending) and their distances."""
        if not self._metric or len(self._states) < PIVOTED_FROM:
            distances = self.distances(state)
            within = np.flatnonzero(distances <= radius)
            return within, distances[within]
        candidates = np.flatnonzero(self._lower_bounds(state) <= radius * (1.0 + 1e-12) + 1e-300)
        distances = np.array([self._distance(self._states[node], state) for node in candidates.tolist()], dtype=float)
        keep = distances <= radius
        return candidates[keep], distances[keep]

    def _lower_bounds(self, state: ob.State) -> np.ndarray:
        """``max_p |d(state, p) - d(x, p)|`` for every node ``x``: each a lower bound of ``d(state, x)``."""
        size = len(self._states)
        to_query = np.array([self._distance(state, pivot) for pivot in self._states[:PIVOTS]])
        return np.abs(self._to_pivots[:size, : len(to_query)] - to_query).max(axis=1)

    def _keep_states(self, kept: np.ndarray) -> None:
        self._states = [self._states[index] for index in kept.tolist()]
        if self._metric:  # the pivots may be gone: measure again
            for index in range(len(self._states)):
                self._measure(index)

    def clear(self) -> None:
        super().clear()
        self._states = []
