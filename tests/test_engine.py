"""The compiled engine against the Python engine, and the compiled engine's contract.

Where the two engines share one random stream (real-vector spaces, SE(2)), the compiled one
must make the same trees, the same path and the same counts as the Python one, for every
policy and every kind of check; SE(3) and the termination condition, Ctrl-C and a fresh
process's first solve are tested on their own.
"""

from __future__ import annotations

import functools
import math
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou
from ompl_time import timed

from ompl_balance import BalancedRRTConnect
from ompl_balance.core.counting import CountingValidityChecker
from ompl_balance.core.layout import layout_for
from ompl_balance.engine.index import INDEX_FROM
from ompl_balance.planners import PRESETS
from ompl_balance.worlds.boxes import BoxWorld2D, get_problem
from ompl_balance.worlds.occupancy import rooms_problem

ou.setLogLevel(ou.LOG_WARN)

#: Every preset but the Gaussian passage sampler's (a valid-state sampler: the Python engine only).
COMPILED_PRESETS = [name for name in PRESETS if name != "GaussianPassageRRTConnect"]
IGNORED = {"time", "engine", "checks", "exits"}


def solve(
    make_setup,
    engine,
    planner_class=BalancedRRTConnect,
    seed=3,
    params=None,
    limit=20.0,
    solves=1,
    between=(),
    **kwargs,
):
    """Solve ``make_setup()`` on ``engine`` ``solves`` times in a row (``between[i](ss, planner)``
    called before solve ``i + 1``); returns (stats, trees, path) per solve."""
    ss = make_setup()
    planner = planner_class(ss.getSpaceInformation(), **kwargs)
    assert planner.params().setParams({"engine": engine, "seed": str(seed), **(params or {})})
    ss.setPlanner(planner)
    outcomes = []
    for index in range(solves):
        if index > 0 and index - 1 < len(between):
            between[index - 1](ss, planner)
        status = ss.solve(limit)
        stats = {key: value for key, value in planner.stats.as_dict().items() if key not in IGNORED}
        assert planner.stats.engine == engine
        trees = [tree.states.copy() for tree in (planner._start_tree, planner._goal_tree)]
        parents = [tree.parents[: len(tree)].copy() for tree in (planner._start_tree, planner._goal_tree)]
        path = None
        if status == ob.PlannerStatus.EXACT_SOLUTION:
            p = ss.getSolutionPath()
            path = [points(ss, p.getState(i)) for i in range(p.getStateCount())]
        outcomes.append((str(status), stats, trees, parents, path))
    return outcomes


def points(ss, state):
    """The flat values of an OMPL state of ``ss``'s space."""
    from ompl_balance.core.layout import state_reader

    return state_reader(ss.getStateSpace())(state)


def assert_same_run(python, compiled):
    for (status, stats, trees, parents, path), (status2, stats2, trees2, parents2, path2) in zip(python, compiled):
        assert status == status2
        assert stats == stats2
        for a, b in zip(trees, trees2):
            np.testing.assert_array_equal(a, b)
        for a, b in zip(parents, parents2):
            np.testing.assert_array_equal(a, b)
        assert path == path2


# -- the same trees ---------------------------------------------------------------------------


@pytest.mark.parametrize("problem", ["bug_trap", "maze"])
@pytest.mark.parametrize("preset", COMPILED_PRESETS)
def test_every_preset_makes_the_python_engines_trees(preset, problem):
    make = get_problem(problem).setup
    python = solve(make, "python", PRESETS[preset])
    compiled = solve(make, "compiled", PRESETS[preset])
    assert python[0][0] == "Exact solution"
    assert_same_run(python, compiled)


