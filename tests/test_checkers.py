"""Your own checker: setup_checker's kinds of function, and plain callables, on both engines and stock.

Oracles: the Python engine on the same seed (the same trees, paths and counts), OMPL's own
``DiscreteMotionValidator`` (the same answers and the same states tested), a brute-force
re-check of OMPL's lastValid rule, and the function's own calls.
"""

from __future__ import annotations

import itertools
import re
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numba
import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou
from test_engine import assert_same_run, solve

from ompl_balance import BalancedRRTConnect, setup_checker
from ompl_balance.checking import CheckerError, FunctionMotionValidator, FunctionValidityChecker
from ompl_balance.core.counting import CountingValidityChecker

ou.setLogLevel(ou.LOG_WARN)

#: Three staggered walls between the start (0.05, 0.05) and the goal (0.95, 0.95) of the unit square.
WALLS = np.array([(0.2, 0.0, 0.25, 0.85), (0.45, 0.15, 0.5, 1.0), (0.7, 0.0, 0.75, 0.85)])


def python_free(q):
    return all(not (x0 <= q[0] <= x1 and y0 <= q[1] <= y1) for x0, y0, x1, y1 in WALLS.tolist())


@numba.njit(cache=True)
def numba_free(q):
    for i in range(WALLS.shape[0]):
        if WALLS[i, 0] <= q[0] <= WALLS[i, 2] and WALLS[i, 1] <= q[1] <= WALLS[i, 3]:
            return False
    return True


def vectorized_free(states):
    x, y = states[:, :1], states[:, 1:2]
    inside = (WALLS[:, 0] <= x) & (x <= WALLS[:, 2]) & (WALLS[:, 1] <= y) & (y <= WALLS[:, 3])
    return ~inside.any(axis=1)


def state_free(state) -> bool:
    """The same test as a plain callable of an OMPL state."""
    return python_free((state[0], state[1]))


KINDS = {
    "python": (python_free, False),
    "numba": (numba_free, False),
    "vectorized": (vectorized_free, True),
}


def square(function=None, vectorized=False, plain=None, space=None):
    """The unit square (or ``space``) with ``function`` through setup_checker, or ``plain`` as
    ``ss.setStateValidityChecker(plain)``; start (0.05, 0.05), goal (0.95, 0.95)."""
    if space is None:
        space = ob.RealVectorStateSpace(2)
        space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    if plain is not None:
        ss.setStateValidityChecker(plain)
    else:
        setup_checker(ss, function, vectorized=vectorized)
    start, goal = space.allocState(), space.allocState()
    start[0], start[1], goal[0], goal[1] = 0.05, 0.05, 0.95, 0.95
    ss.setStartAndGoalStates(start, goal)
    return ss


def make(kind):
    function, vectorized = KINDS[kind]
    return lambda: square(function, vectorized)


# -- the same trees --------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", list(KINDS))
def test_each_kind_of_function_makes_the_same_trees_on_both_engines(kind):
    python = solve(make(kind), "python", seed=5, solves=2)
    compiled = solve(make(kind), "compiled", seed=5, solves=2)
    assert python[0][0] == "Exact solution"
    assert_same_run(python, compiled)


def test_a_numba_function_and_the_same_test_as_a_plain_callable_make_the_same_trees():
    """The package's planner on a seed: a numba function through setup_checker (compiled, no
    Python per state) and the same test as ``ss.setStateValidityChecker(fn)`` (one call into
    Python per motion) make the same trees, paths and counts, on either engine."""
    runs = [
        solve(make("numba"), "compiled", seed=9),
        solve(lambda: square(plain=state_free), "compiled", seed=9),
        solve(lambda: square(plain=state_free), "python", seed=9),
    ]
    for other in runs[1:]:
        assert_same_run(runs[0], other)


