"""OMPL's 2-D test environments, ported from its test suite.

Python versions of ``tests/resources/environment2D.h`` (occupancy grid),
``tests/resources/circles2D.h`` (circular obstacles and queries),
``tests/geometric/2d/2DmapSetup.h`` and ``tests/geometric/2d/2DcirclesSetup.h``
(the space information OMPL's ``2denvs.cpp`` plans in), reading the resource files
the package ships (``ompl_balance/data/ompl_2d/``, byte copies of OMPL's), by name::

    env = load_environment("env1")                  # or a path to a file of the same format
    circles = load_circles("circle_obstacles")
    queries = load_queries("circle_queries")

Validity rules are OMPL's: a map state is valid when the grid cell it falls in
(coordinates rounded towards zero) exists and is free (0); a circles state is valid
when it lies strictly outside every circle (``dx^2 + dy^2 >= r^2``). Checkers are plain
loops over Python floats: OMPL's thresholds were set for C++ checkers, and they are
called hundreds of thousands of times per test.

One deliberate simplification: ``2DmapSetup.h`` plans in ``StateSpace2DMap``, a
``RealVectorStateSpace`` whose ``distance`` override is the same Euclidean distance; a
Python override would only add a Python call per distance, so the plain space is used.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from ompl import base as ob

from ..core.counting import CountingValidityChecker

#: Where the resource files live: shipped with the package.
RESOURCES = Path(str(resources.files("ompl_balance") / "data" / "ompl_2d"))
#: The shipped resources by name.
RESOURCE_NAMES = ("env1", "env2", "circle_obstacles", "circle_queries")


def resource_path(name: str | Path) -> Path:
    """The file of a shipped resource (``"env1"`` or ``"env1.txt"``), or ``name`` itself as a path."""
    stem = str(name).removesuffix(".txt")
    if stem in RESOURCE_NAMES and not Path(name).is_file():
        return RESOURCES / f"{stem}.txt"
    path = Path(name)
    if not path.is_file():
        raise ValueError(f"{str(name)!r} is neither a shipped resource ({', '.join(RESOURCE_NAMES)}) nor a file")
    return path


T_FREE = 0  # the free grid cell value of environment2D.h

#: ``2DmapSetup.h``: the map bounds stop just under ``width`` and ``height``.
MAP_BOUND_MARGIN = 1e-9
#: Validity-checking resolutions (fractions of the space's maximum extent).
MAP_RESOLUTION = 0.016
CIRCLES_RESOLUTION = 0.002


# -- the occupancy grid (environment2D.h, 2DmapSetup.h) --------------------------------


@dataclass(frozen=True)
class Environment2D:
    """An occupancy grid with a start and a goal cell.

    ``grid[x][y]`` is the cell at column ``x`` (``0 <= x < width``) and row ``y``;
    ``0`` is free. The file's ``environment:`` block lists ``grid[0]`` first (one line
    per ``x``), as ``loadEnvironment`` reads it.
    """

    width: int
    height: int
    start: tuple[int, int]
    goal: tuple[int, int]
    grid: tuple[tuple[int, ...], ...]

    def is_free(self, x: float, y: float) -> bool:
        """``StateValidityChecker2DMap::isValid`` for the point ``(x, y)``."""
        column, row = int(x), int(y)  # truncation towards zero, as static_cast
        if column < 0 or row < 0 or column >= self.width or row >= self.height:
            return False
        return self.grid[column][row] == T_FREE

    def __call__(self, state: ob.State) -> bool:
        return self.is_free(state[0], state[1])


def load_environment(path: str | Path) -> Environment2D:
    """Read an ``env*.txt`` occupancy grid (``loadEnvironment`` of environment2D.h), shipped or a file.

    The file is a stream of ``discretization(cells): W H``, ``start(cells): X Y``,
    ``end(cells): X Y`` and ``environment:`` followed by ``W x H`` cell values.
    """
    path = resource_path(path)
    tokens = iter(path.read_text().split())
    width = height = 0
    start = goal = (0, 0)
    cells: list[int] = []
    try:
        for name in tokens:
            if name == "discretization(cells):":
                width, height = int(next(tokens)), int(next(tokens))
            elif name == "start(cells):":
                start = (int(next(tokens)), int(next(tokens)))
            elif name == "end(cells):":
                goal = (int(next(tokens)), int(next(tokens)))
            elif name == "environment:":
                cells = [int(next(tokens)) for _ in range(width * height)]
    except (StopIteration, ValueError) as error:
        raise ValueError(f"{path}: malformed environment file ({error or 'ended early'})") from error
    if width * height == 0 or len(cells) != width * height:
        raise ValueError(
            f"{path}: the environment has a 0 dimension or no 'environment:' block of {width} x {height} cells"
        )
    grid = tuple(tuple(cells[x * height : (x + 1) * height]) for x in range(width))
    return Environment2D(width, height, start, goal, grid)


def map_space_information(env: Environment2D) -> ob.SpaceInformation:
    """``spaceInformation2DMap``: ``[0, width) x [0, height)``, resolution 0.016, grid checker."""
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0.0)
    bounds.setHigh(0, env.width - MAP_BOUND_MARGIN)  # (``bounds.high[i] = v`` is lost: a copy)
    bounds.setHigh(1, env.height - MAP_BOUND_MARGIN)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityCheckingResolution(MAP_RESOLUTION)
    si.setStateValidityChecker(CountingValidityChecker(si, env))
    si.setup()
    return si


# -- circular obstacles (circles2D.h, 2DcirclesSetup.h) ---------------------------------


@dataclass(frozen=True)
class CircleQuery:
    start: tuple[float, float]
    goal: tuple[float, float]


class Circles2D:
    """Circular obstacles ``(x, y, r)`` and their bounding box.

    ``no_overlap`` answers as ``Circles2D::noOverlap`` (every circle tested), but tests
    only the circles whose bounding square meets the point's cell of a
    :data:`BUCKETS` x :data:`BUCKETS` grid over the bounding box: the same answers for
    a fraction of the time of a loop over all 70 circles in Python.
    """

    BUCKETS = 16

    def __init__(self, circles: list[tuple[float, float, float]]) -> None:
        if not circles:
            raise ValueError("Circles2D needs at least one circle (x, y, r)")
        self.circles = tuple(circles)
        self.min_x = min(x - r for x, _, r in circles)
        self.max_x = max(x + r for x, _, r in circles)
        self.min_y = min(y - r for _, y, r in circles)
        self.max_y = max(y + r for _, y, r in circles)
        self._cell_x = (self.max_x - self.min_x) / self.BUCKETS
        self._cell_y = (self.max_y - self.min_y) / self.BUCKETS
        # per cell (row-major, x fastest): (x, y, r^2) of the circles whose square meets it
        self._buckets: list[list[tuple[float, float, float]]] = [[] for _ in range(self.BUCKETS**2)]
        for x, y, r in circles:
            for i in range(self._column(x - r), self._column(x + r) + 1):
                for j in range(self._row(y - r), self._row(y + r) + 1):
                    self._buckets[j * self.BUCKETS + i].append((x, y, r * r))

    def _column(self, x: float) -> int:
        return min(max(int((x - self.min_x) / self._cell_x), 0), self.BUCKETS - 1)

    def _row(self, y: float) -> int:
        return min(max(int((y - self.min_y) / self._cell_y), 0), self.BUCKETS - 1)

    def no_overlap_all(self, x: float, y: float) -> bool:
        """``Circles2D::noOverlap`` as written: ``(x, y)`` lies in no circle (boundary counts as free)."""
        return all((cx - x) ** 2 + (cy - y) ** 2 >= r * r for cx, cy, r in self.circles)

    def no_overlap(self, x: float, y: float) -> bool:
        """:meth:`no_overlap_all`, testing only the circles of ``(x, y)``'s cell."""
        if not (self.min_x <= x <= self.max_x and self.min_y <= y <= self.max_y):
            return True  # outside the bounding box of all circles
        column = int((x - self.min_x) / self._cell_x)  # (_column and _row, inlined: the hot path)
        row = int((y - self.min_y) / self._cell_y)
        last = self.BUCKETS - 1
        for cx, cy, r2 in self._buckets[
            (row if row < last else last) * self.BUCKETS + (column if column < last else last)
        ]:
            dx = cx - x
            dy = cy - y
            if dx * dx + dy * dy < r2:
                return False
        return True

    def __call__(self, state: ob.State) -> bool:
        return self.no_overlap(state[0], state[1])