@pytest.mark.parametrize(
    "params",
    [
        {"balance_tree_sizes": "1", "max_tree_size_ratio": "0.5", "range": "0.05"},
        {"nearest_policy": "exhausted", "exhausted_after": "2", "sample_policy": "goal_bias", "goal_bias": "0.3"},
        {"nearest_policy": "exhaustion", "sample_policy": "neighbour_quality", "min_quality": "0.2"},
        {"swap_policy": "swap_limit", "swap_steps": "3", "sample_policy": "goal_ball", "uniform_rate": "0.0"},
    ],
)
def test_policy_combinations_make_the_python_engines_trees(params):
    make = get_problem("bug_trap").setup
    assert_same_run(solve(make, "python", params=params), solve(make, "compiled", params=params))


def test_intermediate_states_and_repeated_solves_without_clear():
    make = get_problem("narrow_gap").setup
    kwargs = {"addIntermediateStates": True}
    python = solve(make, "python", solves=3, **kwargs)
    compiled = solve(make, "compiled", solves=3, **kwargs)
    assert_same_run(python, compiled)
    assert python[2][1]["start_tree_size"] > python[0][1]["start_tree_size"]  # the trees carry over


def test_a_cleared_planner_solves_as_a_new_one():
    """clear() empties the trees in place (their arrays, the compiled engine's index and the nodes'
    failure counts kept for the next solve): the solve after it makes the trees, path and counts
    of a new planner with the same seed, on both engines, after trees searched through the index."""
    make = get_problem("bug_trap").setup
    params = {"nearest_policy": "exhausted", "exhausted_after": "2", "range": "0.02"}  # (failures matter)

    def cleared_and_reseeded(ss, planner):
        ss.clear()
        planner.params().setParam("seed", "11")

    for engine in ("python", "compiled"):
        first, cleared = solve(make, engine, seed=3, params=params, solves=2, between=(cleared_and_reseeded,))
        assert max(len(tree) for tree in first[2]) >= INDEX_FROM  # (the index was built)
        assert_same_run([cleared], solve(make, engine, seed=11, params=params))


def finer_resolution(ss, planner):
    si = ss.getSpaceInformation()
    si.setStateValidityCheckingResolution(0.002)
    si.setup()


def test_changes_between_solves_reach_the_compiled_engine():
    """The compiled engine keeps its check view, arrays and loop settings from one solve to the
    next; a finer validity-checking resolution (after ``si.setup()``), a new range, a recorded
    run and a ``clear()`` must reach it as they reach the Python engine."""
    from ompl_balance.engine.events import LoopRecord

    def record(ss, planner):
        planner.loop_record = LoopRecord()

    def shorter_range(ss, planner):
        planner.params().setParam("range", "0.04")

    changes = (finer_resolution, shorter_range, record, lambda ss, planner: ss.clear())
    make = get_problem("narrow_gap").setup
    python = solve(make, "python", solves=5, between=changes)
    compiled = solve(make, "compiled", solves=5, between=changes)
    assert_same_run(python, compiled)
    checks_per_motion = [run[1]["states_checked"] / max(run[1]["motions_checked"], 1) for run in python]
    assert checks_per_motion[1] > checks_per_motion[0]  # (the finer resolution checks more states a motion)


def several_goals_setup():
    ss = get_problem("maze").setup()
    goals = ob.GoalStates(ss.getSpaceInformation())
    for x, y in ((0.95, 0.95), (0.95, 0.05), (0.7, 0.95)):
        goal = ss.getStateSpace().allocState()
        goal[0], goal[1] = x, y
        goals.addState(goal)
    ss.setGoal(goals)
    return ss


def test_goal_states_are_fed_as_the_python_engine_feeds_them():
    assert_same_run(solve(several_goals_setup, "python"), solve(several_goals_setup, "compiled"))


class GoalRefusingOneState(ob.GoalStates):
    """Goal states of which the last may not end a path (``isStartGoalPairValid`` refuses it)."""

    def __init__(self, si):
        super().__init__(si)
        self.asked = 0

    def isStartGoalPairValid(self, start, goal):
        self.asked += 1
        last = self.getState(self.getStateCount() - 1)
        return (goal[0], goal[1]) != (last[0], last[1])


