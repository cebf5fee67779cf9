"""Independent re-check of solution paths, shared by the planner tests.

A path is checked with the *raw* validity function of the problem (not through the
space information, so a wrapper bug cannot hide a collision) at the states OMPL's
discrete motion validator looks at: for each segment ``(a, b)``, the states
``interpolate(a, b, j / n)`` for ``j = 0..n`` with ``n = space.validSegmentCount(a, b)``.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

from ompl import base as ob
from ompl import geometric as og


def invalid_points(
    si: ob.SpaceInformation, path: og.PathGeometric, is_valid: Callable[[ob.State], bool]
) -> list[tuple[int, int]]:
    """(segment, step) of every state along ``path`` that ``is_valid`` rejects."""
    space = si.getStateSpace()
    scratch = si.allocState()
    bad = []
    states = [path.getState(i) for i in range(path.getStateCount())]
    for segment, (a, b) in enumerate(itertools.pairwise(states)):
        steps = max(1, space.validSegmentCount(a, b))  # a segment of length 0 counts 0 segments
        for step in range(steps + 1):
            space.interpolate(a, b, step / steps, scratch)
            if not (si.satisfiesBounds(scratch) and is_valid(scratch)):
                bad.append((segment, step))
    if len(states) == 1 and not is_valid(states[0]):
        bad.append((0, 0))
    return bad


def assert_valid_solution(
    ss: og.SimpleSetup, is_valid: Callable[[ob.State], bool], starts, goal_test
) -> og.PathGeometric:
    """The solution path of ``ss`` is exact, valid under ``is_valid``, and joins a start to the goal.

    ``starts`` are OMPL states, one of which the path must begin at; ``goal_test(state)``
    says whether the path's last state satisfies the goal.
    """
    assert ss.haveExactSolutionPath(), "no exact solution"
    si = ss.getSpaceInformation()
    path = ss.getSolutionPath()
    assert path.getStateCount() >= 2
    first, last = path.getState(0), path.getState(path.getStateCount() - 1)
    assert any(si.distance(first, start) < 1e-9 for start in starts), "path does not begin at a start state"
    assert goal_test(last), "path does not end in the goal"
    bad = invalid_points(si, path, is_valid)
    assert not bad, f"invalid states along the path at (segment, step) {bad[:5]}"
    return path
