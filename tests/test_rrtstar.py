"""BallRadiusRRTstar: valid paths, monotone cost, the gamma claim, drop-in behaviour, bad input."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og
from ompl import tools as ot
from ompl import util as ou
from pathcheck import assert_valid_solution

from ompl_balance.core.trees import ArrayTree
from ompl_balance.gamma import ball_radius_constant
from ompl_balance.rrtstar import BallRadiusRRTstar
from ompl_balance.worlds.boxes import get_problem
from ompl_balance.worlds.occupancy import rooms_problem

ou.setLogLevel(ou.LOG_WARN)


def _planner(ss: og.SimpleSetup, **params: str) -> BallRadiusRRTstar:
    planner = BallRadiusRRTstar(ss.getSpaceInformation())
    assert planner.params().setParams(params)
    ss.setPlanner(planner)
    return planner


def _goal_test(si, goal_values):
    def reaches(state) -> bool:
        return math.dist([state[i] for i in range(len(goal_values))], goal_values) < 1e-9

    return reaches


def test_rooms_path_is_valid_and_its_cost_is_the_reported_best():
    problem = rooms_problem()
    ss = problem.setup()
    planner = _planner(ss, range="4", max_iterations="800", seed="1", ball_radius_constant="auto")
    assert ss.solve(30.0) == ob.PlannerStatus.EXACT_SOLUTION
    start = ss.getSpaceInformation().allocState()
    problem.write_state(start, problem.start)
    path = assert_valid_solution(ss, problem.is_valid, [start], _goal_test(None, problem.goal))
    assert path.length() == pytest.approx(planner.stats.best_cost)
    assert planner.stats.tree_size <= planner.stats.iterations + 1
    assert planner.stats.rewires > 0


def test_se2_rooms_path_is_valid():
    problem = rooms_problem(se2=True)
    ss = problem.setup()
    # SE(2) runs on OMPL's sampler (the seed parameter does not apply): stop at the first path
    planner = _planner(ss, range="6", max_iterations="0", goal_bias="0.2", continue_after_goal_reached="0")
    assert ss.solve(60.0) == ob.PlannerStatus.EXACT_SOLUTION
    si = ss.getSpaceInformation()
    start, goal = si.allocState(), si.allocState()
    problem.write_state(start, problem.start)
    problem.write_state(goal, problem.goal)
    assert_valid_solution(ss, problem.is_valid, [start], lambda state: si.distance(state, goal) < 1e-9)
    assert planner.stats.best_cost == pytest.approx(ss.getSolutionPath().length())


@pytest.mark.parametrize("name", ["maze", "bug_trap"])
def test_box_world_paths_are_valid(name):
    problem = get_problem(name)
    ss = problem.setup()
    _planner(ss, max_iterations="4000", seed="2")
    assert ss.solve(30.0)
    si = ss.getSpaceInformation()
    start = si.allocState()
    start[0], start[1] = problem.start
    assert_valid_solution(ss, problem.world(), [start], _goal_test(si, problem.goal))


def test_best_cost_never_increases_and_matches_the_iterations():
    ss = rooms_problem().setup()
    planner = _planner(ss, range="4", max_iterations="600", seed="5", ball_radius_constant="3000")
    ss.solve(30.0)
    costs = planner.stats.best_costs
    assert len(costs) == planner.stats.iterations == 600
    first = planner.stats.first_solution_iteration
    assert first is not None and np.all(np.isinf(costs[: first - 1])) and np.isfinite(costs[first - 1])
    assert np.all(np.diff(costs[first - 1 :]) <= 0)
    assert costs[-1] == planner.stats.best_cost
    assert costs[-1] < costs[first - 1]  # rewiring improved the first path


def test_estimated_gamma_beats_the_default_of_100_at_equal_iterations():
    """With gamma = 100 (MATLAB's default) the 40 m map's ball is nearly empty and the cost stalls."""
    problem = rooms_problem()
    final = {}
    for gamma in ("100", "auto"):
        costs = []
        for seed in range(1, 11):
            ss = problem.setup()
            planner = _planner(ss, ball_radius_constant=gamma, range="4", max_iterations="1000", seed=str(seed))
            ss.solve(60.0)
            assert planner.stats.iterations == 1000
            costs.append(planner.stats.best_cost)
        final[gamma] = costs
    # the estimate is close to gamma* of the exact free area
    assert planner.getBallRadiusConstantInUse() == pytest.approx(
        ball_radius_constant(2, problem.grid.free_area), rel=0.05
    )
    assert np.median(final["auto"]) < np.median(final["100"]), final


def test_cost_threshold_stops_at_the_first_solution():
    ss = rooms_problem().setup()
    objective = ob.PathLengthOptimizationObjective(ss.getSpaceInformation())
    objective.setCostThreshold(ob.Cost(1e6))
    ss.setOptimizationObjective(objective)
    planner = _planner(ss, range="4", max_iterations="3000", seed="3")
    assert ss.solve(30.0) == ob.PlannerStatus.EXACT_SOLUTION
    assert planner.stats.iterations == planner.stats.first_solution_iteration < 3000


def test_not_continuing_after_the_goal_stops_at_the_first_solution():
    ss = rooms_problem().setup()
    planner = _planner(ss, range="4", max_iterations="3000", seed="3", continue_after_goal_reached="0")
    assert ss.solve(30.0)
    assert planner.stats.iterations == planner.stats.first_solution_iteration


def test_limits_on_iterations_and_nodes():
    ss = rooms_problem().setup()
    planner = _planner(ss, range="4", max_iterations="0", max_nodes="150", seed="3")
    ss.solve(30.0)
    assert planner.stats.tree_size == 150
    planner.clear()
    planner.setMaxNodes(0)
    planner.setMaxIterations(50)
    ss.getProblemDefinition().clearSolutionPaths()
    assert ss.solve(30.0) == ob.PlannerStatus.TIMEOUT
    assert planner.stats.iterations == 50


def test_same_seed_same_run():
    runs = []
    for _ in range(2):
        ss = rooms_problem().setup()
        planner = _planner(ss, range="4", max_iterations="300", seed="11", ball_radius_constant="auto")
        ss.solve(30.0)
        runs.append((planner.getBallRadiusConstantInUse(), planner.stats.best_costs, planner.stats.states_checked))
    assert runs[0][0] == runs[1][0] and runs[0][2] == runs[1][2]
    np.testing.assert_array_equal(runs[0][1], runs[1][1])


def test_planner_data_is_the_tree():
    ss = rooms_problem().setup()
    planner = _planner(ss, range="4", max_iterations="300", seed="4")
    ss.solve(30.0)
    data = planner.plannerData()
    assert data.numVertices() == planner.stats.tree_size
    assert data.numEdges() == planner.stats.tree_size - 1
    assert data.numStartVertices() == 1
    assert data.numGoalVertices() >= 1


def test_drops_into_a_benchmark_next_to_stock_rrtstar():
    ss = rooms_problem().setup()
    # Both planners stop at their first solution (any cost satisfies the objective), so
    # the test does not depend on how far a loaded machine gets in the time limit.
    objective = ob.PathLengthOptimizationObjective(ss.getSpaceInformation())
    objective.setCostThreshold(objective.infiniteCost())
    ss.setOptimizationObjective(objective)
    benchmark = ot.Benchmark(ss, "rrtstar drop-in")
    ours = BallRadiusRRTstar(ss.getSpaceInformation())
    ours.params().setParams({"range": "4", "max_iterations": "0"})
    stock = og.RRTstar(ss.getSpaceInformation())
    stock.setRange(4.0)
    benchmark.addPlanner(ours)
    benchmark.addPlanner(stock)
    benchmark.benchmark(ot.Request(10.0, 1024.0, 2, 0.05, False, False, False))
    planners = {p.name: p for p in benchmark.getRecordedExperimentData().planners}
    for name in ("geometric_BallRadiusRRTstar", "geometric_RRTstar"):
        runs = planners[name].runs
        assert len(runs) == 2 and all(run.to_dict()["solved BOOLEAN"] == "1" for run in runs)


def _stock_parameters(planner: og.RRTstar) -> dict[str, str]:
    """og.RRTstar's declared parameters and values, read from its printSettings()."""
    lines = planner.printSettings().splitlines()[1:]
    return dict(line.split(" = ") for line in lines if " = " in line)


def test_carries_og_rrtstar_parameters_where_they_mean_the_same():
    si = rooms_problem().setup().getSpaceInformation()
    ours, stock = BallRadiusRRTstar(si), og.RRTstar(si)
    shared = {"range", "goal_bias", "rewire_factor", "use_k_nearest", "delay_collision_checking"}
    shared |= {"tree_pruning", "prune_threshold"}
    stock_params = _stock_parameters(stock)
    assert shared <= set(stock_params)
    assert set(ours.params().getParamNames()) == shared | {
        "ball_radius_constant",
        "continue_after_goal_reached",
        "max_iterations",
        "max_nodes",
        "seed",
    }
    # og.RRTstar's camelCase accessors of those parameters, under og.RRTstar's spelling
    stock_accessors = {name for name in dir(stock) if name[:3] in ("set", "get")}
    values = {"Range": 2.5, "GoalBias": 0.2, "RewireFactor": 1.3, "PruneThreshold": 0.1}
    for stem in ("Range", "GoalBias", "RewireFactor", "KNearest", "DelayCC", "TreePruning", "PruneThreshold"):
        assert {f"set{stem}", f"get{stem}"} <= stock_accessors
        value = values.get(stem, True)
        getattr(ours, f"set{stem}")(value)
        getattr(stock, f"set{stem}")(value)
        assert getattr(ours, f"get{stem}")() == getattr(stock, f"get{stem}")() == value
    assert _stock_parameters(stock)["range"] == ours.params().getParam("range") == "2.5"
    # no second name for the range
    assert not hasattr(ours, "setMaxConnectionDistance") and "max_connection_distance" not in ours.params()


def test_specs_say_it_optimizes_and_gives_no_approximate_solutions():
    si = rooms_problem().setup().getSpaceInformation()
    planner = BallRadiusRRTstar(si)
    specs = planner.getSpecs()
    assert specs.optimizingPaths and not specs.approximateSolutions and not specs.multithreaded
    lines = planner.printProperties().splitlines()
    stock_lines = og.RRTstar(si).printProperties().splitlines()
    assert [line.split(":")[0] for line in lines[1:]] == [line.split(":")[0] for line in stock_lines[1:]]
    assert lines[0] == "Planner BallRadiusRRTstar specs:" and stock_lines[0] == "Planner RRTstar specs:"
    assert "Can optimize solutions:        Yes" in lines and "Reports approximate solutions: No" in lines
    assert lines[-1].split(": ")[1].split() == planner.params().getParamNames()
    settings = planner.printSettings().splitlines()
    assert settings[0] == "Declared parameters for planner BallRadiusRRTstar:"
    assert settings[1:] == [f"{name} = {value}" for name, value in planner.params().getParams().items()]


def test_parameters_and_camel_case_accessors():
    ss = rooms_problem().setup()
    planner = BallRadiusRRTstar(ss.getSpaceInformation())
    params = planner.params()
    # the default is the estimate, and says so (MATLAB's default is 100 whatever the map)
    assert params.getParam("ball_radius_constant") == "auto" and params.getParam("goal_bias") == "0.05"
    assert params.getParam("rewire_factor") == "1.0" and params.getParam("use_k_nearest") == "0"
    planner.setBallRadiusConstant(250.0)
    assert params.getParam("ball_radius_constant") == "250.0" and planner.getBallRadiusConstantInUse() == 250.0
    assert params.setParam("ball_radius_constant", "auto") and planner.getBallRadiusConstant() == "auto"
    planner.setSeed(11)
    estimate = planner.getBallRadiusConstantInUse()  # estimated on demand, then kept for the solve
    assert estimate == pytest.approx(ball_radius_constant(2, rooms_problem().grid.free_area), rel=0.05)
    planner.setMaxIterations(20)
    ss.setPlanner(planner)
    ss.solve(30.0)
    assert planner.stats.ball_radius_constant == estimate


def test_constructor_takes_only_si_and_a_name():
    si = rooms_problem().setup().getSpaceInformation()
    assert BallRadiusRRTstar(si).getName() == "BallRadiusRRTstar"
    assert BallRadiusRRTstar(si, "mine").getName() == BallRadiusRRTstar(si, name="mine").getName() == "mine"
    with pytest.raises(TypeError, match=r"BallRadiusRRTstar\(si, name=None\): name must be a str, got True"):
        BallRadiusRRTstar(si, True)


def test_rewire_factor_scales_the_radius_and_k_nearest_takes_og_rrtstars_k():
    si = rooms_problem().setup().getSpaceInformation()
    planner = BallRadiusRRTstar(si)
    planner.setRange(100.0)
    points = np.random.default_rng(3).random((500, 2)) * 40.0
    tree = ArrayTree(2)
    for point in points:
        tree.add(point)
    query = np.array([20.0, 20.0])
    distances = np.linalg.norm(points - query, axis=1)
    gamma = 3000.0
    for factor in (1.0, 2.0):
        planner.setRewireFactor(factor)
        radius = factor * (gamma * math.log(501) / 501) ** 0.5
        indices, found = planner._neighbours(tree, query, 2, gamma)
        assert indices.tolist() == np.flatnonzero(distances <= radius).tolist()
        np.testing.assert_allclose(found, distances[indices], rtol=1e-12)
    planner.setKNearest(True)
    planner.setRewireFactor(1.1)
    k = math.ceil(1.1 * 2**3 * math.e * 1.5 * math.log(501))  # og.RRTstar's k_rrt * log(N)
    indices, found = planner._neighbours(tree, query, 2, gamma)
    assert len(indices) == k and indices.tolist() == sorted(indices.tolist())
    assert found.max() == np.sort(distances)[k - 1]


def test_k_nearest_mode_solves_with_a_valid_path_and_needs_no_gamma():
    problem = rooms_problem()
    ss = problem.setup()
    planner = _planner(ss, range="4", max_iterations="600", seed="2", use_k_nearest="1")
    assert ss.solve(30.0) == ob.PlannerStatus.EXACT_SOLUTION
    start = ss.getSpaceInformation().allocState()
    problem.write_state(start, problem.start)
    path = assert_valid_solution(ss, problem.is_valid, [start], _goal_test(None, problem.goal))
    assert path.length() == pytest.approx(planner.stats.best_cost)
    assert math.isnan(planner.stats.ball_radius_constant) and planner.stats.rewires > 0


def test_without_delayed_checking_the_same_tree_with_more_checks():
    runs = {}
    for delay in ("1", "0"):
        ss = rooms_problem().setup()
        planner = _planner(ss, range="4", max_iterations="400", seed="6", delay_collision_checking=delay)
        ss.solve(30.0)
        runs[delay] = planner.stats
    assert runs["0"].best_cost == pytest.approx(runs["1"].best_cost, rel=1e-12)
    assert runs["0"].tree_size == runs["1"].tree_size and runs["0"].rewires == runs["1"].rewires
    assert runs["0"].motions_checked > runs["1"].motions_checked


def _check_costs(planner: BallRadiusRRTstar) -> None:
    """Every node's cost is the length of its branch, recomputed from the states."""
    nodes = planner._tree
    tree = nodes.tree
    for node in range(len(tree)):
        branch = tree.branch(node)
        length = sum(float(np.linalg.norm(tree.state(a) - tree.state(b))) for a, b in itertools.pairwise(branch))
        assert nodes.costs[node] == pytest.approx(length, rel=1e-9, abs=1e-9)
        assert all(tree.parent(child) == node for child in nodes.children[node])


def test_tree_pruning_removes_only_nodes_that_cannot_improve_the_solution():
    problem = rooms_problem()
    sizes = {}
    for prune in ("0", "1"):
        ss = problem.setup()
        planner = _planner(ss, range="4", max_iterations="1500", seed="8", tree_pruning=prune)
        assert ss.solve(60.0) == ob.PlannerStatus.EXACT_SOLUTION
        sizes[prune] = planner.stats.tree_size
        _check_costs(planner)
        start = ss.getSpaceInformation().allocState()
        problem.write_state(start, problem.start)
        path = assert_valid_solution(ss, problem.is_valid, [start], _goal_test(None, problem.goal))
        assert path.length() == pytest.approx(planner.stats.best_cost)
    assert sizes["1"] < sizes["0"]

    # One more pruning at the final cost, checked against the straight-line bounds.
    nodes = planner._tree

    def bounds() -> np.ndarray:
        states = nodes.tree.states
        return np.linalg.norm(states - np.array(problem.start), axis=1) + np.linalg.norm(
            states - np.array(problem.goal), axis=1
        )

    best = planner.stats.best_cost
    promising = {tuple(state) for state in nodes.tree.states[bounds() <= best]}
    planner._pruned_cost = math.inf  # prune whatever the threshold
    planner._prune(planner._points, ss.getProblemDefinition().getGoal(), best)
    after = bounds() <= best
    assert promising == {tuple(state) for state in nodes.tree.states[after]}  # all kept
    for node in np.flatnonzero(~after).tolist():  # the others lead to a promising node
        subtree = [node]
        for member in subtree:
            subtree.extend(nodes.children[member])
        assert any(after[member] for member in subtree)
    _check_costs(planner)
    assert nodes.best_cost() == best


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("ball_radius_constant", "-1"),
        ("ball_radius_constant", "0"),
        ("ball_radius_constant", "lots"),
        ("ball_radius_constant", "inf"),
        ("goal_bias", "1.5"),
        ("goal_bias", "-0.1"),
        ("range", "-2"),
        ("max_iterations", "-3"),
        ("max_iterations", "2.5"),
        ("max_nodes", "many"),
        ("continue_after_goal_reached", "maybe"),
        ("rewire_factor", "0"),
        ("prune_threshold", "1.5"),
        ("use_k_nearest", "2"),
    ],
)
def test_bad_parameters_are_rejected_and_leave_the_planner_unchanged(name, value):
    planner = BallRadiusRRTstar(rooms_problem().setup().getSpaceInformation())
    before = planner.params().getParams()
    assert planner.params().setParam(name, value) is False
    assert planner.params().getParams() == before