@pytest.mark.parametrize("engine", ["python", "compiled"])
def test_a_goal_written_in_python_is_asked_for_each_connection(engine):
    ss = several_goals_setup()
    si = ss.getSpaceInformation()
    goals = GoalRefusingOneState(si)
    for x, y in ((0.95, 0.95), (0.95, 0.05), (0.7, 0.95)):
        goal = ss.getStateSpace().allocState()
        goal[0], goal[1] = x, y
        goals.addState(goal)
    ss.setGoal(goals)
    planner = BalancedRRTConnect(si)
    assert planner.params().setParams({"engine": engine, "seed": "5"})
    ss.setPlanner(planner)
    assert ss.solve(20.0) == ob.PlannerStatus.EXACT_SOLUTION
    end = ss.getSolutionPath().getState(ss.getSolutionPath().getStateCount() - 1)
    # (without the refusal, this seed's paths end at the last goal state)
    assert goals.asked >= 2
    assert (end[0], end[1]) in ((0.95, 0.95), (0.95, 0.05))


def shell_setup():
    """A Python callable checker (through si.isValid and si.checkMotion): a 4-D shell around the start."""
    space = ob.RealVectorStateSpace(4)
    space.setBounds(-1.0, 1.0)
    ss = og.SimpleSetup(space)

    def free(state) -> bool:
        values = [state[i] for i in range(4)]
        radius = math.sqrt(sum(v * v for v in values))
        return not 0.3 <= radius <= 0.4 or -values[0] / radius > 0.9

    ss.setStateValidityChecker(free)
    start, goal = space.allocState(), space.allocState()
    for i in range(4):
        start[i] = goal[i] = 0.0
    goal[0] = 0.8
    ss.setStartAndGoalStates(start, goal)
    return ss


def test_a_python_checker_gives_the_same_trees_through_the_space_information():
    python = solve(shell_setup, "python")
    compiled = solve(shell_setup, "compiled")
    assert_same_run(python, compiled)


@pytest.mark.parametrize("se2", [False, True])
def test_occupancy_grids_in_the_plane_and_in_se2(se2):
    make = rooms_problem(se2=se2).setup
    assert_same_run(solve(make, "python"), solve(make, "compiled"))


def test_the_kernels_and_the_path_they_take_are_reported():
    ss = get_problem("bug_trap").setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    ss.setPlanner(planner)
    assert ss.solve(10.0)
    assert (planner.stats.engine, planner.stats.checks, planner.stats.exits) == ("compiled", "kernel", 0)
    ss = shell_setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    ss.setPlanner(planner)
    assert ss.solve(10.0)
    assert (planner.stats.engine, planner.stats.checks) == ("compiled", "python")
    # one call out per growth of a tree (an extension; a connect, all its steps), not per motion
    assert 0 < planner.stats.exits <= 2 * planner.stats.iterations


def test_auto_plans_every_checker_on_the_compiled_engine():
    """engine=auto plans on the compiled engine whatever the checker, once it is loaded: with the
    package's kernels (the box world), and with a Python callable, called once per motion."""
    for make, checks in ((shell_setup, "python"), (get_problem("bug_trap").setup, "kernel")):
        ss = make()
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        ss.setPlanner(planner)
        ss.setup()
        planner.wait_for_engine()
        assert ss.solve(10.0)
        assert (planner.stats.engine, planner.stats.checks) == ("compiled", checks)


def test_a_solve_handed_over_to_the_compiled_engine_makes_the_python_engines_trees(monkeypatch):
    """engine=auto while the compiled engine loads: the solve begins on Python and the compiled
    engine takes over once it is loaded (here: at the fourth time the planner asks), going on with
    the same trees, random numbers and counts as a whole solve on either engine."""
    from ompl_balance.engine import loading

    make = get_problem("bug_trap").setup
    python = solve(make, "python", params={"range": "0.05"})
    ss = make()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.params().setParams({"engine": "auto", "seed": "3", "range": "0.05"})
    ss.setPlanner(planner)
    ss.setup()
    planner.wait_for_engine()
    asked = []
    ready = loading.LOADER.ready
    monkeypatch.setattr(loading.LOADER, "ready", lambda key: asked.append(key) or (len(asked) > 3 and ready(key)))
    assert ss.solve(20.0)
    assert planner.stats.engine == "python, then compiled" and planner.stats.iterations > 3 * 32
    stats = {key: value for key, value in planner.stats.as_dict().items() if key not in IGNORED}
    assert stats == python[0][1]
    for tree, expected in zip((planner._start_tree, planner._goal_tree), python[0][2]):
        np.testing.assert_array_equal(tree.states, expected)


