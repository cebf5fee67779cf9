"""What the plots draw is what the runs measured: outcomes, times to a solution, progress of the
planners that improve a cost, and no stale picture left in the folder."""

from __future__ import annotations

import numpy as np

from ompl_balance.bench.plots import fraction_solved, outcome, time_to_solution


def run(planner, status, time, solved, samples=None, improves=False, error=""):
    """A record as the runner writes it (``samples``: ``(time, best cost)`` pairs of its progress)."""
    record = {
        "problem": "p",
        "planner": planner,
        "status": status,
        "error": error,
        "improves_cost": improves,
        "properties": {"time REAL": time, "solved BOOLEAN": int(solved)},
    }
    if samples is not None:
        record["progress"] = {
            "properties": ["best cost REAL", "time REAL"],
            "samples": [[cost, at] for at, cost in samples],
        }
    return record


SOLVED_FAST = run("RRTConnect", "EXACT_SOLUTION", 0.2, True)
TIMED_OUT = run("RRT", "TIMEOUT", 1.0, False)
APPROXIMATE = run("RRT", "APPROXIMATE_SOLUTION", 1.0, False)
KILLED = run("PRM", "CRASH", 7.0, False, error="PRM did not return from the timed solve ...")
# RRT*: the solve runs to its 1 s limit; the first solution shows in the third sample
RRTSTAR = run(
    "RRTstar", "EXACT_SOLUTION", 1.0, True, [("0.05", "inf"), ("0.1", "inf"), ("0.15", "3"), ("0.2", "2.5")], True
)
RRTSTAR_UNSOLVED = run("RRTstar", "TIMEOUT", 1.0, False, [("0.05", "inf"), ("0.1", "inf")], True)
# a planner of the RRT-Connect family reports a best cost too, but it stops at its first solution
BALANCED = run("BalancedRRTConnect", "EXACT_SOLUTION", 0.12, True, [("0.05", "inf"), ("0.1", "inf")], False)


def test_outcomes_are_solved_not_solved_or_crashed():
    assert [outcome(r) for r in (SOLVED_FAST, TIMED_OUT, APPROXIMATE, KILLED, RRTSTAR)] == [
        "solved",
        "not solved",
        "not solved",
        "crashed or killed",
        "solved",
    ]


def test_time_to_a_solution_is_none_without_one_and_the_first_solution_for_improving_planners():
    assert time_to_solution(SOLVED_FAST) == 0.2
    assert time_to_solution(BALANCED) == 0.12  # its end: it stops at its solution
    assert time_to_solution(RRTSTAR) == 0.15  # not its 1 s limit
    for failed in (TIMED_OUT, APPROXIMATE, KILLED, RRTSTAR_UNSOLVED):
        assert time_to_solution(failed) is None  # never drawn as a solve time
    # an improving planner solved after its last sample (or before its first): the end bounds it
    late = run("RRTstar", "EXACT_SOLUTION", 1.0, True, [("0.05", "inf")], True)
    assert time_to_solution(late) == 1.0


def test_fraction_solved_counts_failures_and_crashes_as_runs_without_a_solution():
    runs = [SOLVED_FAST, TIMED_OUT, KILLED, RRTSTAR]
    times = np.array([0.1, 0.15, 0.2, 0.99, 7.5])
    # brute force: at each time, the runs whose solution came at or before it, over all four
    expected = [sum(t is not None and t <= at for t in (0.2, None, None, 0.15)) / 4 for at in times]
    assert list(fraction_solved(runs, times)) == expected
    assert fraction_solved(runs, times)[-1] == 0.5  # the killed run never counts, even past its kill time
    assert list(fraction_solved([KILLED], times)) == [0.0] * len(times)
