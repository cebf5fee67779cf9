"""Drop-in conformance: the package's planners where OMPL code expects og.RRTConnect and og.RRTstar.

OMPL 2.0.1's own Python tests run with the package's planners swapped in (when those tests
are beside the repository), and the package's own checks of what a user's OMPL script
meets: the constructors, the planner graph against stock's on the same problem, the
specs, what C++ callers see, and no start-up cost inside the first solve.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sys
import textwrap
from collections import deque
from pathlib import Path

import numpy as np
import pytest
from fresh_process import run_with_seed
from ompl import base as ob
from ompl import control as oc
from ompl import geometric as og
from ompl import tools as ot
from ompl import util as ou

from ompl_balance import PRESETS, BalancedRRTConnect, BallRadiusRRTstar
from ompl_balance.worlds.boxes import Problem, get_problem

ou.setLogLevel(ou.LOG_WARN)

#: OMPL 2.0.1's ``tests/pytests/`` folder: ``$OMPL_PYTESTS`` if set, else beside the repository.
OMPL_PYTESTS = Path(
    os.environ.get("OMPL_PYTESTS") or Path(__file__).resolve().parents[2] / "shared" / "data" / "ompl_pytests"
)

SWAP = """\
import ompl.geometric as og
import ompl_balance

og.RRTConnect = ompl_balance.BalancedRRTConnect
og.RRTstar = ompl_balance.BallRadiusRRTstar
"""


def _counts(output: str) -> dict[str, int]:
    """pytest's summary line as counts: ``{"passed": 89, "failed": 0, ...}``."""
    summary = output.strip().splitlines()[-1]
    counts = {"passed": 0, "failed": 0, "errors": 0, "skipped": 0}
    for number, word in re.findall(r"(\d+) (passed|failed|errors?|skipped)", summary):
        counts["errors" if word.startswith("error") else word] += int(number)
    return counts


@pytest.mark.skipif(not OMPL_PYTESTS.is_dir(), reason=f"OMPL's Python tests are not at {OMPL_PYTESTS}")
def test_ompls_own_python_tests_pass_with_the_package_planners_swapped_in(tmp_path):
    copy = tmp_path / "ompl_pytests"
    shutil.copytree(OMPL_PYTESTS, copy)
    (copy / "conftest.py").write_text(SWAP)
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(copy)],
        capture_output=True,
        text=True,
        cwd=copy,
        timeout=600,
        check=False,  # the counts say what failed
    )
    counts = _counts(result.stdout)
    assert counts == {"passed": 89, "failed": 0, "errors": 0, "skipped": 0}, result.stdout[-3000:]


# -- constructors --------------------------------------------------------------------------


def test_constructors_take_stocks_arguments():
    si = get_problem("open").setup().getSpaceInformation()
    stock = og.RRTConnect(si, True)
    assert stock.getName() == "RRTConnectIntermediate" and stock.getIntermediateStates()
    for name, planner_class in PRESETS.items():
        plain, intermediate = planner_class(si), planner_class(si, True)
        assert plain.getName() == name and not plain.getIntermediateStates()
        assert intermediate.getName() == f"{name}Intermediate" and intermediate.getIntermediateStates()
        assert planner_class(si, False).getName() == name
        assert planner_class(si, True, "mine").getName() == planner_class(si, name="mine").getName() == "mine"
        assert planner_class(si, addIntermediateStates=True).getIntermediateStates()
        # the preset's policies are untouched by the argument
        for parameter, value in planner_class.POLICIES.items():
            assert intermediate.params().getParam(parameter) == value


@pytest.mark.parametrize("argument", ["BalancedRRTConnect2", 1, 0, None.__class__])
def test_a_second_argument_that_is_not_a_bool_is_a_type_error_naming_the_signature(argument):
    si = get_problem("open").setup().getSpaceInformation()
    with pytest.raises(TypeError, match=r"\(si, addIntermediateStates=False, name=None\): addIntermediateStates"):
        BalancedRRTConnect(si, argument)
    with pytest.raises(TypeError, match="name must be a str"):
        BalancedRRTConnect(si, False, 3)


def _control_setup() -> oc.SimpleSetup:
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    return oc.SimpleSetup(oc.RealVectorControlSpace(space, 2))


@pytest.mark.parametrize("planner_class", [BalancedRRTConnect, *PRESETS.values(), BallRadiusRRTstar])
def test_a_control_space_information_or_a_simple_setup_is_a_type_error_naming_what_is_accepted(planner_class):
    control = _control_setup()
    geometric = get_problem("open").setup()
    for given, kind in (
        (control.getSpaceInformation(), "control.SpaceInformation"),
        (control, "control.SimpleSetup"),
        (geometric, "geometric.SimpleSetup"),
    ):
        with pytest.raises(TypeError) as raised:
            planner_class(given)
        message = str(raised.value)
        assert "\n" not in message and kind in message, message
        assert "si must be a geometric ompl.base.SpaceInformation (ss.getSpaceInformation() of an" in message
    planner_class(geometric.getSpaceInformation())  # what is accepted