def robot_setup(motion, scene="arm3", problem_index=0):
    """A robot problem with the package's checker: the 3-joint test arm among four obstacles (a
    start and goal on either side of the wall) or a MotionBenchMaker Panda problem."""
    from ompl_balance.collision.checker import CollisionChecker
    from ompl_balance.validity import setup_robot, space_for

    if scene == "arm3":
        from test_validity import arm3_scene

        robot, environment, _ = arm3_scene()

        def make():
            checker = CollisionChecker(robot, environment)
            ss = og.SimpleSetup(space_for(robot))
            setup_robot(ss, checker, motion=motion)
            si = ss.getSpaceInformation()
            start, goal = si.allocState(), si.allocState()
            for i, (a, b) in enumerate(zip((0.0, -1.0, 0.1), (2.5, 1.0, 0.1))):
                start[i], goal[i] = a, b
            ss.setStartAndGoalStates(start, goal)
            return ss

        return make
    from ompl_balance.collision.robots import load_panda_vamp
    from ompl_balance.worlds.mbm import load_mbm

    robot = load_panda_vamp()
    problem = load_mbm(scene, robot.joint_names)[problem_index]
    return lambda: problem.simple_setup(robot, CollisionChecker(robot, problem.environment), motion=motion)


@pytest.mark.parametrize("motion", ["certified", "discrete"])
def test_the_robot_checkers_kernels_give_the_python_engines_trees(motion):
    make = robot_setup(motion)
    for seed in (1, 2):
        python = solve(make, "python", seed=seed)
        compiled = solve(make, "compiled", seed=seed)
        assert python[0][0] == "Exact solution"
        assert_same_run(python, compiled)


@pytest.mark.parametrize("motion", ["certified", "discrete"])
def test_a_panda_problem_on_both_engines(motion):
    make = robot_setup(motion, "bookshelf_small", 3)
    assert_same_run(solve(make, "python", seed=4), solve(make, "compiled", seed=4))


def rigid_setup(name, motion):
    from ompl_balance import rigid_problem

    problem = rigid_problem(name)
    return lambda: problem.simple_setup(motion=motion)


@pytest.mark.parametrize("name", ["se2_slot", "se3_slot"])
def test_the_rigid_body_checkers_kernels_give_the_python_engines_runs(name):
    """Certified rigid-body motions: the engine calls the checker's kernels (FCL through its
    exits); SE(2) gives the same trees, SE(3) the same work (see the quaternion note below)."""
    make = rigid_setup(name, "certified")
    python = solve(make, "python", seed=2)
    compiled = solve(make, "compiled", seed=2)
    assert python[0][0] == "Exact solution"
    if name == "se2_slot":
        assert_same_run(python, compiled)
    else:
        assert python[0][1] == compiled[0][1]
    ss = make()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    planner.setSeed(2)
    ss.setPlanner(planner)
    assert ss.solve(20.0) == ob.PlannerStatus.EXACT_SOLUTION
    assert planner.stats.checks == "kernel" and planner.stats.exits > 0


@pytest.mark.slow
def test_the_rigid_body_discrete_validator_is_checked_as_ompls_by_the_kernels():
    """The same trees; the Python validator screens a motion's states in one batch (and counts
    them all), the kernels one at a time up to the first collision (and count those)."""
    make = rigid_setup("se2_slot", "discrete")
    python = solve(make, "python", seed=2)
    compiled = solve(make, "compiled", seed=2)
    assert python[0][0] == "Exact solution"
    screened, checked = python[0][1].pop("states_checked"), compiled[0][1].pop("states_checked")
    assert 0 < checked <= screened
    assert_same_run(python, compiled)


