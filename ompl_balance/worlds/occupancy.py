"""Occupancy-grid worlds: a map of rooms and corridors, its validity checker, its problems.

A grid is a boolean array ``occupied`` of shape ``(rows, cols)``; cell ``(row, col)``
covers ``x in [x0 + col * res, x0 + (col + 1) * res)`` and
``y in [y0 + row * res, y0 + (row + 1) * res)`` (row 0 at the bottom, as in a plot with
``origin="lower"``). Positions outside the grid are not free.

:func:`rooms_grid` is a 40 m x 40 m floor plan: six rooms off a corridor, doors placed
so that the way from the start (bottom-left room) to the goal (top-right room) winds
through the corridor, with more than one route. :func:`rooms_problem` poses it in
R^2 (``"rooms"``) or SE(2) (``"rooms_se2"``, a point robot with a free heading).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..core.checks import kernels_in
from ..core.counting import CountingValidityChecker


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """A 2-D occupancy grid: ``occupied`` ``(rows, cols)`` bool, square cells of side ``resolution`` (m)."""

    occupied: np.ndarray
    resolution: float
    origin: tuple[float, float] = (0.0, 0.0)
    _free_rows: list[list[bool]] = field(init=False, repr=False)  # list lookups: fastest per-state check

    def __post_init__(self) -> None:
        occupied = np.asarray(self.occupied)
        if occupied.ndim != 2 or occupied.dtype != bool or occupied.size == 0:
            raise ValueError(
                f"occupied must be a non-empty 2-D boolean array, got shape {occupied.shape} dtype {occupied.dtype}"
            )
        if not math.isfinite(self.resolution) or self.resolution <= 0:
            raise ValueError(f"resolution must be a positive cell side in metres, got {self.resolution!r}")
        object.__setattr__(self, "occupied", occupied)
        object.__setattr__(self, "_free_rows", (~occupied).tolist())

    @property
    def shape(self) -> tuple[int, int]:
        return self.occupied.shape

    @property
    def low(self) -> tuple[float, float]:
        """Lower-left corner ``(x, y)`` in metres."""
        return self.origin

    @property
    def high(self) -> tuple[float, float]:
        """Upper-right corner ``(x, y)`` in metres."""
        rows, cols = self.occupied.shape
        return self.origin[0] + cols * self.resolution, self.origin[1] + rows * self.resolution

    @property
    def area(self) -> float:
        """Area covered by the grid, m^2."""
        return self.occupied.size * self.resolution**2

    @property
    def free_area(self) -> float:
        """Area of the free cells, m^2 (exact)."""
        return float((~self.occupied).sum()) * self.resolution**2

    def is_free(self, x: float, y: float) -> bool:
        """``True`` when ``(x, y)`` (m) lies in a free cell of the grid (``False`` for NaN or infinite)."""
        if not (math.isfinite(x) and math.isfinite(y)):
            return False
        col = math.floor((x - self.origin[0]) / self.resolution)
        row = math.floor((y - self.origin[1]) / self.resolution)
        rows, cols = self.occupied.shape
        return 0 <= row < rows and 0 <= col < cols and self._free_rows[row][col]

    def free_mask(self, xy: np.ndarray) -> np.ndarray:
        """:meth:`is_free` for many positions: ``xy`` ``(n, 2)`` m -> ``(n,)`` bool."""
        xy = np.asarray(xy, dtype=float)
        cells = np.floor((xy - np.asarray(self.origin)) / self.resolution).astype(np.int64)
        rows, cols = self.occupied.shape
        inside = (cells[:, 0] >= 0) & (cells[:, 0] < cols) & (cells[:, 1] >= 0) & (cells[:, 1] < rows)
        free = np.zeros(len(xy), dtype=bool)
        free[inside] = ~self.occupied[cells[inside, 1], cells[inside, 0]]
        return free


@kernels_in("ompl_balance.worlds.grid_kernels")
class GridKernel(NamedTuple):
    """An occupancy grid's compiled view (:mod:`ompl_balance.core.checks`): ``free`` (rows, cols)
    bool, ``origin`` (2,) m, square cells of ``resolution`` m; the position is a state's first two
    values (a real-vector space's, or SE(2)'s x and y); the checks count in ``counts``."""

    free: np.ndarray
    origin: np.ndarray
    resolution: float
    counts: np.ndarray


class _GridCheck:
    """The validity of an OMPL state's position on a grid: a callable with a compiled view."""

    def __init__(self, grid: OccupancyGrid, position: Callable[[ob.State], tuple[float, float]]) -> None:
        self.grid = grid
        self.position = position

    def __call__(self, state: ob.State) -> bool:
        return self.grid.is_free(*self.position(state))

    def compiled_view(self, counts: np.ndarray) -> GridKernel:
        grid = self.grid
        return GridKernel(~grid.occupied, np.array(grid.origin, dtype=float), float(grid.resolution), counts)


class GridValidityChecker(CountingValidityChecker):
    """An OMPL validity checker from an :class:`OccupancyGrid`, counting the states it checks.

    The state's position is ``(s[0], s[1])`` in a real-vector space (further
    coordinates are ignored) or ``(s.getX(), s.getY())`` in SE(2). A state is valid
    when its position lies in a free cell. ``counters()`` follows
    :mod:`ompl_balance.core.counting`; the compiled engine checks states with its kernel.
    """

    def __init__(self, si: ob.SpaceInformation, grid: OccupancyGrid) -> None:
        space = si.getStateSpace()
        position: Callable[[ob.State], tuple[float, float]]
        if isinstance(space, ob.SE2StateSpace):
            position = lambda state: (state.getX(), state.getY())  # noqa: E731
        elif isinstance(space, ob.RealVectorStateSpace) and space.getDimension() >= 2:
            position = lambda state: (state[0], state[1])  # noqa: E731
        else:
            raise TypeError(
                f"a grid checker needs an SE2 or a real-vector space of dimension >= 2, got {type(space).__name__}"
            )
        super().__init__(si, _GridCheck(grid, position))
        self.grid = grid