@pytest.mark.parametrize("kind", ["plain", "python", "vectorized"])
def test_the_compiled_engine_calls_python_once_per_growth_of_a_tree(kind):
    """Every check of a function written in Python is made in Python, all the states one growth
    of a tree tests in one call (an extension step: a goal tree's new state and its motion; a
    connect: all its steps), and a vectorized function's all the states of an iteration (its
    extension, then the connect after it): the calls out of compiled code are the growths (the
    extensions) the loop record shows, and the work is that of the Python engine (one state at a
    time) on the same seed; a numba function makes no call at all."""
    from ompl_balance.engine.events import LoopRecord

    def setup():
        if kind == "plain":
            return square(plain=state_free)
        return square(*KINDS[kind])

    runs = {}
    for engine in ("compiled", "python"):
        ss = setup()
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        planner.setEngine(engine)
        planner.setSeed(2)
        planner.loop_record = LoopRecord()
        ss.setPlanner(planner)
        assert ss.solve(10.0)
        runs[engine] = planner
    stats, record = runs["compiled"].stats, runs["compiled"].loop_record
    assert (stats.engine, stats.checks) == ("compiled", "python" if kind == "plain" else "kernel")
    extensions = sum(1 for step in record.steps if not step.connect)
    connects = sum(1 for step in record.steps if step.connect and not step.node_given)
    assert connects > 0
    assert stats.exits == (extensions if kind == "vectorized" else extensions + connects)
    assert stats.exits < stats.states_checked
    python = runs["python"].stats
    assert (stats.states_checked, stats.motions_checked) == (python.states_checked, python.motions_checked)
    other = runs["python"].loop_record.steps
    assert [step._replace(target=None) for step in record.steps] == [step._replace(target=None) for step in other]
    assert all(np.array_equal(a.target, b.target) for a, b in zip(record.steps, other))
    ss = make("numba")()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    ss.setPlanner(planner)
    assert ss.solve(10.0)
    assert (planner.stats.checks, planner.stats.exits) == ("kernel", 0)


def test_a_plain_callable_is_called_directly_and_ambiguity_keeps_ompls_checker():
    """``ss.setStateValidityChecker(fn)``: the counting checker the package installs calls ``fn``
    itself. Two SimpleSetups of one space information given different functions leave it unsure
    which is installed: then it calls OMPL's checker as it is."""
    ss = square(plain=state_free)
    ss.setPlanner(BalancedRRTConnect(ss.getSpaceInformation()))
    ss.setup()
    checker = ss.getSpaceInformation().getStateValidityChecker()
    assert isinstance(checker, CountingValidityChecker) and checker.check is state_free
    ss = square(plain=state_free)
    other = og.SimpleSetup(ss.getSpaceInformation())
    other.setStateValidityChecker(lambda state: not state_free(state))  # installed last: the one OMPL calls
    ss.setPlanner(BalancedRRTConnect(ss.getSpaceInformation()))
    ss.setup()
    checker = ss.getSpaceInformation().getStateValidityChecker()
    assert checker.check is not state_free
    state = ss.getSpaceInformation().allocState()
    state[0], state[1] = 0.22, 0.5  # inside the first wall: the installed (inverted) checker says valid
    assert checker.isValid(state) is True


# -- OMPL's discrete rule -----------------------------------------------------------------------------


def ompl_reference(function_of_state):
    """A space information with ``function_of_state`` and OMPL's own DiscreteMotionValidator, and
    the function's call count."""
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    si = ob.SpaceInformation(space)
    calls = [0]

    def counted(state):
        calls[0] += 1
        return function_of_state(state)

    si.setStateValidityChecker(counted)
    si.setStateValidityCheckingResolution(0.01)
    si.setup()
    return si, calls


@pytest.mark.parametrize("kind", list(KINDS))
def test_motions_get_ompls_answers_and_test_as_many_states(kind):
    """On 300 random motions (short and across the square): the same answers as OMPL's
    DiscreteMotionValidator with the same test, and as many states tested (OMPL's calls)."""
    reference, calls = ompl_reference(state_free)
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    si = ob.SpaceInformation(space)
    function, vectorized = KINDS[kind]
    checker, validator = setup_checker(si, function, vectorized=vectorized)
    si.setStateValidityCheckingResolution(0.01)
    si.setup()
    rng = np.random.default_rng(4)
    a, b = si.allocState(), si.allocState()
    ra, rb = reference.allocState(), reference.allocState()
    answers = []
    for index in range(300):
        p, q = rng.random(2), rng.random(2)
        if index % 2:
            q = p + 0.05 * (q - p)  # a short motion too
        for state, other, values in ((a, ra, p), (b, rb, q)):
            state[0], state[1] = other[0], other[1] = values
        before, counted = calls[0], checker.counters()["states_checked"]
        answer = validator.checkMotion(a, b)
        assert answer == reference.checkMotion(ra, rb), (p, q)
        assert checker.counters()["states_checked"] - counted == calls[0] - before
        answers.append(answer)
    assert 0 < sum(answers) < len(answers)  # both kinds of answer were given
    assert validator.counters()["motions_checked"] == 300


class RowsTarget:
    """An exit's target testing rows with :func:`python_free`, as the package's function targets do."""

    def __init__(self):
        self.error, self.rows = None, np.empty((0, 2))

    def answer(self, kind, count):
        for index in range(count):
            if not python_free(self.rows[index]):
                return index
        return count