# -- SE(3) and the flat layouts' geometry ----------------------------------------------------------


def se3_setup():
    """A point robot in SE(3) (its rotation free) through a wall with a hole, a Python checker."""
    space = ob.SE3StateSpace()
    bounds = ob.RealVectorBounds(3)
    bounds.setLow(-1.0)
    bounds.setHigh(1.0)
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: not (-0.05 < s.getX() < 0.05 and (abs(s.getY()) > 0.2 or abs(s.getZ()) > 0.2)))
    start, goal = space.allocState(), space.allocState()
    start.setXYZ(-0.8, 0.0, 0.0)
    goal.setXYZ(0.8, 0.3, -0.3)
    start.rotation().setIdentity()
    goal.rotation().setAxisAngle(0.0, 0.0, 1.0, 2.5)
    ss.setStartAndGoalStates(start, goal)
    return ss


@pytest.mark.parametrize("space_kind", ["SE2", "SE3", "SO2", "SO3", "compound"])
def test_flat_layouts_have_ompls_metric_and_interpolation(space_kind):
    from ompl_balance.core import compiled_spaces, layout

    if space_kind == "SE2":
        space = ob.SE2StateSpace()
        bounds = ob.RealVectorBounds(2)
        bounds.setLow(-2.0)
        bounds.setHigh(3.0)
        space.setBounds(bounds)
    elif space_kind == "SE3":
        space = se3_setup().getStateSpace()
    elif space_kind == "SO2":
        space = ob.SO2StateSpace()
    elif space_kind == "SO3":
        space = ob.SO3StateSpace()
    else:
        space = ob.CompoundStateSpace()
        inner = ob.RealVectorStateSpace(2)
        inner.setBounds(0.0, 4.0)
        space.addSubspace(inner, 0.7)
        space.addSubspace(ob.SO2StateSpace(), 0.3)
        space.addSubspace(ob.SO3StateSpace(), 1.9)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda s: True)
    si.setStateValidityCheckingResolution(0.013)
    si.setup()
    flat = layout_for(space)
    assert flat is not None
    sampler = si.allocStateSampler()
    a, b, mid = si.allocState(), si.allocState(), si.allocState()
    read = layout.state_reader(space)
    rng = np.random.default_rng(0)
    for _ in range(200):
        sampler.sampleUniform(a)
        sampler.sampleUniform(b)
        x, y = np.array(read(a)), np.array(read(b))
        t = float(rng.uniform())
        space.interpolate(a, b, t, mid)
        for distance, interpolate, count in (
            (layout.distance, lambda p, q, s: layout.interpolate(flat, p, q, s), layout.segment_count),
            (compiled_spaces.distance, None, compiled_spaces.segment_count),
        ):
            assert distance(flat, x, y) == pytest.approx(si.distance(a, b), rel=1e-12, abs=1e-12)
            assert count(flat, x, y) == space.validSegmentCount(a, b)
            if interpolate is not None:
                np.testing.assert_allclose(interpolate(x, y, t), read(mid), rtol=0, atol=1e-12)
        out = np.empty(flat.dim)
        compiled_spaces.interpolate(flat, x, y, t, out)
        np.testing.assert_allclose(out, read(mid), rtol=0, atol=1e-12)
    # uniform samples: inside the bounds, unit quaternions, the same from numpy and compiled code
    uniforms = rng.random((64, flat.total_draws))
    samples = layout.samples_from_uniforms(flat, uniforms)
    compiled = np.empty((64, flat.dim))
    compiled_spaces.samples_from_uniforms(flat, uniforms, compiled)
    np.testing.assert_allclose(compiled, samples, rtol=0, atol=1e-15)
    for row in range(64):
        space.copyFromReals(a, samples[row].tolist())
        assert space.satisfiesBounds(a)