# -- the planner graph ---------------------------------------------------------------------


def _graph_path(data: ob.PlannerData) -> list[int]:
    """A directed path from the first start vertex to a goal vertex (breadth-first), or []."""
    start = data.getStartIndex(0)
    came_from = {start: start}
    queue = deque([start])
    while queue:
        vertex = queue.popleft()
        if data.isGoalVertex(vertex):
            path = [vertex]
            while path[-1] != start:
                path.append(came_from[path[-1]])
            return path[::-1]
        for following in data.getEdges(vertex):
            if following not in came_from:
                came_from[following] = vertex
                queue.append(following)
    return []


def _shape(ss: og.SimpleSetup, data: ob.PlannerData) -> dict:
    """What stock's and our graph must share, and the graph's path against the solution path."""
    vertices = data.numVertices()
    tags = {data.getVertex(i).getTag() for i in range(vertices)}
    path = _graph_path(data)
    solution = ss.getSolutionPath()
    states = [[solution.getState(i)[k] for k in range(2)] for i in range(solution.getStateCount())]
    graph_states = [[data.getVertex(v).getState()[k] for k in range(2)] for v in path]
    start, goal = data.getStartIndex(0), data.getGoalIndex(0)
    return {
        "edges": data.numEdges() - (vertices - 1),  # V - 1 edges: 0
        "starts": data.numStartVertices(),
        "goals": data.numGoalVertices(),
        "tags": tags,
        "start tag": data.getVertex(start).getTag(),
        "goal tag": data.getVertex(goal).getTag(),
        "start has no incoming edge": data.getIncomingEdges(start) == [],
        "goal has no outgoing edge": data.getEdges(goal) == [],
        "graph path is the solution": graph_states == states,
    }


@pytest.mark.parametrize("problem_name", ["narrow_gap", "bug_trap"])
def test_planner_graph_has_stocks_shape_on_the_same_problem(problem_name):
    shapes = []
    for make in (og.RRTConnect, BalancedRRTConnect):
        ss = get_problem(problem_name).setup()
        planner = make(ss.getSpaceInformation())
        ss.setPlanner(planner)
        assert ss.solve(10.0) == ob.PlannerStatus.EXACT_SOLUTION
        data = ob.PlannerData(ss.getSpaceInformation())
        planner.getPlannerData(data)  # as OMPL's test_planner_data.py calls it
        shapes.append(_shape(ss, data))
    stock, ours = shapes
    assert stock == ours
    assert ours["edges"] == 0 and ours["tags"] == {1, 2} and ours["graph path is the solution"]


def test_planner_graph_properties_and_a_second_solve():
    ss = get_problem("maze").setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    ss.setPlanner(planner)
    assert ss.solve(10.0)
    graph = planner.plannerData()
    assert graph.properties["approx goal distance REAL"] == "0"
    assert graph.properties["iterations INTEGER"] == str(planner.stats.iterations)
    assert graph.properties["start tree size INTEGER"] == str(planner.stats.start_tree_size)
    planner.clear()
    empty = planner.plannerData()
    assert empty.numVertices() == 0 and empty.properties["approx goal distance REAL"] == "inf"


#: A wall across the square, 0.1 thick: no way through.
WALL = Problem("wall", "a wall across the square", ((0.45, 0.0, 0.55, 1.0),), (0.1, 0.5), (0.9, 0.5))


def test_approx_goal_distance_is_stocks_on_an_impossible_problem():
    """Stock reports its value through OMPL's Benchmark (which copies the PlannerData
    properties into each run); both come close to the wall's thickness from above."""
    ss = WALL.setup()
    benchmark = ot.Benchmark(ss, "approx goal distance")
    benchmark.addPlanner(og.RRTConnect(ss.getSpaceInformation()))
    benchmark.benchmark(ot.Request(0.5, 1024.0, 1, 0.05, False, False, False))
    (run,) = benchmark.getRecordedExperimentData().planners[0].runs
    stock = float(run.to_dict()["approx goal distance REAL"])

    ss = WALL.setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setSeed(4)
    planner.setEngine("python")  # checks the condition, which counts iterations, every iteration
    ss.setPlanner(planner)
    iterations = iter(range(3000))
    ss.solve(ob.PlannerTerminationCondition(lambda: next(iterations, None) is None))
    ours = float(planner.plannerData().properties["approx goal distance REAL"])
    start, goal = planner._start_tree.states, planner._goal_tree.states
    closest_pair = min(float(np.linalg.norm(goal - point, axis=1).min()) for point in start)
    # never below the trees' true distance (but for the six digits of C++'s default format)
    assert 0.1 <= closest_pair <= ours * (1 + 5e-6)
    assert stock >= 0.1 and math.isclose(ours, stock, rel_tol=0.25), (ours, stock)