def rooms_grid(side: float = 40.0, resolution: float = 0.2) -> OccupancyGrid:
    """The built-in floor plan: a square of ``side`` metres in cells of ``resolution`` metres.

    In units of ``side / 10``: a corridor runs across the middle (y in [4.5, 5.5]);
    three rooms lie below it and three above; walls are 0.2 thick and doors 0.8 wide.
    Rooms open onto the corridor through one door each, and neighbouring rooms in a row
    are joined by a door, so several routes connect any two rooms.
    """
    cells = round(side / resolution)
    if cells < 50:
        raise ValueError(
            f"the floor plan needs at least 50 cells a side, got side {side} m / resolution {resolution} m"
        )
    occupied = np.zeros((cells, cells), dtype=bool)
    unit = side / 10

    def fill(x0: float, y0: float, x1: float, y1: float, value: bool = True) -> None:
        def cell(u: float) -> int:
            return round(u * unit / resolution)

        occupied[cell(y0) : cell(y1), cell(x0) : cell(x1)] = value

    wall = 0.2
    for box in ((0, 0, 10, wall), (0, 10 - wall, 10, 10), (0, 0, wall, 10), (10 - wall, 0, 10, 10)):
        fill(*box)
    fill(0, 4.5 - wall, 10, 4.5)  # corridor walls
    fill(0, 5.5, 10, 5.5 + wall)
    for x in (10 / 3, 20 / 3):  # walls between rooms, below and above the corridor
        fill(x - wall / 2, 0, x + wall / 2, 4.5)
        fill(x - wall / 2, 5.5, x + wall / 2, 10)
    door = 0.8
    for x in (2.6, 4.2, 8.8):  # doors from the lower rooms into the corridor
        fill(x, 4.5 - wall, x + door, 4.5, False)
    for x in (1.0, 6.0, 7.2):  # doors from the upper rooms into the corridor
        fill(x, 5.5, x + door, 5.5 + wall, False)
    for x, y in ((10 / 3, 0.8), (20 / 3, 3.0), (10 / 3, 8.4), (20 / 3, 6.4)):  # doors between rooms
        fill(x - wall / 2, y, x + wall / 2, y + door, False)
    return OccupancyGrid(occupied, resolution)


@dataclass(frozen=True, eq=False)
class OccupancyProblem:
    """A start/goal query on an occupancy grid, in R^2 or SE(2).

    ``start``/``goal``: ``(x, y)`` in metres (SE(2): ``(x, y, heading)`` in radians).
    ``step``: validity-checking step along motions, metres (half a cell by default).
    """

    name: str
    grid: OccupancyGrid
    start: tuple[float, ...]
    goal: tuple[float, ...]
    se2: bool = False
    step: float | None = None

    def space(self) -> ob.StateSpace:
        """A fresh state space with the grid's bounds (SE(2) headings are free)."""
        space = ob.SE2StateSpace() if self.se2 else ob.RealVectorStateSpace(2)
        bounds = ob.RealVectorBounds(2)
        for axis in range(2):
            bounds.setLow(axis, self.grid.low[axis])
            bounds.setHigh(axis, self.grid.high[axis])
        space.setBounds(bounds)
        return space

    def setup(self) -> og.SimpleSetup:
        """A fresh ``SimpleSetup`` with a :class:`GridValidityChecker` and the start and goal set."""
        space = self.space()
        ss = og.SimpleSetup(space)
        si = ss.getSpaceInformation()
        si.setStateValidityChecker(GridValidityChecker(si, self.grid))
        step = self.step if self.step is not None else self.grid.resolution / 2
        si.setStateValidityCheckingResolution(step / space.getMaximumExtent())
        start, goal = space.allocState(), space.allocState()
        self.write_state(start, self.start)
        self.write_state(goal, self.goal)
        ss.setStartAndGoalStates(start, goal)
        return ss

    def write_state(self, state: ob.State, values: tuple[float, ...]) -> None:
        """Write ``(x, y)`` (or ``(x, y, heading)`` in SE(2)) into an OMPL state of this problem's space."""
        if self.se2:
            x, y, heading = values
            state.setX(x), state.setY(y), state.setYaw(heading)
        else:
            state[0], state[1] = values

    def is_valid(self, state: ob.State) -> bool:
        """The raw validity test (no counting), for independent path checks."""
        if self.se2:
            return self.grid.is_free(state.getX(), state.getY())
        return self.grid.is_free(state[0], state[1])


def rooms_problem(se2: bool = False) -> OccupancyProblem:
    """From the bottom-left room to the top-right room of :func:`rooms_grid` (R^2, or SE(2))."""
    grid = rooms_grid()
    (x0, y0), (x1, y1) = grid.low, grid.high
    start = (x0 + 0.08 * (x1 - x0), y0 + 0.08 * (y1 - y0))
    goal = (x1 - 0.08 * (x1 - x0), y1 - 0.08 * (y1 - y0))
    if se2:
        return OccupancyProblem("rooms_se2", grid, (*start, 0.0), (*goal, math.pi / 2), se2=True)
    return OccupancyProblem("rooms", grid, start, goal)


OCCUPANCY_PROBLEMS = {"rooms": lambda: rooms_problem(se2=False), "rooms_se2": lambda: rooms_problem(se2=True)}