def steps_one_by_one(reference, chain, steps, outward):
    """The oracle of a tree's steps: OMPL's own ``isValid`` and ``DiscreteMotionValidator`` called
    one step at a time as RRT-Connect grows a tree (outward: the start tree; else the goal tree,
    the new state first). Returns the steps free and the motions begun."""
    a, b = reference.allocState(), reference.allocState()
    for k in range(1, steps + 1):
        a[0], a[1] = chain[k - 1] if outward else chain[k]
        b[0], b[1] = chain[k] if outward else chain[k - 1]
        if not outward and not reference.isValid(a):
            return k - 1, k - 1
        if not reference.checkMotion(a, b):
            return k - 1, k
    return steps, steps


def batched_exit_view(reference, rows):
    """A batched exit view of :func:`state_free` (``rows``: its rows, else the view's own) and its target."""
    from ompl_balance.core.checks import Count, load_kernels
    from ompl_balance.core.exit_checks import exit_checks
    from ompl_balance.core.layout import layout_for

    layout = layout_for(reference.getStateSpace())
    target = RowsTarget()
    view = exit_checks(target, layout, reference.getMaximumExtent(), np.zeros(len(Count), dtype=np.int64), True)
    if rows is not None:
        view = view._replace(rows=np.empty((rows, 2)), row_steps=np.empty(rows, dtype=np.int64))
    target.rows = view.rows
    load_kernels(view)
    return view, target


def random_chain(rng, steps):
    """``steps`` short random steps in the unit square, (steps + 1, 2)."""
    return np.cumsum(np.vstack([rng.random(2), 0.15 * (rng.random((steps, 2)) - 0.5)]), axis=0).clip(0.0, 1.0)


@pytest.mark.parametrize("rows", [3, 40, None])
@pytest.mark.parametrize("outward", [True, False])
def test_a_trees_steps_checked_together_are_checked_as_one_by_one(rows, outward):
    """``steps_free`` of a batched exit view (all a connect's steps in one call to Python, in parts
    when its rows are full: 3 and 40 rows, and the view's own): on 200 random chains of steps,
    the steps taken, the states tested and the motions begun are those of OMPL's own
    ``isValid`` and ``DiscreteMotionValidator`` called one step at a time as RRT-Connect grows a
    tree (outward: the start tree; else the goal tree, the new state first)."""
    from ompl_balance.core.checks import Count, steps_free

    reference, calls = ompl_reference(state_free)
    view, _target = batched_exit_view(reference, rows)

    @numba.njit
    def call(view, chain, steps, outward):  # (steps_free from compiled code, as the loop calls it)
        return steps_free(view, chain, steps, outward)

    rng = np.random.default_rng(11)
    taken = []
    for _ in range(200):
        steps = int(rng.integers(1, 6))
        chain = random_chain(rng, steps)
        before_calls, before = calls[0], view.counts.copy()
        free, motions = steps_one_by_one(reference, chain, steps, outward)
        assert call(view, chain, steps, outward) == free
        assert view.counts[Count.STATES] - before[Count.STATES] == calls[0] - before_calls
        assert view.counts[Count.MOTIONS] - before[Count.MOTIONS] == motions
        taken.append(free)
    assert any(free == 0 for free in taken) and any(free > 1 for free in taken)
    exits_per_chain = view.counts[Count.EXITS] / len(taken)
    assert exits_per_chain > 1 if rows == 3 else exits_per_chain == 1


@pytest.mark.parametrize("rows", [3, 40, None])
@pytest.mark.parametrize("extension_outward", [True, False])
def test_an_iterations_extension_and_connect_checked_together_are_checked_as_one_by_one(rows, extension_outward):
    """``growth_free`` of a batched exit view (a vectorized function's: an iteration's extension
    step, then the other tree's connect, in one call to Python, in parts when its rows are full):
    on 200 random extensions and connects, the answer (the connect's free steps, or
    ``EXTENSION_BLOCKED``), the states tested and the motions begun are those of OMPL's own
    checks one step at a time: the extension, then the connect's steps only if it is free."""
    from ompl_balance.core.checks import EXTENSION_BLOCKED, Count, growth_free

    reference, calls = ompl_reference(state_free)
    view, _target = batched_exit_view(reference, rows)

    @numba.njit
    def call(view, extension, extension_outward, chain, steps, outward):  # (as the loop calls it)
        return growth_free(view, extension, extension_outward, chain, steps, outward)

    rng = np.random.default_rng(12)
    answers = []
    outward = not extension_outward  # (the connect grows the other tree)
    for _ in range(200):
        extension, steps = random_chain(rng, 1), int(rng.integers(1, 6))
        chain = random_chain(rng, steps)
        before_calls, before = calls[0], view.counts.copy()
        free, motions = steps_one_by_one(reference, extension, 1, extension_outward)
        if free == 0:
            expected = EXTENSION_BLOCKED
        else:
            expected, connect_motions = steps_one_by_one(reference, chain, steps, outward)
            motions += connect_motions
        assert call(view, extension, extension_outward, chain, steps, outward) == expected
        assert view.counts[Count.STATES] - before[Count.STATES] == calls[0] - before_calls
        assert view.counts[Count.MOTIONS] - before[Count.MOTIONS] == motions
        answers.append(expected)
    assert EXTENSION_BLOCKED in answers and 0 in answers and any(answer > 1 for answer in answers)
    exits_per_iteration = view.counts[Count.EXITS] / len(answers)
    assert exits_per_iteration > 1 if rows == 3 else exits_per_iteration == 1


