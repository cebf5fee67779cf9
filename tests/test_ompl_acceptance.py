"""OMPL's planner acceptance test (``tests/geometric/2d/2denvs.cpp``) for every planner.

Each planner the package exports (found at import time, see
``acceptance.package_planners``) and, as the control, stock ``og.RRTConnect`` run
through the same harness: the simple test, the termination test, the 2-D map test and
the 2-D circles test at OMPL's thresholds, with OMPL's counts (100 map runs, the 100
circles queries; about half a minute for a dozen planners). The timed tests print
OMPL's figures and stock's from the same run in their assertion messages, with the
load average: the time bound is absolute, as in OMPL (set ``MACHINE_SPEED_FACTOR``,
default 3, as OMPL's CMake option, 5 in OMPL's CI), and a loaded machine shows in
stock's figure as well as ours.
"""

from __future__ import annotations

import math
import os

import pytest
from acceptance import (
    MAP_RUNS,
    STOCK,
    package_planners,
    run_2d_circles_test,
    run_2d_map_test,
    simple_test,
    termination_test,
)
from ompl import util as ou

from ompl_balance.worlds.ompl_2d import RESOURCES, load_circles, load_environment, load_queries

ou.setLogLevel(ou.LOG_ERROR)  # as TestPlanner's constructor

pytestmark = pytest.mark.skipif(
    not (RESOURCES / "env1.txt").is_file(),
    reason=f"OMPL's test resources are absent: expected env1.txt and circle_*.txt in {RESOURCES}",
)

PLANNERS = [STOCK, *package_planners()]


@pytest.fixture(scope="module")
def env():
    return load_environment(RESOURCES / "env1.txt")


@pytest.fixture(scope="module")
def circles():
    return load_circles(RESOURCES / "circle_obstacles.txt"), load_queries(RESOURCES / "circle_queries.txt")


def measure(env, circles, queries, map_runs: int):
    """Every planner's :class:`Outcome` of both timed tests by (test, label), and the load.

    Planners are interleaved run by run, so a loaded phase of the machine hits all alike.
    """
    load_before = os.getloadavg()[0]
    measured = run_2d_map_test(PLANNERS, env, map_runs) + run_2d_circles_test(PLANNERS, circles, queries)
    load = f"load average {load_before:.2f} before, {os.getloadavg()[0]:.2f} after measuring"
    return {(outcome.test, outcome.planner): outcome for outcome in measured}, load


@pytest.fixture(scope="module")
def outcomes(env, circles):
    """OMPL's counts: 100 map runs and all 100 circles queries."""
    obstacles, queries = circles
    return measure(env, obstacles, queries, MAP_RUNS)


def assert_accepted(outcomes, test: str, entry) -> None:
    """OMPL's three checks (success, average time, average length); no path fails the re-check."""
    measured, load = outcomes
    outcome, stock = measured[test, entry.label], measured[test, STOCK.label]
    report = f"{outcome.summary()}; stock in the same run: {stock.summary()}; {load}"
    assert outcome.faulty_paths == [], f"paths that fail the independent re-check: {outcome.faulty_paths[:5]}"
    unmet = outcome.unmet(timed=entry.time_asserted)
    assert unmet == [], f"{unmet}: {report}"


@pytest.mark.parametrize("entry", PLANNERS, ids=lambda entry: entry.label)
def test_simple(entry, env):
    assert simple_test(entry, env) == []


@pytest.mark.parametrize("entry", PLANNERS, ids=lambda entry: entry.label)
def test_termination(entry, env):
    """Nothing but the query states is valid: ``solve(0.1)`` returns promptly, unsolved."""
    elapsed, solved = termination_test(entry, env, limit=0.1)
    assert not solved
    assert elapsed < 0.5, f"solve(0.1) took {elapsed:.3f} s of CPU time with nothing valid to sample"


@pytest.mark.parametrize("test", ["2D map", "2D circles"])
@pytest.mark.parametrize("entry", PLANNERS, ids=lambda entry: entry.label)
def test_timed(entry, test, outcomes):
    assert_accepted(outcomes, test, entry)


def test_circle_buckets_answer_as_every_circle(circles):
    # the bucketed check is the test's validity checker: it must equal Circles2D::noOverlap
    import random

    obstacles, _ = circles
    rng = random.Random(4)
    points = [
        (rng.uniform(obstacles.min_x, obstacles.max_x), rng.uniform(obstacles.min_y, obstacles.max_y))
        for _ in range(20000)
    ]
    for x, y, r in obstacles.circles:  # on, just inside and just outside every circle
        for k in range(16):
            angle = 2 * 3.141592653589793 * k / 16
            for scale in (1 - 1e-9, 1.0, 1 + 1e-9):
                points.append((x + scale * r * math.cos(angle), y + scale * r * math.sin(angle)))
    answers = [obstacles.no_overlap(x, y) for x, y in points]
    assert answers == [obstacles.no_overlap_all(x, y) for x, y in points]
    assert 0.1 < 1 - sum(answers) / len(answers) < 0.9  # both answers are exercised
