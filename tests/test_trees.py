"""Tree storage: exact nearest neighbour, growth by doubling, parent/root bookkeeping."""

import numpy as np
import pytest
from fresh_process import run_with_seed
from ompl import base as ob

from ompl_balance.core import trees
from ompl_balance.core.layout import squared_distances as _squared_distances
from ompl_balance.core.trees import COMPILED_SCANS_FROM, NO_PARENT, ArrayTree, StateTree, load_scans


@pytest.mark.parametrize(("dim", "offset", "scale"), [(2, 0.0, 1.0), (7, 0.0, 1.0), (3, 1e6, 1e-3), (7, -50.0, 1e-6)])
def test_array_tree_nearest_is_exact(dim, offset, scale):
    """Brute-force comparison, including clouds far from the origin and tiny spreads."""
    rng = np.random.default_rng(dim)
    tree = ArrayTree(dim, capacity=4)  # grows by doubling several times
    points = offset + scale * rng.random((600, dim))
    for size in (100, 600):  # a small tree, then one grown past its capacity several times
        while tree.size < size:
            tree.add(points[tree.size], NO_PARENT if tree.size == 0 else 0)
        assert np.array_equal(tree.states, points[:size])
        for query in offset + scale * rng.random((100, dim)):
            distances = np.linalg.norm(points[:size] - query, axis=1)
            index, distance = tree.nearest(query)
            assert distances[index] == distances.min()
            assert distance == pytest.approx(distances.min(), rel=1e-12, abs=0)


@pytest.mark.parametrize("dim", [2, 7])
def test_array_tree_near_is_exact(dim):
    """Every node within the radius, in index order, with its distance; none outside it."""
    rng = np.random.default_rng(dim)
    tree = ArrayTree(dim, capacity=4)
    points = rng.random((700, dim))
    for point in points:
        tree.add(point, NO_PARENT)
    for query in rng.random((50, dim)):
        distances = np.linalg.norm(points - query, axis=1)
        radius = float(np.quantile(distances, 0.05))
        indices, near_distances = tree.near(query, radius)
        assert indices.tolist() == np.flatnonzero(distances <= radius).tolist()
        assert near_distances == pytest.approx(distances[indices], rel=1e-12, abs=0)
    # a strided query (a column of a matrix) answers as a contiguous one
    column = np.asfortranarray(rng.random((dim, 3)))[:, 1]
    assert tree.nearest(column) == tree.nearest(np.ascontiguousarray(column))


def test_array_tree_nearest_of_an_empty_tree_is_refused():
    with pytest.raises(ValueError, match="empty tree"):
        ArrayTree(2).nearest(np.zeros(2))


def test_kernels_load_only_where_a_tree_needs_them():
    """``import ompl_balance``, a Python-engine planner's setup() and a solve whose trees stay
    small load neither numba nor the compiled scans; a tree reaching COMPILED_SCANS_FROM nodes
    starts loading them in the background, and scans with them once they are there."""
    script = (
        "import sys, time\n"
        "import numpy as np\n"
        "import ompl_balance\n"
        "from ompl import base as ob, util as ou\n"
        "from ompl_balance.core import trees\n"
        "ou.setLogLevel(ou.LOG_WARN)\n"
        "loaded = lambda: ('numba' in sys.modules, 'ompl_balance.core.compiled_spaces' in sys.modules)\n"
        "print(*loaded())\n"
        "problem = ompl_balance.get_problem('narrow_gap')\n"
        "ss = problem.setup()\n"
        "planner = ompl_balance.BalancedRRTConnect(ss.getSpaceInformation())\n"
        "planner.setEngine('python')\n"
        "planner.setSeed(int(sys.argv[1]))  # (a solve whose trees stay small)\n"
        "ss.setPlanner(planner)\n"
        "ss.setup()\n"
        "print(*loaded())\n"
        "ss.solve(10.0)\n"
        "print(planner.stats.start_tree_size < trees.COMPILED_SCANS_FROM, *loaded())\n"
        "tree = trees.ArrayTree(2)\n"
        "for point in np.random.default_rng(0).random((trees.COMPILED_SCANS_FROM, 2)):\n"
        "    tree.add(point)\n"
        "answer = tree.nearest(np.array([0.5, 0.5]))\n"
        "trees._LOADER.finish()\n"
        "print('ompl_balance.core.compiled_spaces' in sys.modules, tree.nearest(np.array([0.5, 0.5])) == answer)\n"
    )
    assert run_with_seed(script, 2).split() == ["False"] * 2 + ["False"] * 2 + ["True", "False", "False"] + [
        "True",
        "True",
    ]


