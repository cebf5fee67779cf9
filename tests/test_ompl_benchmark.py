"""OMPL's own ompl.tools.Benchmark with the package's planners: run through run_ompl_benchmark, its
log holds their parameters and graph sizes (read back with OMPL's own log converter)."""

from __future__ import annotations

import sqlite3

from ompl import geometric as og
from ompl import tools as ot

from ompl_balance import BalancedRRTConnect, BallRadiusRRTstar
from ompl_balance.bench.ompl_benchmark import run_ompl_benchmark
from ompl_balance.worlds.boxes import get_problem

RUNS = 3


def test_the_log_of_ompls_benchmark_holds_the_package_planners_parameters_and_graphs(tmp_path):
    ss = get_problem("narrow_gap").setup()
    si = ss.getSpaceInformation()
    benchmark = ot.Benchmark(ss, "filled")
    balanced = BalancedRRTConnect(si, name="ratio_0.5")
    balanced.setMaxTreeSizeRatio(0.5)
    default = BalancedRRTConnect(si, name="ratio_1")
    rrtstar = BallRadiusRRTstar(si)
    stock = og.RRTConnect(si)
    for planner in (balanced, default, rrtstar, stock):
        benchmark.addPlanner(planner)
    own_events = []
    graphs: dict[str, list[tuple[int, int]]] = {}

    def post_run(planner, run):
        own_events.append(planner.getName())
        if hasattr(planner, "stats"):  # the planner's own count of its two trees, or of its tree
            stats = planner.stats
            trees = (
                stats.start_tree_size + stats.goal_tree_size if hasattr(stats, "goal_tree_size") else stats.tree_size
            )
            graphs.setdefault(planner.getName(), []).append((trees, stats.iterations))

    request = ot.Request(0.5, 1000.0, RUNS, 0.05, True, False, True)  # no .console file in the cwd
    request.displayProgress = False
    run_ompl_benchmark(benchmark, request, post_run=post_run)
    log = tmp_path / "filled.log"
    benchmark.saveResultsToFile(str(log))
    database = tmp_path / "filled.db"
    ot.readBenchmarkLog(str(database), [str(log)], False)

    assert (
        own_events == ["ratio_0.5"] * RUNS + ["ratio_1"] * RUNS + ["BallRadiusRRTstar"] * RUNS + ["RRTConnect"] * RUNS
    )
    with sqlite3.connect(database) as db:
        settings = dict(db.execute("SELECT name, settings FROM plannerConfigs"))
        runs = db.execute(
            "SELECT plannerConfigs.name, graph_states, iterations FROM runs "
            "JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id ORDER BY runs.id"
        ).fetchall()
    assert "max_tree_size_ratio = 0.5" in settings["geometric_ratio_0.5"]
    assert "max_tree_size_ratio = 1" in settings["geometric_ratio_1"]  # the two configurations differ
    assert "ball_radius_constant" in settings["geometric_BallRadiusRRTstar"]
    for name in ("ratio_0.5", "ratio_1", "BallRadiusRRTstar"):
        logged = [(states, iterations) for planner, states, iterations in runs if planner == f"geometric_{name}"]
        assert logged == graphs[name]  # graph states: the trees' sizes the planner counted itself
        assert all(states > 0 for states, _ in logged)
    stock_runs = [states for planner, states, _ in runs if planner == "geometric_RRTConnect"]
    assert len(stock_runs) == RUNS and all(states > 0 for states in stock_runs)  # Benchmark's own reading


def test_two_configurations_under_one_name_are_logged_each_with_its_own_parameters_and_runs(tmp_path):
    """Two BalancedRRTConnect with the default name and different ratios: each log entry holds its
    own planner's parameters and, run by run, the graph sizes and iterations that planner counted
    (what Benchmark recorded is matched by position, not by name)."""
    ss = get_problem("bug_trap").setup()
    si = ss.getSpaceInformation()
    benchmark = ot.Benchmark(ss, "one_name")
    default, halved = BalancedRRTConnect(si), BalancedRRTConnect(si)
    halved.setMaxTreeSizeRatio(0.5)
    halved.setRange(0.05)  # a different search: the two planners' runs differ
    stock = og.RRTConnect(si)
    for planner in (default, stock, halved):
        benchmark.addPlanner(planner)
    counted: dict[int, list[tuple[int, int]]] = {id(default): [], id(halved): []}

    def post_run(planner, run):
        if id(planner) in counted:
            stats = planner.stats
            counted[id(planner)].append((stats.start_tree_size + stats.goal_tree_size, stats.iterations))

    request = ot.Request(0.5, 1000.0, RUNS, 0.05, True, False, True)
    request.displayProgress = False
    run_ompl_benchmark(benchmark, request, post_run=post_run)
    log = tmp_path / "one_name.log"
    benchmark.saveResultsToFile(str(log))
    database = tmp_path / "one_name.db"
    ot.readBenchmarkLog(str(database), [str(log)], False)

    with sqlite3.connect(database) as db:
        configs = db.execute("SELECT id, name, settings FROM plannerConfigs ORDER BY id").fetchall()
        runs = db.execute("SELECT plannerid, graph_states, iterations FROM runs ORDER BY id").fetchall()
    balanced = [
        (config_id, settings) for config_id, name, settings in configs if name == "geometric_BalancedRRTConnect"
    ]
    assert len(balanced) == 2, configs  # two configurations, not one merged entry
    (first_id, first_settings), (second_id, second_settings) = balanced
    assert "max_tree_size_ratio = 1" in first_settings and "range = 0" in first_settings
    assert "max_tree_size_ratio = 0.5" in second_settings and "range = 0.05" in second_settings
    for config_id, planner in ((first_id, default), (second_id, halved)):
        logged = [(states, iterations) for plannerid, states, iterations in runs if plannerid == config_id]
        assert logged == counted[id(planner)]
    assert counted[id(default)] != counted[id(halved)]
