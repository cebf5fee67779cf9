"""The compiled engine's k-d tree over positions and rotations answers every query as the
linear scan does: the same node (the lowest index among equally near ones) and the same
distance, while the tree grows between queries (nodes added since the last build scanned,
rebuilds as it grows)."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit
from ompl import base as ob

from ompl_balance.core.compiled_spaces import nearest
from ompl_balance.core.layout import layout_for
from ompl_balance.engine.index import INDEX_FROM, indexed_nearest, new_index


def real_space(dim: int) -> ob.StateSpace:
    space = ob.RealVectorStateSpace(dim)
    space.setBounds(-1.0, 1.0)
    return space


def rigid_space(space: ob.StateSpace, positions: int) -> ob.StateSpace:
    """``space`` (SE(2) or SE(3)) with its ``positions`` coordinates bounded to [-1, 1]."""
    bounds = ob.RealVectorBounds(positions)
    bounds.setLow(-1.0)
    bounds.setHigh(1.0)
    space.setBounds(bounds)
    return space


def weighted_compound() -> ob.StateSpace:
    space = ob.CompoundStateSpace()
    space.addSubspace(real_space(3), 0.5)
    space.addSubspace(ob.SO2StateSpace(), 2.0)
    return space


SPACES = {
    "R^2": lambda: real_space(2),
    "R^3": lambda: real_space(3),
    "SE(2)": lambda: rigid_space(ob.SE2StateSpace(), 2),
    "SE(3)": lambda: rigid_space(ob.SE3StateSpace(), 3),
}
SPACES["R^3 x SO(2), weighted"] = weighted_compound
SPACES["SO(2)"] = ob.SO2StateSpace
SPACES["SO(3)"] = ob.SO3StateSpace


def random_states(layout, count: int, rng: np.random.Generator) -> np.ndarray:
    """States of the layout: positions (with many repeated, for ties), angles, unit quaternions."""
    states = np.empty((count, layout.dim))
    for leaf in range(len(layout.kind)):
        start, size, kind = int(layout.offset[leaf]), int(layout.size[leaf]), int(layout.kind[leaf])
        block = states[:, start : start + size]
        if kind == 0:
            block[:] = rng.uniform(-1.0, 1.0, (count, size)).round(2)  # a coarse grid: equal distances occur
        elif kind == 1:  # half from a few angles (equal distances), -pi among them
            block[:] = rng.uniform(-np.pi, np.pi, (count, 1))
            block[::2] = rng.choice(np.linspace(-np.pi, np.pi, 9, endpoint=False), (len(block[::2]), 1))
        else:  # half from a few rotations, each as q or -q (the same rotation)
            q = rng.normal(size=(count, 4))
            q[::2] = q[rng.integers(0, 8, len(q[::2]))] * rng.choice([-1.0, 1.0], (len(q[::2]), 1))
            block[:] = q / np.linalg.norm(q, axis=1)[:, None]
    return states


@njit
def queries_as_it_grows(index, layout, states, queries, found, scanned):  # pragma: no cover (compiled)
    """Query ``queries[n - 1]`` with the first ``n`` states, for n = 1, 2, ...: (node, distance) rows."""
    for size in range(1, states.shape[0] + 1):
        node, distance = indexed_nearest(index, layout, states, size, queries[size - 1])
        found[size - 1, 0], found[size - 1, 1] = node, distance
        node, distance = nearest(layout, states, size, queries[size - 1])
        scanned[size - 1, 0], scanned[size - 1, 1] = node, distance


#: Enough nodes for several rebuilds, with nodes left unbuilt between them.
COUNT = 6 * INDEX_FROM + 123


def assert_answers_as_the_scan(layout, states: np.ndarray, queries: np.ndarray) -> np.ndarray:
    """The index's answers to ``queries`` as ``states`` grow are the scan's; returns the scan's (node, distance) rows."""
    index = new_index(layout, len(states))
    found, scanned = np.empty((len(states), 2)), np.empty((len(states), 2))
    queries_as_it_grows(index, layout, states, queries, found, scanned)
    np.testing.assert_array_equal(found[:, 0], scanned[:, 0])  # the same node, ties to the lowest index
    np.testing.assert_allclose(found[:, 1], scanned[:, 1], rtol=0.0, atol=1e-12)
    return scanned


@pytest.mark.parametrize("name", SPACES)
def test_the_index_answers_as_the_linear_scan_while_the_tree_grows(name):
    space = SPACES[name]()
    si = ob.SpaceInformation(space)
    si.setup()  # (and the space's: OMPL's bindings give SO(2) and SO(3) spaces no setup of their own)
    layout = layout_for(space)
    rng = np.random.default_rng(3)
    count = COUNT
    states = random_states(layout, count, rng)
    queries = random_states(layout, count, rng)
    queries[::7] = states[rng.integers(0, count, len(queries[::7]))]  # queries on nodes: distance 0
    scanned = assert_answers_as_the_scan(layout, states, queries)
    # the scan itself against OMPL's own distance, for some queries
    a, b = si.allocState(), si.allocState()
    for row in rng.integers(INDEX_FROM, count, 20):
        space.copyFromReals(b, queries[row].tolist())
        distances = []
        for node in range(row + 1):
            space.copyFromReals(a, states[node].tolist())
            distances.append(si.distance(a, b))
        assert int(np.argmin(distances)) == int(scanned[row, 0])
        assert abs(min(distances) - scanned[row, 1]) < 1e-9


def test_quaternions_not_of_unit_length_still_get_the_scans_answer():
    """Quaternions not of unit length (as a user's states may be) break the chord bound; the
    index leaves such rotations out of its bounds."""
    space = SPACES["SE(3)"]()
    ob.SpaceInformation(space).setup()
    layout = layout_for(space)
    rng = np.random.default_rng(5)
    states, queries = random_states(layout, COUNT, rng), random_states(layout, COUNT, rng)
    rotation = slice(int(layout.offset[1]), int(layout.offset[1] + layout.size[1]))
    states[::3, rotation] *= 1.5  # a third of the nodes
    queries[1::3, rotation] *= 1.5  # and a third of the queries, others
    assert_answers_as_the_scan(layout, states, queries)