def test_small_euclidean_trees_scan_with_the_kernels_once_the_compiled_engine_imported_them():
    """Where the compiled engine has imported the compiled scans, a Euclidean tree of a few nodes
    scans with them at once (nothing loaded in the background; numpy's scan is not called), with
    the answer numpy gave; an SE(2) tree as small keeps numpy's scan (its kernel compiles at its
    first call, which a short solve must not wait for)."""
    script = (
        "import numpy as np\n"
        "from ompl import base as ob\n"
        "from ompl_balance.core import trees\n"
        "from ompl_balance.core.layout import layout_for\n"
        "rng = np.random.default_rng(0)\n"
        "tree, plane = trees.ArrayTree(2), trees.ArrayTree(3, layout=layout_for(ob.SE2StateSpace()))\n"
        "for point in rng.random((50, 3)):\n"
        "    tree.add(point[:2])\n"
        "    plane.add(point)\n"
        "query = np.array([0.3, 0.6])\n"
        "answer = tree.nearest(query)\n"
        "import ompl_balance.engine.loop\n"  # (what loading the compiled engine imports)
        "trees.squared_distances = trees.distances = None\n"  # (numpy's scans: a call fails)
        "print(tree.nearest(query) == answer, trees._LOADER.thread is None)\n"
        "try:\n"
        "    plane.nearest(np.array([0.3, 0.6, 0.5]))\n"
        "except TypeError:\n"
        "    print('numpy')\n"
    )
    assert run_with_seed(script, 0).split() == ["True", "True", "numpy"]


@pytest.mark.parametrize("dim", range(1, 10))
def test_numpy_and_compiled_scans_agree_to_the_last_bit(dim):
    rng = np.random.default_rng(dim)
    scans = load_scans()
    for scale in (1.0, 1e6, 1e-6):
        states = np.ascontiguousarray(rng.normal(size=(300, dim)) * scale)
        for query in rng.normal(size=(30, dim)) * scale:
            squared = _squared_distances(states, query)
            index, nearest_squared = scans.euclidean_nearest(states, len(states), query)
            assert index == int(squared.argmin()) and nearest_squared == squared[index]
            radius = float(np.sqrt(np.quantile(squared, 0.1)))
            indices, distances = np.empty(300, dtype=np.int64), np.empty(300)
            count = scans.euclidean_within(states, len(states), query, radius, indices, distances)
            inside = np.flatnonzero(squared <= radius * radius)
            assert np.array_equal(indices[:count], inside)
            assert np.array_equal(distances[:count], np.sqrt(squared[inside]))


def test_array_tree_answers_the_same_with_either_scan(monkeypatch):
    rng = np.random.default_rng(5)
    tree = ArrayTree(3)
    for point in rng.random((COMPILED_SCANS_FROM + 500, 3)):
        tree.add(point)
    load_scans()
    queries = rng.random((20, 3))

    def answers():
        return [(tree.nearest(query), *(a.tolist() for a in tree.near(query, 0.2))) for query in queries]

    compiled = answers()
    monkeypatch.setattr(trees, "COMPILED_SCANS_FROM", 10**9)  # numpy scans whatever the size
    assert answers() == compiled


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


@pytest.mark.parametrize("space_kind", ["reeds_shepp", "dubins"])
def test_state_tree_answers_as_the_full_scan_with_few_distances_in_a_metric_space(space_kind):
    """Reeds-Shepp is a metric (the tree bounds distances through pivots); Dubins is not (it scans)."""
    space = ob.ReedsSheppStateSpace(0.3) if space_kind == "reeds_shepp" else ob.DubinsStateSpace(0.3)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0.0)
    bounds.setHigh(10.0)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda state: True)
    si.setup()
    sampler = si.allocStateSampler()
    tree = StateTree(si)
    for _ in range(600):
        state = si.allocState()
        sampler.sampleUniform(state)
        tree.add(state)
    calls = []
    exact = si.distance
    tree._distance = lambda a, b: calls.append(1) or exact(a, b)  # count the calls into OMPL
    query = si.allocState()
    for _ in range(30):
        sampler.sampleUniform(query)
        full = [exact(node, query) for node in tree.states]
        calls.clear()
        index, distance = tree.nearest(query)
        assert (index, distance) == (int(np.argmin(full)), min(full))
        if space_kind == "reeds_shepp":
            assert len(calls) < len(full) / 3
        near, distances = tree.near(query, 2.0)
        assert near.tolist() == [i for i, d in enumerate(full) if d <= 2.0]
        np.testing.assert_array_equal(distances, [d for d in full if d <= 2.0])