@pytest.mark.parametrize("kind", list(KINDS))
def test_last_valid_follows_ompls_rule(kind):
    """``check_motion_last_valid``: the states from s1 outwards at j / n, then s2; the fraction of
    the last valid one, brute force with the same function."""
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    si = ob.SpaceInformation(space)
    function, vectorized = KINDS[kind]
    _, validator = setup_checker(si, function, vectorized=vectorized)
    si.setup()
    rng = np.random.default_rng(6)
    a, b = si.allocState(), si.allocState()
    for _ in range(100):
        p, q = rng.random(2), rng.random(2)
        p = np.array([0.1, p[1]]) if python_free(p) is False else p
        a[0], a[1], b[0], b[1] = *p, *q
        n = space.validSegmentCount(a, b)
        expected = (True, 1.0)
        for j in range(1, n + 1):
            if not python_free(p + (j / n) * (q - p)):
                expected = (False, (j - 1) / n)
                break
        valid, fraction = validator.check_motion_last_valid(a, b)
        assert valid == expected[0]
        assert fraction == pytest.approx(expected[1])


def test_the_flat_layout_of_se2_and_a_compound_space_reaches_the_function():
    """The function gets OMPL's copyFromReals order: (x, y, yaw) for SE(2), then a compound's
    second subspace."""
    seen = []

    def record(q):
        seen.append(q.copy())
        return True

    space = ob.CompoundStateSpace()
    se2 = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(-1.0)
    bounds.setHigh(1.0)
    se2.setBounds(bounds)
    line = ob.RealVectorStateSpace(1)
    line.setBounds(0.0, 2.0)
    space.addSubspace(se2, 1.0)
    space.addSubspace(line, 1.0)
    si = ob.SpaceInformation(space)
    checker, _ = setup_checker(si, record)
    si.setup()
    state = si.allocState()
    space.copyFromReals(state, [0.25, -0.5, 1.5, 1.75])
    assert checker.isValid(state)
    np.testing.assert_array_equal(seen[-1], [0.25, -0.5, 1.5, 1.75])


# -- errors ---------------------------------------------------------------------------------------------

_RAISE = [True]


def raising_python(q):
    if _RAISE[0] and q[0] > 0.5:
        raise ValueError("the test's own error")
    return True


@numba.njit
def raising_numba(q):
    if q[0] > 0.5 and q[1] > -10.0:  # (numba cannot read the module's flag: always raises there)
        raise ValueError("the test's own error")
    return True


def raising_vectorized(states):
    if _RAISE[0] and (states[:, 0] > 0.5).any():
        raise ValueError("the test's own error")
    return np.ones(len(states), dtype=bool)


@pytest.mark.parametrize(
    ("function", "vectorized"),
    [(raising_python, False), (raising_numba, False), (raising_vectorized, True)],
    ids=["python", "numba", "vectorized"],
)
@pytest.mark.parametrize("engine", ["python", "compiled", "stock"])
def test_a_function_that_raises_gives_an_error_naming_it(function, vectorized, engine):
    """The error names the function and says what it raised, on both engines and under a stock
    planner; the package's planner then solves again (once the function no longer raises)."""
    _RAISE[0] = True
    ss = square(function, vectorized)
    si = ss.getSpaceInformation()
    planner = og.RRTConnect(si) if engine == "stock" else BalancedRRTConnect(si)
    if engine != "stock":
        planner.setEngine(engine)
    ss.setPlanner(planner)
    with pytest.raises(CheckerError, match=rf"{function.__name__}.*ValueError.*the test's own error"):
        ss.solve(5.0)
    if engine == "stock" or function is raising_numba:
        return
    _RAISE[0] = False
    try:
        assert ss.solve(5.0)
        path = ss.getSolutionPath()
        assert path.check()
    finally:
        _RAISE[0] = True


