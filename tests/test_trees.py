"""Tree storage: exact nearest neighbour, growth by doubling, parent/root bookkeeping."""

import numpy as np
import pytest
from ompl import base as ob

from ompl_balance.trees import NO_PARENT, ArrayTree, StateTree


@pytest.mark.parametrize(("dim", "offset", "scale"), [(2, 0.0, 1.0), (7, 0.0, 1.0), (3, 1e6, 1e-3), (7, -50.0, 1e-6)])
def test_array_tree_nearest_is_exact(dim, offset, scale):
    """Brute-force comparison, including clouds far from the origin where |s|^2 - 2 s.q cancels."""
    rng = np.random.default_rng(dim)
    tree = ArrayTree(dim, capacity=4)  # grows by doubling several times
    points = offset + scale * rng.random((600, dim))
    for size in (100, 600):  # below and above the brute-force size
        while tree.size < size:
            tree.add(points[tree.size], NO_PARENT if tree.size == 0 else 0)
        assert np.array_equal(tree.states, points[:size])
        for query in offset + scale * rng.random((100, dim)):
            distances = np.linalg.norm(points[:size] - query, axis=1)
            index, distance = tree.nearest(query)
            assert distances[index] == distances.min()
            assert distance == pytest.approx(distances.min(), rel=1e-12, abs=0)


def test_links_roots_and_branches():
    tree = ArrayTree(2, capacity=2)
    root = tree.add(np.zeros(2))
    a = tree.add(np.ones(2), root)
    b = tree.add(2 * np.ones(2), a)
    other_root = tree.add(np.full(2, 5.0))
    c = tree.add(np.full(2, 6.0), other_root)
    assert [tree.root(i) for i in (root, a, b, other_root, c)] == [root, root, root, other_root, other_root]
    assert tree.branch(b) == [b, a, root]
    assert tree.parent(root) == NO_PARENT and tree.parent(c) == other_root
    tree.clear()
    assert len(tree) == 0


def test_state_tree_nearest_uses_the_space_distance():
    """SO2 wraps around: 3.1 and -3.1 are 0.083 apart, which Euclidean distance on angles misses."""
    space = ob.SO2StateSpace()
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda state: True)
    si.setup()
    tree = StateTree(si)
    for angle in (0.0, 1.5, 3.1):
        state = si.allocState()
        state.value = angle
        tree.add(state, NO_PARENT)
    query = si.allocState()
    query.value = -3.1
    index, distance = tree.nearest(query)
    assert index == 2
    assert distance == pytest.approx(2 * np.pi - 6.2)
