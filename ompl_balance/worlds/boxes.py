"""Built-in planning problems: 2-D worlds of axis-aligned boxes in the unit square.

Each :class:`Problem` builds a fresh ``og.SimpleSetup`` whose state validity checker
counts the states it checks (:class:`~ompl_balance.core.counting.CountingValidityChecker`),
so stock OMPL planners and this package's planners are measured alike.

=============  ===============================================================
``open``       no obstacles; start and goal in opposite corners
``narrow_gap`` a wall across the square with one gap 0.02 wide
``bug_trap``   the start inside a box left only through a channel 0.02 wide facing away
``maze``       four staggered walls to weave through
=============  ===============================================================
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..core.checks import kernels_in
from ..core.counting import CountingValidityChecker

Box = tuple[float, float, float, float]  # x_min, y_min, x_max, y_max


@kernels_in("ompl_balance.worlds.box_kernels")
class BoxKernel(NamedTuple):
    """A box world's compiled view (:mod:`ompl_balance.core.checks`): ``boxes`` (n, 4) rows of
    ``x_min, y_min, x_max, y_max``; the checks count in ``counts``."""

    boxes: np.ndarray
    counts: np.ndarray


class BoxWorld2D:
    """Validity in the unit square with axis-aligned box obstacles (closed boxes)."""

    def __init__(self, boxes: Sequence[Box]) -> None:
        for box in boxes:
            if len(box) != 4 or box[0] > box[2] or box[1] > box[3]:
                raise ValueError(f"a box is (x_min, y_min, x_max, y_max) with min <= max, got {box!r}")
        self.boxes = tuple(tuple(float(v) for v in box) for box in boxes)

    def compiled_view(self, counts: np.ndarray) -> BoxKernel:
        """The view compiled code checks states with, counting in ``counts`` (a checker's counter)."""
        return BoxKernel(np.array(self.boxes, dtype=float).reshape(-1, 4), counts)

    def is_free(self, x: float, y: float) -> bool:
        """``True`` when the point ``(x, y)`` lies in no box (``False`` for NaN or infinite)."""
        if not (math.isfinite(x) and math.isfinite(y)):
            return False
        return all(not (x_min <= x <= x_max and y_min <= y <= y_max) for x_min, y_min, x_max, y_max in self.boxes)

    def __call__(self, state: ob.State) -> bool:
        return self.is_free(state[0], state[1])


@dataclass(frozen=True)
class Problem:
    """A named start/goal query in a 2-D box world."""

    name: str
    description: str
    boxes: tuple[Box, ...]
    start: tuple[float, float]
    goal: tuple[float, float]
    resolution: float = field(default=0.005)  # validity-checking resolution, fraction of the extent

    def world(self) -> BoxWorld2D:
        return BoxWorld2D(self.boxes)

    def setup(self) -> og.SimpleSetup:
        """A fresh ``SimpleSetup`` for this problem, with a counting validity checker."""
        space = ob.RealVectorStateSpace(2)
        space.setBounds(0.0, 1.0)
        ss = og.SimpleSetup(space)
        si = ss.getSpaceInformation()
        si.setStateValidityChecker(CountingValidityChecker(si, self.world()))
        si.setStateValidityCheckingResolution(self.resolution)
        start, goal = space.allocState(), space.allocState()
        start[0], start[1] = self.start
        goal[0], goal[1] = self.goal
        ss.setStartAndGoalStates(start, goal)
        return ss


def _wall_with_gap(x: float, gap_low: float, gap_high: float, thickness: float = 0.04) -> tuple[Box, Box]:
    half = thickness / 2
    return (x - half, 0.0, x + half, gap_low), (x - half, gap_high, x + half, 1.0)


PROBLEMS: dict[str, Problem] = {
    problem.name: problem
    for problem in (
        Problem("open", "no obstacles", (), (0.05, 0.05), (0.95, 0.95)),
        Problem(
            "narrow_gap",
            "a wall with one gap 0.02 wide",
            _wall_with_gap(0.5, 0.49, 0.51),
            (0.1, 0.5),
            (0.9, 0.5),
        ),
        Problem(
            "bug_trap",
            "start inside a box whose only way out is a channel 0.02 wide, entered from inside",
            (
                (0.30, 0.30, 0.70, 0.33),  # bottom
                (0.30, 0.67, 0.70, 0.70),  # top
                (0.67, 0.33, 0.70, 0.67),  # right side, between the start and the goal
                (0.30, 0.33, 0.45, 0.59),  # left side, thickened into a channel at y = 0.6
                (0.30, 0.61, 0.45, 0.67),
            ),
            (0.6, 0.4),
            (0.95, 0.5),
        ),
        Problem(
            "maze",
            "four staggered walls",
            (
                (0.18, 0.0, 0.22, 0.8),
                (0.38, 0.2, 0.42, 1.0),
                (0.58, 0.0, 0.62, 0.8),
                (0.78, 0.2, 0.82, 1.0),
            ),
            (0.05, 0.05),
            (0.95, 0.95),
        ),
    )
}


#: Not in :data:`PROBLEMS` (``compare`` runs those): start and goal each in a pocket that opens
#: away from the other, so every way out of a pocket leaves the ball around the other root
#: whose radius is the start-goal distance (0.3). A goal-ball sampler without uniform
#: samples never solves it.
TWIN_POCKETS = Problem(
    "twin_pockets",
    "start and goal in pockets opening away from each other",
    (
        (0.22, 0.60, 0.45, 0.62),
        (0.22, 0.38, 0.45, 0.40),
        (0.43, 0.38, 0.45, 0.62),
        (0.55, 0.60, 0.78, 0.62),
        (0.55, 0.38, 0.78, 0.40),
        (0.55, 0.38, 0.57, 0.62),
    ),
    (0.35, 0.5),
    (0.65, 0.5),
)


def circle_setup() -> og.SimpleSetup:
    """A one-dimensional problem: SO(2), an obstacle between 0.5 and 1.0 rad, start 0 and goal
    1.5 rad, so the only way round leads away from the goal; a counting validity checker."""
    space = ob.SO2StateSpace()
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    si.setStateValidityChecker(CountingValidityChecker(si, lambda state: not 0.5 <= state.value <= 1.0))
    start, goal = space.allocState(), space.allocState()
    start.value, goal.value = 0.0, 1.5
    ss.setStartAndGoalStates(start, goal)
    return ss


def get_problem(name: str) -> Problem:
    """The built-in problem ``name``; ``KeyError`` naming the known ones otherwise."""
    if name not in PROBLEMS:
        raise KeyError(f"unknown problem {name!r}; built-in problems: {', '.join(PROBLEMS)}")
    return PROBLEMS[name]