def test_the_planner_solves_on_after_a_numba_function_raised():
    """A numba function that raises where the first solve goes: the error, then a fresh problem
    for the same planner object (cleared) solves, its compiled engine reused."""

    @numba.njit
    def walls_that_raise_beyond(q):
        if q[0] > 2.0:
            raise ValueError("outside")
        return numba_free(q)

    ss = square(walls_that_raise_beyond)
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    ss.setPlanner(planner)
    assert ss.solve(10.0)
    checker = ss.getSpaceInformation().getStateValidityChecker()
    state = ss.getSpaceInformation().allocState()
    state[0], state[1] = 3.0, 0.5
    with pytest.raises(CheckerError, match=r"walls_that_raise_beyond.*outside"):
        checker.isValid(state)
    ss.clear()
    assert ss.solve(10.0)


@pytest.mark.parametrize(
    ("returned", "accepted"),
    [(np.bool_(True), True), (None, False), (np.float64(1.0), False), (1, False)],
)
def test_a_plain_callables_answer_must_be_a_bool(returned, accepted):
    """numpy's bool is taken as Python's; anything else is refused with an error naming the
    function and what it returned (OMPL's own binding says only std::bad_cast)."""

    def answers_oddly(state):
        return returned

    ss = square(plain=answers_oddly)
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    ss.setPlanner(planner)
    if accepted:
        assert ss.solve(1.0)
    else:
        with pytest.raises(TypeError, match=rf"answers_oddly returned {re.escape(repr(returned))}.*True or False"):
            ss.solve(1.0)


def test_setup_checker_refuses_what_it_cannot_take():
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    si = ob.SpaceInformation(space)
    cases = [
        (42, {}, TypeError, "fn must be a function"),
        (lambda: True, {}, TypeError, "must take one argument"),
        (lambda q, extra: True, {}, TypeError, "must take one argument"),
        (numba.njit(lambda q: q[0]), {}, TypeError, "returns float64; a validity function returns a bool"),
        (numba_free, {"vectorized": True}, TypeError, "vectorized=True takes a numpy function"),
    ]
    for function, options, error, message in cases:
        with pytest.raises(error, match=message):
            setup_checker(si, function, **options)
    with pytest.raises(TypeError, match=r"SpaceInformation or an ompl\.geometric\.SimpleSetup"):
        setup_checker(space, python_free)
    unbounded = ob.SpaceInformation(ob.RealVectorStateSpace(2))
    with pytest.raises(ValueError, match="bounds are not set"):
        setup_checker(unbounded, python_free)
    discrete = ob.DiscreteStateSpace(0, 5)
    with pytest.raises(ValueError, match="no flat layout"):
        setup_checker(ob.SpaceInformation(discrete), python_free)
    # a space whose real-vector part has no bounds, though its extent is positive (its SO(2) part)
    with pytest.raises(ValueError, match="bounds are not set"):
        setup_checker(ob.SpaceInformation(ob.SE2StateSpace()), python_free)
    # a space OMPL gives no maximum extent
    with pytest.raises(ValueError, match="TimeStateSpace has no flat layout"):
        setup_checker(ob.SpaceInformation(ob.TimeStateSpace()), python_free)


def test_a_numba_function_compiled_for_its_own_signature_is_taken_and_a_cfunc_named_as_written():
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    si = ob.SpaceInformation(space)
    for signature in ("boolean(float64[::1])", "boolean(float64[:])"):
        eager = numba.njit(signature)(numba_free.py_func)
        checker, _ = setup_checker(si, eager)
        assert [checker.function.check(np.array(point)) for point in ((0.22, 0.5), (0.1, 0.5))] == [False, True]
    with pytest.raises(TypeError, match=r"compiled for its own signatures only \(\(int64,\) -> bool\)"):
        setup_checker(si, numba.njit("boolean(int64)")(lambda q: q > 0))

    @numba.cfunc(numba.types.float64(numba.types.CPointer(numba.types.float64), numba.types.intp))
    def misdeclared(values, dim):
        return 1.0

    with pytest.raises(TypeError, match="has signature") as refused:
        setup_checker(si, misdeclared)
    assert "misdeclared has signature" in str(refused.value) and "numba.core" not in str(refused.value)


@numba.njit(cache=True)
def writes_into_its_state(q):
    free = numba_free(q)
    q[0] = 0.22  # (inside the first wall)
    q[1] = 0.5
    return free


