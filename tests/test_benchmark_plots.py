"""What the plots draw is what the runs measured: outcomes, times to a solution, progress of the
planners that improve a cost, and no stale picture left in the folder."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

from ompl_balance.bench.plots import fraction_solved, outcome, problem_figure, time_to_solution, tree_panels
from ompl_balance.core.planner import START_TAG


def run(planner, status, time, solved, samples=None, improves=False, error="", first=None):
    """A record as the runner writes it (``samples``: ``(time, best cost)`` pairs of its progress;
    ``first``: the first solution time of a planner that keeps improving its solution)."""
    record = {
        "problem": "p",
        "planner": planner,
        "status": status,
        "error": error,
        "improves_cost": improves,
        "properties": {"time REAL": time, "solved BOOLEAN": int(solved)},
    }
    if first is not None:
        record["properties"]["first solution time REAL"] = first
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
# RRT*: the solve runs to its 1 s limit; its first solution came at 0.103 s, which the progress
# samples (every 0.05 s) show only at 0.15 s
RRTSTAR = run(
    "RRTstar",
    "EXACT_SOLUTION",
    1.0,
    True,
    [("0.05", "inf"), ("0.1", "inf"), ("0.15", "3"), ("0.2", "2.5")],
    True,
    first=0.103,
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
    assert time_to_solution(RRTSTAR) == 0.103  # neither its 1 s limit nor the sample that showed it
    for failed in (TIMED_OUT, APPROXIMATE, KILLED, RRTSTAR_UNSOLVED):
        assert time_to_solution(failed) is None  # never drawn as a solve time
    # an improving planner that reports no best cost, so no first solution time: the end bounds it
    unwatched = run("PRMstar", "EXACT_SOLUTION", 1.0, True, improves=True)
    assert time_to_solution(unwatched) == 1.0


def test_fraction_solved_counts_failures_and_crashes_as_runs_without_a_solution():
    runs = [SOLVED_FAST, TIMED_OUT, KILLED, RRTSTAR]
    times = np.array([0.1, 0.103, 0.15, 0.2, 0.99, 7.5])
    # brute force: at each time, the runs whose solution came at or before it, over all four
    expected = [sum(t is not None and t <= at for t in (0.2, None, None, 0.103)) / 4 for at in times]
    assert list(fraction_solved(runs, times)) == expected
    assert fraction_solved(runs, times)[-1] == 0.5  # the killed run never counts, even past its kill time
    assert list(fraction_solved([KILLED], times)) == [0.0] * len(times)


#: Labels as long as users write them (a planner with its parameters).
LONG_LABELS = (
    "RRTConnect",
    "BalancedRRTConnect[balance_tree_sizes=0]",
    "BalancedRRTConnect[max_tree_size_ratio=0.5;range=0.1]",
    "RRTstar",
)


def _extents(texts, renderer):
    return [t.get_window_extent(renderer) for t in texts if t.get_visible() and t.get_text()]


def test_a_problems_figure_keeps_titles_and_tick_labels_inside_and_apart_with_long_labels():
    pytest.importorskip("matplotlib")
    records = []
    for index, label in enumerate(LONG_LABELS):  # times from 0.2 ms to 0.4 s, checks from 100 to 300000
        for run_index in range(5):
            record = run(label, "EXACT_SOLUTION", 2e-4 * 6.0**index * (1 + run_index), True)
            record["properties"]["validity checks INTEGER"] = int(100 * 7.0**index * (1 + run_index))
            records.append(record)
    figure = problem_figure(records, "p", list(LONG_LABELS), time_limit=1.0)
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    width = figure.bbox.width
    for axis in figure.axes:
        title = axis.title.get_window_extent(renderer)
        assert title.x0 >= 0 and title.x1 <= width, axis.get_title()  # not clipped at the figure's edge
        ticks = sorted(_extents(axis.get_xticklabels(), renderer), key=lambda box: box.x0)
        assert len(ticks) >= 3, axis.get_title()
        for left, right in pairwise(ticks):
            assert left.x1 < right.x0, axis.get_title()  # no label runs into the next
    labels = _extents(figure.axes[0].get_yticklabels(), renderer)
    assert len(labels) == len(LONG_LABELS) and min(box.x0 for box in labels) >= 0
    assert not any(_extents(axis.get_yticklabels(), renderer) for axis in figure.axes[1:])  # the labels once
    figure.clf()


def test_trees_are_drawn_once_when_balanced_and_alternating_growth_made_the_same():
    """The narrow gap is symmetric about its start and goal: the tree sizes stay alike, balancing
    never chooses another tree than alternation, and both grow the same trees."""
    ((title, trees),) = tree_panels("narrow_gap", 300)
    assert title == "balanced and alternating growth: the same trees"
    assert trees.iterations == 300 and len(trees.points) > 100
    balanced, alternating = tree_panels("bug_trap", 300)  # the start tree is trapped: balancing grows it
    assert (balanced[0], alternating[0]) == ("balanced growth", "alternating growth")
    assert not balanced[1].same_as(alternating[1])
    assert balanced[1].size(START_TAG) > alternating[1].size(START_TAG)
