"""Every planner a user can name runs through the benchmark runner: none is recorded as crashed
unless it also hangs outside the benchmark, and then its record says so.

The oracle for "hangs by itself" is a plain ``ss.solve(t)`` of the same problem and planner in
a subprocess of the test's own, without any of the runner's code (no warm-up, no progress
thread, no memory limit).
"""

from __future__ import annotations

import math
import subprocess
import sys

import pytest
from test_benchmark import deterministic

from ompl_balance.bench.compare import bench
from ompl_balance.bench.execution import FIRST_SOLUTION_TIME
from ompl_balance.bench.experiment import Experiment, PlannerSpec, package_planner_classes, stock_planner_classes
from ompl_balance.bench.isolation import run_isolated
from ompl_balance.bench.problems import ProblemSpec
from ompl_balance.bench.progress_sampler import BEST_COST_PROPERTIES, SAMPLE_PERIOD

TIME_LIMIT = 0.2  # s: planners that run to their limit stay brief

PLAIN_SOLVE = """\
import os, sys
from ompl import geometric as og, util as ou
from ompl_balance.worlds.boxes import PROBLEMS
ou.setLogLevel(ou.LogLevel.LOG_NONE)
ss = PROBLEMS[sys.argv[1]].setup()
planner = getattr(og, sys.argv[2])(ss.getSpaceInformation())
ss.setPlanner(planner)
ss.solve(float(sys.argv[3]))
print("returned", flush=True)
os._exit(0)  # some planners crash when destroyed (AORRTC)
"""


def hangs_in_a_plain_solve(problem: str, planner: str, time_limit: float, wait: float = 20.0) -> bool:
    """Whether ``ss.solve(time_limit)`` of stock ``planner`` on built-in ``problem`` has not returned after ``wait`` s."""
    try:
        done = subprocess.run(
            [sys.executable, "-c", PLAIN_SOLVE, problem, planner, str(time_limit)],
            capture_output=True,
            text=True,
            timeout=wait,
            check=False,
        )
    except subprocess.TimeoutExpired:
        return True
    assert "returned" in done.stdout, done.stderr
    return False


@pytest.fixture(scope="module")
def every_planner(tmp_path_factory):
    """One run of every stock geometric planner and every package planner on the open square
    (where OMPL 2.0.1's SORRTstar does not return) and on the narrow gap."""
    names = [*sorted(stock_planner_classes()), *package_planner_classes()]
    experiment = Experiment(
        name="every_planner",
        problems=(ProblemSpec("open", "builtin", "open"), ProblemSpec("narrow_gap", "builtin", "narrow_gap")),
        planners=tuple(PlannerSpec(name, name) for name in names),
        runs=1,
        time_limit=TIME_LIMIT,
        seed=1,
        hard_limit_margin=1.0,
    )
    return experiment, bench(experiment, tmp_path_factory.mktemp("every_planner"), jobs=2, progress=False)


def test_no_planner_is_recorded_crashed_unless_it_hangs_by_itself(every_planner):
    experiment, records = every_planner
    assert len(records) == len(experiment.tasks())
    stock = stock_planner_classes()
    for record in records:
        if record["status"] != "CRASH":
            assert not record["error"], record
            continue
        assert record["planner"] in stock, record  # the package's planners never hang
        assert hangs_in_a_plain_solve(record["problem"], record["planner"], TIME_LIMIT), record
        assert f"{record['planner']} did not return from" in record["error"]
        assert "does not return either: the planner hangs by itself" in record["error"]
    solved = {(r["problem"], r["planner"]) for r in records if r["properties"]["solved BOOLEAN"]}
    # the planners with a thread of their own that the harness used to hang now solve
    assert {("narrow_gap", "PRM"), ("narrow_gap", "PRMstar"), ("open", "PRM"), ("open", "PRMstar")} <= solved