@pytest.mark.parametrize("engine", ["compiled", "python"])
def test_a_function_that_writes_into_its_state_leaves_the_planners_states_alone(engine):
    """A numba function is given a copy of the state on the compiled engine, as it is elsewhere:
    the path, checked again with the function that does not write, is the same as the Python
    engine's and valid."""
    ss = square(writes_into_its_state)
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.params().setParam("engine", engine)
    planner.params().setParam("seed", "3")
    ss.setPlanner(planner)
    assert ss.solve(10.0)
    path = ss.getSolutionPath()
    points = [(path.getState(i)[0], path.getState(i)[1]) for i in range(path.getStateCount())]
    assert all(python_free(point) for point in points)
    assert (0.22, 0.5) not in points
    other = square(numba_free)
    reference = BalancedRRTConnect(other.getSpaceInformation())
    reference.params().setParam("engine", "python")
    reference.params().setParam("seed", "3")
    other.setPlanner(reference)
    assert other.solve(10.0)
    again = other.getSolutionPath()
    assert points == [(again.getState(i)[0], again.getState(i)[1]) for i in range(again.getStateCount())]


def wall_at_the_middle(state) -> bool:
    return not (0.45 < state[0] < 0.55 and state[1] < 0.9)


@pytest.mark.parametrize("planner", ["python", "compiled"])
def test_a_checker_set_after_setup_checker_decides_the_motions_too(planner):
    """setup_checker(ss, f), then ss.setStateValidityChecker(g): the package's planners have motions
    checked with g by OMPL's discrete rule (OMPL's own validator is the oracle) on both engines,
    counted, and the validator answers so from Python afterwards."""
    ss = square(lambda q: True)  # everything free: its motion validator would let any path through
    ss.setStateValidityChecker(wall_at_the_middle)
    si = ss.getSpaceInformation()
    si.setStateValidityCheckingResolution(0.01)
    made = BalancedRRTConnect(si)
    made.params().setParam("engine", planner)
    ss.setPlanner(made)
    assert ss.solve(10.0)
    reference, _ = ompl_reference(wall_at_the_middle)
    path = ss.getSolutionPath()
    a, b = reference.allocState(), reference.allocState()
    for i in range(path.getStateCount() - 1):
        a[0], a[1] = path.getState(i)[0], path.getState(i)[1]
        b[0], b[1] = path.getState(i + 1)[0], path.getState(i + 1)[1]
        assert reference.checkMotion(a, b), i
    assert made.stats.motions_checked > 0
    assert made.stats.states_checked >= made.stats.motions_checked
    # the validator's own answers, from Python, against OMPL's on random motions
    validator = si.getMotionValidator()
    rng = np.random.default_rng(2)
    s1, s2 = si.allocState(), si.allocState()
    for _ in range(100):
        p, q = rng.random(2), rng.random(2)
        s1[0], s1[1], s2[0], s2[1] = a[0], a[1], b[0], b[1] = *p, *q
        assert validator.checkMotion(s1, s2) == reference.checkMotion(a, b)
        valid, fraction = validator.check_motion_last_valid(s1, s2)
        assert valid == reference.checkMotion(a, b)
        if not valid:  # the last valid state by OMPL's rule from s1 (brute force)
            n = si.getStateSpace().validSegmentCount(s1, s2)
            between = si.allocState()
            first = next(j for j in range(1, n + 1) if not _valid_at(si, s1, s2, j / n, between))
            assert fraction == pytest.approx((first - 1) / n)


def _valid_at(si, s1, s2, t, state) -> bool:
    si.getStateSpace().interpolate(s1, s2, t, state)
    return wall_at_the_middle(state)


@pytest.mark.parametrize(
    ("returned", "message"),
    [
        (lambda states: np.ones(len(states) + 1, dtype=bool), r"shape \(\d+,\) and dtype bool for \d+ states"),
        (lambda states: np.ones(len(states)), "dtype float64"),
        (lambda states: [True] * len(states), "returned list"),
    ],
    ids=["shape", "dtype", "list"],
)
def test_a_vectorized_function_of_the_wrong_shape_or_dtype_is_refused(returned, message):
    ss = square(returned, vectorized=True)
    ss.setPlanner(BalancedRRTConnect(ss.getSpaceInformation()))
    with pytest.raises(CheckerError, match=message):
        ss.solve(1.0)


def test_a_numba_function_is_wrapped_once_for_every_checker_set_up_with_it():
    """The C wrapper of a numba function is compiled the first time setup_checker is given it;
    checkers set up again with the function (a fresh SimpleSetup per run, as benchmarks make
    them) call the same machine code, and a new function gets its own."""
    addresses = [square(numba_free).getSpaceInformation().getStateValidityChecker().function.address for _ in range(3)]
    assert addresses[0] != 0 and addresses.count(addresses[0]) == 3

    @numba.njit
    def other(q):
        return q[0] < 0.5

    assert square(other).getSpaceInformation().getStateValidityChecker().function.address not in addresses