def load_circles(path: str | Path) -> Circles2D:
    """Read ``circle_obstacles.txt`` (shipped, or a file): two header lines, then ``id x y r`` per circle.

    As ``Circles2D::loadCircles``, reading stops at the first record that does not parse.
    """
    path = resource_path(path)
    circles = []
    for line in path.read_text().splitlines()[2:]:
        fields = line.split()
        try:
            _, x, y, r = int(fields[0]), float(fields[1]), float(fields[2]), float(fields[3])
        except (IndexError, ValueError):
            break
        circles.append((x, y, r))
    if not circles:
        raise ValueError(f"{path}: no circles ('id x y r' after two header lines)")
    return Circles2D(circles)


def load_queries(path: str | Path) -> list[CircleQuery]:
    """Read ``circle_queries.txt`` (shipped, or a file): per query ``N start: x y`` then ``N goal: x y``."""
    path = resource_path(path)
    tokens = path.read_text().split()
    if len(tokens) % 8:
        raise ValueError(f"{path}: expected records 'N start: x y N goal: x y', got {len(tokens)} tokens")
    try:
        return [
            CircleQuery((float(tokens[i + 2]), float(tokens[i + 3])), (float(tokens[i + 6]), float(tokens[i + 7])))
            for i in range(0, len(tokens), 8)
        ]
    except ValueError as error:
        raise ValueError(f"{path}: malformed query ({error})") from error


def circles_space_information(circles: Circles2D) -> ob.SpaceInformation:
    """``spaceInformation2DCircles``: the circles' bounding box, resolution 0.002, circle checker."""
    space = ob.RealVectorStateSpace()
    space.addDimension(circles.min_x, circles.max_x)
    space.addDimension(circles.min_y, circles.max_y)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(CountingValidityChecker(si, circles))
    si.setStateValidityCheckingResolution(CIRCLES_RESOLUTION)
    si.setup()
    return si
