"""What every planner of the package shares: the solve wrapper around its search.

:class:`TreePlanner` is an ``ob.Planner`` written in Python. A subclass declares its
parameters (a :class:`~ompl_balance.core.params.Settings` dataclass, ``Settings``), its
statistics record (``Stats``) and its search (:meth:`TreePlanner._plan`); the base does
the rest the same way for all of them:

* ``params()`` and the camelCase accessors, from the settings table;
* ``setup()``: the counting checker (:func:`~ompl_balance.core.counting.ensure_counting`)
  and the compiled tree scans for real-vector spaces, so that no ``solve()`` pays for them;
* ``solve(ptc)``: the termination condition from what it was given (a condition, seconds
  or a callable), the seed of the solve (the ``seed`` parameter, or a draw from the planner's
  OMPL ``RNG``, which ``ompl.util.RNG.setSeed`` repeats), the work counted, and ``stats``;
* the solution path added to the problem definition, and the trees as ``ob.PlannerData``;
* progress properties (:meth:`TreePlanner.progressProperties`), readable while a solve runs.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from .counting import ensure_counting, read_work
from .params import ParamSet, Settings, add_accessors
from .spaces import Points, points_for, prepare
from .trees import NO_PARENT, Tree

#: OMPL's default range as a fraction of the space's maximum extent
#: (``magic::MAX_MOTION_LENGTH_AS_SPACE_EXTENT_FRACTION``).
RANGE_AS_EXTENT_FRACTION = 0.2

#: ``PlannerData`` vertex tags, as OMPL's RRT-Connect: 1 start tree, 2 goal tree.
START_TAG = 1
GOAL_TAG = 2

#: Anything ``solve`` takes: a condition (C++ callers), seconds, or a callable "stop now?".
Limit = ob.PlannerTerminationCondition | float | Callable[[], bool]


def termination_condition(limit: Limit) -> ob.PlannerTerminationCondition:
    """A ``PlannerTerminationCondition`` from what ``solve`` was given.

    C++ callers (``SimpleSetup``, ``Benchmark``) pass a condition; Python callers may
    pass a time limit in seconds (must be positive and finite) or a callable that
    returns ``True`` when planning should stop.
    """
    if isinstance(limit, ob.PlannerTerminationCondition):
        return limit
    if isinstance(limit, (int, float)) and not isinstance(limit, bool):
        if not math.isfinite(limit) or limit <= 0:
            raise ValueError(f"solve() time limit must be a positive number of seconds, got {limit!r}")
        return ob.timedPlannerTerminationCondition(float(limit))
    if callable(limit):
        return ob.PlannerTerminationCondition(limit)
    raise TypeError(
        f"solve() takes a PlannerTerminationCondition, a time limit in seconds or a callable, got {type(limit).__name__}"
    )


@dataclass
class Progress:
    """What a solve has done so far, updated as it runs (read by :meth:`TreePlanner.progressProperties`)."""

    iterations: int = 0
    best_cost: float = math.inf  # cost (path length) of the best solution so far


class TreePlanner(ob.Planner):
    """Base of the package's planners (see the module docstring).

    Subclasses set ``Settings`` (their parameter table, which must have ``seed``) and
    ``Stats`` (a dataclass with ``status``, ``states_checked``, ``motions_checked``,
    ``distance_queries`` and ``time`` fields besides those :meth:`_plan` returns), implement
    :meth:`_plan` (keeping :attr:`progress` current) and :meth:`_fill_planner_data`.
    """

    Settings: ClassVar[type[Settings]]
    Stats: ClassVar[type]

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "Settings" in cls.__dict__:
            add_accessors(cls, cls.Settings)

    def __init__(self, si: ob.SpaceInformation, name: str | None = None) -> None:
        super().__init__(si, name or type(self).__name__)
        self.settings: Any = type(self).Settings()
        self._params = ParamSet.of(self.settings)
        self._rng = ou.RNG()  # per-planner stream, seeded from OMPL's global seed
        self._points: Points | None = None  # how the last solve saw the space
        self.progress = Progress()
        self.stats: Any = None

    def params(self) -> ParamSet:
        """This planner's parameters (OMPL's ``ParamSet`` semantics)."""
        return self._params

    def setup(self) -> None:
        super().setup()
        si = self.getSpaceInformation()
        ensure_counting(si)
        prepare(si)

    def clear(self) -> None:
        super().clear()
        self.stats = None

    def solve(self, ptc: Limit) -> ob.PlannerStatus:
        """Plan until the search ends or ``ptc`` says stop (a condition, seconds or a callable)."""
        ptc = termination_condition(ptc)
        self.checkValidity()
        self._before_solve()
        si = self.getSpaceInformation()
        began = time.perf_counter()
        work_before = read_work(si)
        rng = np.random.default_rng(self.settings.seed or self._draw_seed())
        self._points = points_for(si, rng)
        self.progress = Progress()
        status, fields = self._plan(ptc, self._points, rng)
        work = read_work(si) - work_before
        self.stats = self.Stats(
            status=ob.PlannerStatus(status).asString(),
            states_checked=work.states_checked,
            motions_checked=work.motions_checked,
            distance_queries=work.distance_queries,
            time=time.perf_counter() - began,
            **fields,
        )
        return ob.PlannerStatus(status)

    def progressProperties(self) -> dict[str, Callable[[], str]]:  # noqa: N802 (OMPL's style)
        """OMPL's planner progress properties: ``"name TYPE"`` -> a function giving the current
        value as a string, safe to call from another thread while a solve runs (as
        ``ompl.tools.Benchmark`` samples ``getPlannerProgressProperties()``; OMPL 2.0's bindings
        cannot return that map, hence this method).

        ``iterations INTEGER`` and ``best cost REAL`` (``inf`` until a path is found) for every
        planner, plus what :meth:`_progress_extras` adds.
        """
        return {
            "iterations INTEGER": lambda: str(self.progress.iterations),
            "best cost REAL": lambda: repr(float(self.progress.best_cost)),
            **self._progress_extras(),
        }

    def _progress_extras(self) -> dict[str, Callable[[], str]]:
        """Further progress properties of a subclass (override)."""
        return {}

    def _draw_seed(self) -> int:
        """A seed from the planner's OMPL ``RNG`` (repeated by ``ompl.util.RNG.setSeed``)."""
        return self._rng.uniformInt(1, 2**31 - 2)

    def _before_solve(self) -> None:
        """Checks and one-time work before a solve is timed (override)."""

    def _plan(
        self, ptc: ob.PlannerTerminationCondition, points: Points, rng: np.random.Generator
    ) -> tuple[ob.PlannerStatus.PlannerStatusType, dict[str, Any]]:
        """The search; returns the status and the fields of ``Stats`` it measured."""
        raise NotImplementedError

    # -- output ----------------------------------------------------------------------

    def _add_solution(self, points: Points, path_points: Iterable[Any]) -> None:
        """Add the path through ``path_points`` (in order) to the problem definition as exact."""
        path = og.PathGeometric(self.getSpaceInformation())
        for point in path_points:
            path.append(points.ompl_state(point))
        self.getProblemDefinition().addSolutionPath(path, False, 0.0, self.getName())

    def plannerData(self) -> ob.PlannerData:  # noqa: N802 (OMPL's style; see the note below)
        """The planner's graph as an ``ob.PlannerData`` that owns copies of its states.

        A Python planner must not define ``getPlannerData``: C++ callers
        (``SimpleSetup.getPlannerData``, ``ompl.tools.Benchmark``) would dispatch to it and
        OMPL 2.0's bindings abort the process, so ``ss.getPlannerData`` returns an empty
        graph for the package's planners and this method gives the graph instead.
        """
        data = ob.PlannerData(self.getSpaceInformation())
        if self._points is not None:
            keep_alive: list[ob.State] = []  # the graph points into these until it is decoupled
            self._fill_planner_data(data, self._points, keep_alive)
            data.decoupleFromPlanner()
        return data

    def _fill_planner_data(self, data: ob.PlannerData, points: Points, keep_alive: list[ob.State]) -> None:
        """Add the planner's vertices and edges to ``data`` (override)."""
        raise NotImplementedError

    @staticmethod
    def _add_tree(
        data: ob.PlannerData,
        points: Points,
        tree: Tree,
        tag: int,
        keep_alive: list[ob.State],
        roots_are_starts: bool = True,
        goal_nodes: Sequence[int] = (),
    ) -> list[int]:
        """Add ``tree``'s nodes (tagged ``tag``) and its edges parent -> child; returns the vertex
        index of each node. Roots are start vertices (goal vertices unless ``roots_are_starts``);
        ``goal_nodes`` are marked as goal vertices."""
        goals = set(goal_nodes)
        indices = []
        for node in range(len(tree)):
            state = points.new_state(tree.state(node))
            keep_alive.append(state)
            vertex = ob.PlannerDataVertex(state, tag)
            if tree.parent(node) == NO_PARENT:
                indices.append(data.addStartVertex(vertex) if roots_are_starts else data.addGoalVertex(vertex))
            elif node in goals:
                indices.append(data.addGoalVertex(vertex))
            else:
                indices.append(data.addVertex(vertex))
        for node in range(len(tree)):
            if tree.parent(node) != NO_PARENT:
                data.addEdge(indices[tree.parent(node)], indices[node])
        return indices