def test_a_cfunc_is_called_as_it_is():
    signature = numba.types.boolean(numba.types.CPointer(numba.types.float64), numba.types.intp)

    @numba.cfunc(signature)
    def free(values, dim):
        return numba.carray(values, (dim,))[0] < 0.99  # the goal's column is free

    ss = square(free)
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    ss.setPlanner(planner)
    assert ss.solve(5.0)
    assert (planner.stats.checks, planner.stats.exits) == ("kernel", 0)
    wrong = numba.cfunc(numba.types.float64(numba.types.float64))(lambda x: x)
    with pytest.raises(TypeError, match="boolean\\(CPointer\\(float64\\), intp\\)"):
        setup_checker(ss, wrong)


# -- concurrency, repetition, Ctrl-C ---------------------------------------------------------------------


def test_two_planners_in_two_threads_with_their_own_functions():
    """Two compiled solves at once, one numba function each (the walls, and the walls mirrored):
    each path is valid for its own function alone."""

    @numba.njit
    def mirrored(q):
        return numba_free(np.array([q[1], q[0]]))

    setups = [make("numba")(), square(mirrored)]
    results: list[object] = [None, None]

    def run(index):
        ss = setups[index]
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        planner.setEngine("compiled")
        planner.setSeed(index + 1)
        ss.setPlanner(planner)
        ss.setup()
        planner.wait_for_engine()
        results[index] = ss.solve(10.0)

    threads = [threading.Thread(target=run, args=(index,)) for index in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert all(results)
    for ss, function in ((setups[0], numba_free), (setups[1], mirrored)):
        path = ss.getSolutionPath()
        path.interpolate(200)
        for i in range(path.getStateCount()):
            state = path.getState(i)
            assert function(np.array([state[0], state[1]]))


def test_repeated_solves_and_clear():
    """Solves without clear() grow the same trees on both engines; clear() starts afresh (the
    counters count each solve's work)."""
    between = (lambda ss, planner: None, lambda ss, planner: ss.clear())
    python = solve(make("numba"), "python", seed=4, solves=3, between=between)
    compiled = solve(make("numba"), "compiled", seed=4, solves=3, between=between)
    assert_same_run(python, compiled)


def test_ctrl_c_during_a_solve_with_a_numba_function():
    script = textwrap.dedent(
        """
        import signal, sys
        import numba, numpy as np
        from ompl import util as ou
        signal.signal(signal.SIGINT, signal.default_int_handler)
        ou.setLogLevel(ou.LOG_WARN)
        sys.path.insert(0, "tests")
        from test_checkers import square
        from ompl_balance import BalancedRRTConnect

        @numba.njit
        def wall(q):
            return not (0.4 <= q[0] <= 0.6)  # across the square: no solve ends

        ss = square(wall)
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        planner.setEngine("compiled")
        ss.setPlanner(planner)
        ss.setup()
        planner.wait_for_engine()
        print("solving", flush=True)
        try:
            planner.solve(60.0)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
        print("again", bool(planner.solve(0.2)) is False, flush=True)
        """
    )
    process = subprocess.Popen(
        [sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    assert process.stdout is not None
    assert process.stdout.readline().strip() == "solving"
    time.sleep(1.0)
    process.send_signal(signal.SIGINT)
    began = time.perf_counter()
    out, err = process.communicate(timeout=60)
    assert "interrupted" in out and "again True" in out, err[-3000:]
    assert time.perf_counter() - began < 20.0


def test_stock_planners_get_paths_valid_by_ompls_own_rule():
    """A stock planner with setup_checker's checker and validator: every motion of its path is
    valid for OMPL's own DiscreteMotionValidator with the same test as a plain callable."""
    reference, _ = ompl_reference(state_free)
    start, end = reference.allocState(), reference.allocState()
    for kind in KINDS:
        ss = make(kind)()
        ss.getSpaceInformation().setStateValidityCheckingResolution(0.01)
        ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
        assert ss.solve(10.0)
        path = ss.getSolutionPath()
        states = [(path.getState(i)[0], path.getState(i)[1]) for i in range(path.getStateCount())]
        for a, b in itertools.pairwise(states):
            start[0], start[1], end[0], end[1] = *a, *b
            assert reference.isValid(start) and reference.checkMotion(start, end), kind


def test_the_installed_objects_are_ompls_classes():
    checker, validator = setup_checker(square(numba_free).getSpaceInformation(), numba_free)
    assert isinstance(checker, (FunctionValidityChecker, ob.StateValidityChecker))
    assert isinstance(validator, (FunctionMotionValidator, ob.MotionValidator))


def test_setup_checkers_objects_are_freed_with_the_simple_setup():
    """The checker and validator setup_checker installs hold nothing that holds the space
    information (an object OMPL holds from C++ that did would never be freed)."""
    import gc
    import weakref

    def planned() -> list:
        ss = square(numba_free)
        checker = ss.getSpaceInformation().getStateValidityChecker()
        validator = ss.getSpaceInformation().getMotionValidator()
        ss.setPlanner(BalancedRRTConnect(ss.getSpaceInformation()))
        assert ss.solve(10.0)
        ss.setStateValidityChecker(state_free)  # (the validator then follows another checker)
        assert ss.solve(10.0)
        return [weakref.ref(checker), weakref.ref(validator)]

    held = planned()
    gc.collect()
    assert [reference() for reference in held] == [None, None]


SCRIPT_START = """
import numba
from ompl import base as ob, geometric as og
from ompl_balance import BalancedRRTConnect, setup_checker

@numba.njit(cache=True)
def free(q):
    return not (0.45 < q[0] < 0.55 and q[1] < 0.9)

space = ob.RealVectorStateSpace(2)
space.setBounds(0.0, 1.0)
ss = og.SimpleSetup(space)
"""
SCRIPT_END = """
start, goal = space.allocState(), space.allocState()
start[0], start[1], goal[0], goal[1] = 0.1, 0.1, 0.9, 0.1
ss.setStartAndGoalStates(start, goal)
ss.setPlanner(BalancedRRTConnect(ss.getSpaceInformation()))
print(bool(ss.solve(1.0)))
"""


@pytest.mark.parametrize(
    "checker", ["setup_checker(ss, free)", "ss.setStateValidityChecker(lambda s: free([s[0], s[1]]))"]
)
def test_a_script_ends_without_nanobinds_leak_report(tmp_path, checker):
    """A script's checker references its globals, which hold the SimpleSetup; OMPL holds the checker
    (and the planner) from C++. nanobind reports what is still alive when the interpreter ends (tens
    of lines after the script's output): nothing is, with setup_checker or a plain callable."""
    script = tmp_path / "script.py"
    script.write_text(SCRIPT_START + checker + "\n" + SCRIPT_END)
    for _ in range(2):  # (the second run loads the function from numba's cache, as a user's runs do)
        done = subprocess.run(
            [sys.executable, str(script)], cwd=tmp_path, check=False, capture_output=True, text=True, timeout=300
        )
    assert done.returncode == 0 and done.stdout.strip().endswith("True"), done.stderr[-2000:]
    assert "leaked" not in done.stderr, done.stderr[-2000:]


def _thin_wall(q) -> bool:
    return not (0.5031 < q[0] < 0.5069)  # (0.0038 thick: between the states of a coarse check)


def _line_and_angle():
    """A compound of a unit segment and an angle, with setup_checker's thin wall across the segment."""
    space = ob.CompoundStateSpace()
    line = ob.RealVectorStateSpace(1)
    line.setBounds(0.0, 1.0)
    space.addSubspace(line, 1.0)
    space.addSubspace(ob.SO2StateSpace(), 1.0)
    ss = og.SimpleSetup(space)
    setup_checker(ss, _thin_wall)
    start, goal = space.allocState(), space.allocState()
    start[0][0], start[1].value, goal[0][0], goal[1].value = 0.1, 0.0, 0.9, 0.0
    ss.setStartAndGoalStates(start, goal)
    return ss, line


@pytest.mark.parametrize("engine", ["python", "compiled"])
def test_a_subspaces_resolution_changed_after_use_is_the_one_motions_are_checked_at(engine):
    """A subspace's longest valid segment refined after the validator and a planner were used: the
    validator answers as OMPL's own validator with the same test on random motions, and the
    planner no longer crosses a wall the coarse resolution stepped over."""
    ss, line = _line_and_angle()
    si = ss.getSpaceInformation()
    planner = BalancedRRTConnect(si)
    planner.params().setParam("engine", engine)
    ss.setPlanner(planner)
    assert ss.solve(5.0)  # (through the wall: its states fall between those the rule tests)
    line.setLongestValidSegmentFraction(0.0005)
    si.setup()
    reference = ob.SpaceInformation(si.getStateSpace())
    reference.setStateValidityChecker(lambda state: _thin_wall([state[0][0]]))
    reference.setup()
    validator, space = si.getMotionValidator(), si.getStateSpace()
    a, b = space.allocState(), space.allocState()
    rng = np.random.default_rng(7)
    answers = []
    for _ in range(60):
        a[0][0], a[1].value, b[0][0], b[1].value = rng.random(), 0.0, rng.random(), 0.0
        answers.append(validator.checkMotion(a, b))
        assert answers[-1] == reference.checkMotion(a, b)
    assert 0 < sum(answers) < len(answers)
    planner.clear()
    ss.getProblemDefinition().clearSolutionPaths()
    ss.solve(0.5)
    assert not ss.haveExactSolutionPath()