def test_other_objectives_are_refused_with_a_clear_error():
    ss = rooms_problem().setup()
    si = ss.getSpaceInformation()
    ss.setOptimizationObjective(ob.StateCostIntegralObjective(si, True))
    _planner(ss, max_iterations="10")
    with pytest.raises(ValueError, match="path length"):
        ss.solve(1.0)  # through SimpleSetup's C++ solve into the Python planner and back


def test_bad_time_limit_is_rejected():
    ss = rooms_problem().setup()
    planner = _planner(ss)
    ss.setup()
    with pytest.raises(ValueError, match="time limit"):
        planner.solve(float("nan"))


def test_the_gamma_estimate_runs_within_the_solves_time():
    ss = rooms_problem().setup()
    planner = _planner(ss, seed="3")
    assert ss.solve(0.0) == ob.PlannerStatus.TIMEOUT  # at once: not even the estimate
    assert planner.stats.iterations == 0 and planner._gamma_in_use() is None
    calls = []
    stop_soon = ob.PlannerTerminationCondition(lambda: calls.append(1) or len(calls) > 5)
    assert planner.solve(stop_soon) == ob.PlannerStatus.TIMEOUT  # stopped inside the estimate
    assert planner.stats.iterations == 0 and len(calls) == 7  # 5 x 100 samples, then the loop's check
    partial = planner._gamma_in_use()  # from the 500 samples drawn, kept for the next solve
    planner.setMaxIterations(10)
    planner.solve(30.0)
    assert planner.stats.iterations == 10 and planner.stats.ball_radius_constant == partial
    free = rooms_problem().grid.free_area
    assert partial == pytest.approx(ball_radius_constant(2, free), rel=0.15)


@pytest.mark.parametrize("values", [(float("nan"), 5.0), (math.inf, 5.0)])
def test_non_finite_start_is_invalid_start(values):
    ss = rooms_problem().setup()
    start = ss.getStateSpace().allocState()
    start[0], start[1] = values
    ss.setStartState(start)
    ss.setPlanner(BallRadiusRRTstar(ss.getSpaceInformation()))
    assert ss.solve(1.0) == ob.PlannerStatus.INVALID_START