def test_planners_that_keep_improving_record_when_they_first_had_a_solution(every_planner):
    """Their solve ends at the time limit; the first solution time is read once an iteration, so
    it comes before the first progress sample (every 0.05 s) that shows a solution's cost."""
    _, records = every_planner
    improving = [r for r in records if r["improves_cost"] and r["properties"]["solved BOOLEAN"]]
    assert {"RRTstar", "BITstar", "AORRTC", "BallRadiusRRTstar"} <= {r["planner"] for r in improving}
    for record in improving:
        first = record["properties"][FIRST_SOLUTION_TIME]
        names, samples = record["progress"]["properties"], record["progress"]["samples"]
        cost = next(names.index(name) for name in BEST_COST_PROPERTIES if name in names)
        sampled = [float(s[names.index("time REAL")]) for s in samples if s[cost] and math.isfinite(float(s[cost]))]
        assert 0 < first <= min(sampled, default=record["properties"]["time REAL"]), record["planner"]
    open_rrtstar = next(r for r in improving if (r["problem"], r["planner"]) == ("open", "RRTstar"))
    assert open_rrtstar["properties"][FIRST_SOLUTION_TIME] < SAMPLE_PERIOD  # a few iterations in open space
    assert not any(FIRST_SOLUTION_TIME in r["properties"] for r in records if not r["improves_cost"])


#: Single-threaded stock planners that end at their first solution (well within 10 s on the narrow gap).
FIRST_SOLUTION_PLANNERS = ("RRTConnect", "RRT", "KPIECE1", "BKPIECE1", "LBKPIECE1", "BFMT")


def test_stock_planner_runs_re_executed_alone_repeat_after_the_warm_up(tmp_path):
    """The warm-up ends at its first solution or at a time, whichever comes first: the timed
    solve's random numbers must not depend on which (nor on how many the warm-up drew)."""
    experiment = Experiment(
        name="repeat",
        problems=(ProblemSpec("narrow_gap", "builtin", "narrow_gap"),),
        planners=tuple(PlannerSpec(name, name) for name in FIRST_SOLUTION_PLANNERS),
        runs=1,
        time_limit=10.0,
        seed=3,
    )
    records = bench(experiment, tmp_path, jobs=2, progress=False)
    assert all(r["status"] == "EXACT_SOLUTION" for r in records)
    by_key = {(r["problem"], r["planner"], r["run"]): r for r in records}
    for task in experiment.tasks():
        assert deterministic(run_isolated(task)) == deterministic(by_key[task.key]), task.planner.label


@pytest.mark.parametrize(
    ("tries", "verdict"),
    [
        ([0.21, "does not return"], "does not return either: the planner hangs by itself"),
        (["ends its process (killed by SIGSEGV)"], "ends its process (killed by SIGSEGV) either: the planner fails"),
        ([0.21, 0.3, 0.25], "returns in 0.30 s (each of 3 tries), so the benchmark kept it from returning"),
    ],
)
def test_a_run_that_did_not_return_is_put_down_to_the_benchmark_only_if_every_plain_solve_returns(
    monkeypatch, tries, verdict
):
    # a planner that hangs in some solves of a seed and returns in others (OMPL 2.0.1's SORRTstar
    # on the open square) hangs by itself: one plain solve that returned must not blame the benchmark
    from ompl_balance.bench import isolation

    task = Experiment(
        name="hangs_sometimes",
        problems=(ProblemSpec("open", "builtin", "open"),),
        planners=(PlannerSpec("SORRTstar", "SORRTstar"),),
        runs=1,
        time_limit=TIME_LIMIT,
        seed=1,
    ).tasks()[0]
    outcomes = iter(tries)
    monkeypatch.setattr(isolation, "plain_solve_once", lambda _task: next(outcomes))
    monkeypatch.setattr(isolation, "_PLAIN_SOLVES", {})
    error = isolation._not_returned(task, "solve", 0.0, task.hard_limit)
    assert error.startswith("SORRTstar did not return from the timed solve") and verdict in error
    assert next(outcomes, None) is None  # tried until one did not return, or all of them
    assert isolation.plain_solve(task) in error  # once per cell: not tried again