def test_se3_plans_on_both_engines_with_valid_paths():
    for engine in ("python", "compiled"):
        for seed in (1, 2, 3):
            ss = se3_setup()
            planner = BalancedRRTConnect(ss.getSpaceInformation())
            planner.setEngine(engine)
            planner.setSeed(seed)
            ss.setPlanner(planner)
            assert ss.solve(20.0) == ob.PlannerStatus.EXACT_SOLUTION
            path = ss.getSolutionPath()
            assert path.check()  # OMPL's own validator on the path's motions
            assert planner.stats.engine == engine


def test_se3_trees_match_where_the_math_library_agrees_with_numpy():
    """SE(3)'s quaternions go through acos and sin: numpy's vectorised acos may round a distance
    differently in its last bit from the C library's, which could reorder two nearly equally
    near nodes; on the seeds here the two engines agree exactly."""
    python = solve(se3_setup, "python", seed=5)
    compiled = solve(se3_setup, "compiled", seed=5)
    assert python[0][1] == compiled[0][1]


# -- termination, interruption, first use ---------------------------------------------------------


def impossible_setup(kernels: bool = False):
    """A wall across the space: no solve ends before its time. The world is a Python callable,
    or (``kernels``) the package's checker, whose compiled view the engine calls."""
    walled = (*get_problem("narrow_gap").boxes[0][:3], 1.0)
    ss = get_problem("narrow_gap").setup()
    si = ss.getSpaceInformation()
    world = BoxWorld2D((walled,))

    def plain(state: ob.State) -> bool:  # (a plain function: the box world itself would offer its kernel)
        return world(state)

    si.setStateValidityChecker(CountingValidityChecker(si, world) if kernels else plain)
    return ss


def test_a_time_limit_ends_the_compiled_solve_on_time():
    ss = impossible_setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    ss.setPlanner(planner)
    ss.setup()
    with timed() as took:
        assert planner.solve(0.5) == ob.PlannerStatus.TIMEOUT
    assert took.wall >= 0.5 and took.monotonic < 1.0  # (OMPL's limit is on the wall clock)
    assert planner.stats.iterations > 100


def test_the_compiled_loops_clock_measures_the_time_pythons_clock_does():
    """The slices' clock (a C-library call from compiled code): a compiled wait of 20 ms of it
    lasts 20 ms by Python's clock (at least; under load, longer)."""
    from numba import njit

    from ompl_balance.engine.clock import monotonic_ns

    @njit
    def wait(nanoseconds: int) -> int:
        began = monotonic_ns()
        while monotonic_ns() - began < nanoseconds:
            pass
        return monotonic_ns() - began

    wait(0)
    began = time.perf_counter()
    waited = wait(20_000_000)
    elapsed = time.perf_counter() - began
    assert waited >= 20_000_000
    assert 0.019 <= elapsed < 5.0


def test_the_compiled_engine_polls_the_condition_every_few_milliseconds_and_stops_on_an_event():
    ss = impossible_setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    ss.setPlanner(planner)
    ss.setup()
    polled: list[float] = []
    event = {"set": False}

    def stop() -> bool:
        polled.append(time.perf_counter())
        if len(polled) == 200:
            event["set"] = True
        return event["set"]

    assert planner.solve(stop) == ob.PlannerStatus.TIMEOUT
    assert len(polled) == 200  # stopped at the first poll after the event
    gaps = np.diff(polled[20:])
    assert np.median(gaps) < 0.005