# -- what C++ callers and printouts see ---------------------------------------------------


def test_cpp_callers_get_ompls_methods_and_python_callers_the_packages():
    """SimpleSetup and Benchmark (C++ callers of getPlannerData, printProperties and
    printSettings) run every planner of the package without aborting the process."""
    script = textwrap.dedent(
        """
        from ompl import base as ob, tools as ot, util as ou
        ou.setLogLevel(ou.LOG_ERROR)
        import ompl_balance
        classes = [ompl_balance.BallRadiusRRTstar] + [getattr(ompl_balance, name) for name in ompl_balance.PRESETS]
        for planner_class in classes:
            ss = ompl_balance.get_problem("narrow_gap").setup()
            planner = planner_class(ss.getSpaceInformation())
            ss.setPlanner(planner)
            ss.solve(10.0)
            data = ob.PlannerData(ss.getSpaceInformation())
            ss.getPlannerData(data)  # C++ calls getPlannerData: OMPL's, empty
            mine = ob.PlannerData(ss.getSpaceInformation())
            ss.getPlanner().getPlannerData(mine)  # as OMPL's test_planner_data.py calls it
            benchmark = ot.Benchmark(ss, "cpp callers")
            benchmark.addPlanner(planner)
            benchmark.benchmark(ot.Request(1.0, 1024.0, 1, 0.05, False, False, False))
            run = benchmark.getRecordedExperimentData().planners[0].runs[0].to_dict()
            print(planner_class.__name__, data.numVertices(), mine.numVertices() > 0, run["graph states INTEGER"],
                  run["solved BOOLEAN"])
        """
    )
    lines = [line.split() for line in run_with_seed(script, 0).splitlines()]
    assert len(lines) == 1 + len(PRESETS)  # every planner ran to the end: none aborted the process
    assert all(line[1:4] == ["0", "True", "0"] for line in lines), lines
    # solved within the benchmark's 1 s (the others may, under load, not; what is tested is the calls)
    assert ["BalancedRRTConnect", "0", "True", "0", "1"] in lines


def test_specs_and_printouts_read_as_stocks():
    si = get_problem("open").setup().getSpaceInformation()
    ours, stock = BalancedRRTConnect(si), og.RRTConnect(si)
    specs = ours.getSpecs()
    assert specs.recognizedGoal == ob.GoalType.GOAL_SAMPLEABLE_REGION and specs.directed
    assert not specs.approximateSolutions and not specs.optimizingPaths
    lines, stock_lines = ours.printProperties().splitlines(), stock.printProperties().splitlines()
    assert lines[1:4] == stock_lines[1:4]  # the same answers: no threads, no approximate paths, not optimising
    assert set(stock_lines[4].split(": ")[1].split()) <= set(lines[4].split(": ")[1].split())
    settings = ours.printSettings().splitlines()
    assert settings[0] == "Declared parameters for planner BalancedRRTConnect:"
    assert "range = 0.0" in settings and "intermediate_states = 0" in settings


# -- start-up cost -------------------------------------------------------------------------

FIRST_SOLVE = """
import sys, time
from ompl import base as ob, geometric as og, util as ou
ou.setLogLevel(ou.LOG_ERROR)
import ompl_balance
from ompl_balance.worlds.boxes import Problem
wall = Problem("wall", "", ((0.45, 0.0, 0.55, 1.0),), (0.1, 0.5), (0.9, 0.5))
times = []
for planner_class in (ompl_balance.BalancedRRTConnect, ompl_balance.BallRadiusRRTstar):
    for limit in (0.5, 0.0, -1.0):
        ss = wall.setup()
        ss.setPlanner(planner_class(ss.getSpaceInformation()))
        on_wall_clock, began = time.time(), time.perf_counter()
        ss.solve(limit)
        times += [time.time() - on_wall_clock, time.perf_counter() - began]  # (OMPL's clock, the monotonic one)
print(*times)
"""


def test_a_fresh_processs_first_solve_takes_its_time_limit_and_no_more():
    """The first ss.solve(0.5) of a process returns after 0.5 s and one iteration (it used
    to load the compiled kernels inside, 1.1 s); solve(0) and solve(-1) return at once."""
    times = [float(value) for value in run_with_seed(FIRST_SOLVE, 0).split()]
    (rrtc, rrtc_zero, rrtc_negative, rrtstar, rrtstar_zero, rrtstar_negative) = zip(times[::2], times[1::2])
    # (at least the limit on OMPL's clock, the wall clock; at most a little more on the monotonic one)
    assert rrtc[0] >= 0.5 and rrtc[1] < 0.8 and rrtstar[0] >= 0.5 and rrtstar[1] < 0.8, (rrtc, rrtstar)
    assert max(took[1] for took in (rrtc_zero, rrtc_negative, rrtstar_zero, rrtstar_negative)) < 0.1