@pytest.mark.parametrize("checker", ["kernel", "python callable"])
def test_ctrl_c_interrupts_a_compiled_solve(checker):
    """Both with kernels that never call Python (SIGINT's own handler stays) and with every check
    an exit to Python (SIGINT only sets a flag while a slice runs)."""
    script = textwrap.dedent(
        f"""
        import signal, sys
        from ompl import util as ou
        # Python's handler, as an interactive program has (a background job starts ignoring SIGINT)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        ou.setLogLevel(ou.LOG_WARN)
        sys.path.insert(0, "tests")
        from test_engine import impossible_setup
        from ompl_balance import BalancedRRTConnect
        ss = impossible_setup(kernels={checker == "kernel"})
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        planner.setEngine("compiled")
        ss.setPlanner(planner)
        ss.setup()
        print("solving", flush=True)
        try:
            planner.solve(60.0)
        except KeyboardInterrupt:
            print("interrupted", planner.stats is None or planner.stats.iterations, flush=True)
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
    out, err = process.communicate(timeout=30)
    assert "interrupted" in out, err[-3000:]
    assert time.perf_counter() - began < 10.0


@pytest.fixture
def sigint_handler():
    """Sets SIGINT's handler for a test (``sigint_handler(handler)``), restoring the runner's after."""
    before = signal.getsignal(signal.SIGINT)
    yield lambda handler: signal.signal(signal.SIGINT, handler)
    signal.signal(signal.SIGINT, before)


def test_ctrl_c_in_a_compiled_slice_is_raised_between_slices_not_inside_it(sigint_handler):
    """SIGINT during a slice (where Python code runs only inside a kernel's exit) sets a flag; the
    driver raises KeyboardInterrupt between slices, and at the end if it came in the last one."""
    import os

    from ompl_balance.engine.driver import interrupts_between_slices

    sigint_handler(signal.default_int_handler)
    with interrupts_between_slices(exits=False):
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # kernels without exits: left
    with pytest.raises(KeyboardInterrupt), interrupts_between_slices(exits=True) as act_on_interrupt:
        act_on_interrupt()  # nothing came yet
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.01)  # Python runs the handler here: no exception yet
        reached = True
        act_on_interrupt()
    assert reached
    with pytest.raises(KeyboardInterrupt), interrupts_between_slices(exits=True):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.01)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored


def test_ctrl_c_between_slices_goes_to_the_process_own_handler_and_an_ignored_one_stays_ignored(sigint_handler):
    """A program's own SIGINT handler is called between slices (once per signal, no
    KeyboardInterrupt); where SIGINT is ignored (a background job) a solve leaves it ignored."""
    import os

    from ompl_balance.engine.driver import interrupts_between_slices

    received: list[int] = []
    sigint_handler(lambda number, frame: received.append(number))
    with interrupts_between_slices(exits=True) as act_on_interrupt:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.01)
        assert received == []  # not inside the slice
        act_on_interrupt()
        assert received == [signal.SIGINT]
        act_on_interrupt()
    assert received == [signal.SIGINT]
    sigint_handler(signal.SIG_IGN)
    with interrupts_between_slices(exits=True) as act_on_interrupt:
        assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.01)
        act_on_interrupt()
    assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN


def test_check_views_say_whether_their_kernels_call_python():
    """Only a solve whose kernels may call Python takes SIGINT over (see above): a box world's
    kernels never do; a Python callable is called from its view's kernels (through a C callback,
    where a KeyboardInterrupt raised on the callback's first line could not be caught)."""
    from ompl_balance.engine.views import checks_for

    kernels, callable_world = impossible_setup(kernels=True), impossible_setup()
    for ss in (kernels, callable_world):
        ss.setPlanner(BalancedRRTConnect(ss.getSpaceInformation()))  # (its setup wraps a checker to count)
        ss.setup()
    si = kernels.getSpaceInformation()
    layout = layout_for(si.getStateSpace())
    box_checks = checks_for(si, layout)
    assert box_checks.path == "kernel" and box_checks.exits is False
    si = callable_world.getSpaceInformation()
    callable_checks = checks_for(si, layout)
    assert callable_checks.path == "python" and callable_checks.exits is True


@pytest.mark.parametrize("motion", ["certified", "discrete"])
@pytest.mark.parametrize(
    "make",
    [
        functools.partial(robot_setup, scene="bookshelf_small", problem_index=3),
        functools.partial(rigid_setup, "se2_slot"),
    ],
    ids=["panda", "rigid body"],
)
def test_the_robot_and_rigid_body_views_call_python_for_fcl(make, motion):
    """The robot and rigid-body checkers' kernels leave to FCL through an exit (pairs their bounds
    cannot decide), so their solves take SIGINT over; a solve's counted exits show the calls."""
    from ompl_balance.engine.views import checks_for

    ss = make(motion=motion)()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    planner.setSeed(1)
    ss.setPlanner(planner)
    ss.setup()
    si = ss.getSpaceInformation()
    checks = checks_for(si, layout_for(si.getStateSpace()))
    assert checks.path == "kernel" and checks.exits is True
    assert ss.solve(20.0) == ob.PlannerStatus.EXACT_SOLUTION
    assert planner.stats.checks == "kernel" and planner.stats.exits > 0


def test_a_fresh_processs_first_half_second_solve_returns_in_time():
    script = textwrap.dedent(
        """
        import time
        from ompl import util as ou
        ou.setLogLevel(ou.LOG_WARN)
        from ompl_balance import BalancedRRTConnect, get_problem
        from ompl_balance.worlds.boxes import BoxWorld2D
        walled = (*get_problem("narrow_gap").boxes[0][:3], 1.0)
        ss = get_problem("narrow_gap").setup()
        ss.setStateValidityChecker(BoxWorld2D((walled,)))
        ss.setPlanner(BalancedRRTConnect(ss.getSpaceInformation()))
        began = time.perf_counter()
        ss.solve(0.5)
        print(time.perf_counter() - began)
        """
    )
    elapsed = float(subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout)
    assert elapsed < 1.0


def test_a_process_exits_cleanly_while_the_engine_loads():
    """A short script's solve ends while the compiled engine still loads in the background (auto
    plans on Python meanwhile): the process lets the load finish, exits with 0, and nanobind's
    own check at shutdown finds no OMPL object left alive."""
    script = textwrap.dedent(
        """
        from ompl import util as ou
        ou.setLogLevel(ou.LOG_WARN)
        from ompl_balance import BalancedRRTConnect, get_problem
        ss = get_problem("open").setup()  # (solved in a millisecond, however loaded the machine)
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        ss.setPlanner(planner)
        print(bool(ss.solve(0.5)), planner.stats.engine)
        """
    )
    result = subprocess.run([sys.executable, "-c", script], check=False, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["True", "python"]  # (the engine was still loading)
    assert "leaked" not in result.stderr


def test_measured_solve_times_a_fresh_processs_solve_on_the_compiled_engine():
    """The benchmark scripts' timed solve (``measured_solve``) has the planner load its engine
    first, untimed: in a fresh process, where ``auto`` would plan the first solves on Python while
    the compiled engine loads (the test above), the timed solve runs compiled."""
    script = textwrap.dedent(
        """
        from ompl import util as ou
        ou.setLogLevel(ou.LOG_WARN)
        from ompl_balance import BalancedRRTConnect, get_problem
        from ompl_balance.core.counting import measured_solve
        ss = get_problem("narrow_gap").setup()
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        ss.setPlanner(planner)
        print(measured_solve(ss, 10.0).solved, planner.stats.engine)
        """
    )
    result = subprocess.run([sys.executable, "-c", script], check=False, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["True", "compiled"]


# -- what the compiled engine refuses -------------------------------------------------------------


def test_compiled_refuses_a_valid_state_sampler_and_spaces_without_a_layout():
    ss = get_problem("open").setup()
    planner = PRESETS["GaussianPassageRRTConnect"](ss.getSpaceInformation())
    planner.setEngine("compiled")
    with pytest.raises(ValueError, match="valid_sampler"):
        planner.setup()
    space = ob.DubinsStateSpace(0.2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0.0)
    bounds.setHigh(1.0)
    space.setBounds(bounds)
    assert layout_for(space) is None
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: True)
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setEngine("compiled")
    with pytest.raises(ValueError, match="DubinsStateSpace"):
        planner.setup()
    planner.setEngine("auto")  # auto plans on Python there
    planner.setup()
