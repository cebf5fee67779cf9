"""What every planner of the package shares: the solve wrapper around its search.

:class:`TreePlanner` is an ``ob.Planner`` written in Python. A subclass declares its
parameters (a :class:`~ompl_balance.core.params.Settings` dataclass, ``Settings``), its
statistics record (``Stats``), what it is (``SPECS``) and its search
(:meth:`TreePlanner._plan`); the base does the rest the same way for all of them:

* ``params()`` and the camelCase accessors, from the settings table;
* ``setup()``: the counting checker (:func:`~ompl_balance.core.counting.ensure_counting`);
  nothing that takes time, since ``SimpleSetup.solve`` calls it inside the solve; ``setup()``
  and ``clear()`` (a subclass's too) run once per call, from Python as from C++
  (:func:`_once_per_call`);
* ``solve(ptc)``: the termination condition from what it was given (a condition, seconds
  or a callable), the seed of the solve (the ``seed`` parameter, or a draw from the planner's
  OMPL ``RNG``, which ``ompl.util.RNG.setSeed`` repeats), the work counted, and ``stats``;
* the solution path added to the problem definition, and the planner's graph
  (``getPlannerData(data)`` for Python callers, :meth:`TreePlanner.plannerData`);
* ``getSpecs()``, ``printProperties()`` and ``printSettings()`` as OMPL's planners answer them;
* progress properties (:meth:`TreePlanner.progressProperties`), readable while a solve runs.

OMPL 2.0.1's bindings limit what C++ callers see of a Python planner: ``docs/drop-in.md``
lists those limits and how the package works around them.
"""

from __future__ import annotations

import functools
import math
import numbers
import time
import types
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, TypeAlias

import numpy as np
import numpy.random  # imported now: numpy loads it lazily, and a solve must not pay for it
from ompl import base as ob
from ompl import control as oc
from ompl import geometric as og
from ompl import util as ou

from .counting import WorkCount, ensure_counting, read_work, tell_validator_the_checker
from .exit_release import release_at_exit
from .params import ParamSet, Settings, add_accessors
from .spaces import Points, points_for
from .trees import NO_PARENT, Tree

#: OMPL's default range as a fraction of the space's maximum extent
#: (``magic::MAX_MOTION_LENGTH_AS_SPACE_EXTENT_FRACTION``).
RANGE_AS_EXTENT_FRACTION = 0.2

#: ``PlannerData`` vertex tags, as OMPL's RRT-Connect: 1 start tree, 2 goal tree.
START_TAG = 1
GOAL_TAG = 2

#: Anything ``solve`` takes: a condition (C++ callers), seconds, or a callable "stop now?".
Limit: TypeAlias = "ob.PlannerTerminationCondition | float | Callable[[], bool]"


#: Seconds beyond which OMPL's timed termination condition overflows its clock (its deadline,
#: in nanoseconds, passes 2**63 near 7.4e9 s after the clock's epoch).
LONGEST_LIMIT = 7.0e9


def termination_condition(limit: Limit) -> ob.PlannerTerminationCondition:
    """A ``PlannerTerminationCondition`` from what ``solve`` was given.

    C++ callers (``SimpleSetup``, ``Benchmark``) pass a condition; Python callers may
    pass a time limit in seconds or a callable that returns ``True`` when planning
    should stop. As OMPL's ``Planner::solve(double)``, a limit of zero or less stops at
    once; a limit that is not a finite number is refused; one beyond OMPL's clock (about 230
    years, :data:`LONGEST_LIMIT`) never stops planning, where OMPL's own condition would
    overflow and stop at once.
    """
    if isinstance(limit, ob.PlannerTerminationCondition):
        return limit
    if isinstance(limit, numbers.Real) and not isinstance(limit, (bool, np.bool_)):
        seconds = float(limit)
        if not math.isfinite(seconds):
            raise ValueError(f"solve() time limit must be a finite number of seconds, got {limit!r}")
        if seconds > LONGEST_LIMIT:
            return ob.plannerNonTerminatingCondition()
        return ob.timedPlannerTerminationCondition(max(seconds, 0.0))
    if callable(limit):
        return ob.PlannerTerminationCondition(limit)
    raise TypeError(
        f"solve() takes a PlannerTerminationCondition, a time limit in seconds or a callable, got {type(limit).__name__}"
    )


@dataclass(frozen=True)
class PlannerSpecs:
    """OMPL's ``ompl::base::PlannerSpecs``: what a planner is and does.

    OMPL 2.0.1's ``Planner.getSpecs()`` cannot return the C++ record to Python, so the
    package's planners answer ``getSpecs()`` with this one (same field names).
    """

    recognizedGoal: ob.GoalType = ob.GoalType.GOAL_ANY  # noqa: N815 (OMPL's names)
    multithreaded: bool = False
    approximateSolutions: bool = False  # noqa: N815
    optimizingPaths: bool = False  # noqa: N815
    directed: bool = False
    provingSolutionNonExistence: bool = False  # noqa: N815
    canReportIntermediateSolutions: bool = False  # noqa: N815


class PlannerGraph(ob.PlannerData):
    """An ``ob.PlannerData`` with the ``properties`` of C++'s ``PlannerData::properties``.

    ``properties`` maps ``"name TYPE"`` to a value string (``"approx goal distance REAL"``),
    as OMPL's planners fill it in ``getPlannerData``; OMPL 2.0.1's bindings do not expose
    the C++ map, so the package's planners write this one.
    """

    def __init__(self, si: ob.SpaceInformation) -> None:
        super().__init__(si)
        self.properties: dict[str, str] = {}


class _ForPythonCallers:
    """A virtual method of ``ob.Planner`` that Python callers get from the package and C++
    callers from OMPL.

    OMPL 2.0.1's bindings dispatch ``getPlannerData``, ``printProperties`` and
    ``printSettings`` called from C++ (``SimpleSetup``, ``ompl.tools.Benchmark``) to a Python
    method of that name, and abort the process when they do (their arguments, a
    ``PlannerData&`` or a ``std::ostream&``, cannot be handed to Python). nanobind looks a
    Python override up once per planner object, at the first call from C++, and keeps the
    answer. :class:`TreePlanner`'s constructor makes those first calls while this descriptor
    still answers with OMPL's own method, so C++ callers keep OMPL's; from then on, Python
    callers get the package's method.
    """

    def __init__(self, method: Callable[..., Any]) -> None:
        self.method = method
        self.name = method.__name__
        self.__doc__ = method.__doc__

    def __get__(self, planner: Any, owner: type | None = None) -> Any:
        if planner is None:
            return self.method
        if planner.__dict__.get("_cpp_overrides_resolved", False):
            return types.MethodType(self.method, planner)
        return getattr(ob.Planner, self.name).__get__(planner, owner)


#: The ``ob.Planner`` methods the package's planners extend (``super().setup()`` first, then theirs).
EXTENDED_METHODS = ("setup", "clear")


def _once_per_call(method: Callable[..., Any]) -> Callable[..., Any]:
    """A planner's ``setup`` or ``clear`` that runs once per call, called from Python as from C++.

    OMPL 2.0.1's bindings (nanobind) tell a call of ``ob.Planner.setup(self)`` made inside a
    Python override apart from a new call only when C++ made the outer call (``SimpleSetup``).
    Called from Python (``planner.setup()``, ``planner.clear()``), the base's call is sent back to
    the most derived override first, which would run every override in the chain twice (twice
    the cost, and a second seed drawn from the planner's RNG). :meth:`TreePlanner._call_base`
    marks the planner while OMPL's own method runs; an override called back meanwhile hands the
    call straight to OMPL's.
    """
    base = getattr(ob.Planner, method.__name__)

    @functools.wraps(method)
    def extended(planner: Any, *args: Any) -> Any:
        if planner.__dict__.get("_in_base_call", False):
            return base(planner, *args)  # the base's call sent back: now nanobind runs OMPL's own
        return method(planner, *args)

    extended.__once_per_call__ = True  # type: ignore[attr-defined]
    return extended


@dataclass
class Progress:
    """What a solve has done so far, updated as it runs (read by :meth:`TreePlanner.progressProperties`)."""

    iterations: int = 0
    best_cost: float = math.inf  # cost (path length) of the best solution so far


class TreePlanner(ob.Planner):
    """Base of the package's planners (see the module docstring).

    Subclasses set ``Settings`` (their parameter table, which must have ``seed``),
    ``Stats`` (a dataclass with ``status``, ``states_checked``, ``motions_checked``,
    ``distance_queries`` and ``time`` fields besides those :meth:`_plan` returns) and
    ``SPECS``, implement :meth:`_plan` (keeping :attr:`progress` current) and
    :meth:`_fill_planner_data`.
    """

    Settings: ClassVar[type[Settings]]
    Stats: ClassVar[type]
    SPECS: ClassVar[PlannerSpecs] = PlannerSpecs()
    #: The constructor's signature, for the message refusing other arguments.
    SIGNATURE: ClassVar[str] = "(si, name=None)"

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "Settings" in cls.__dict__:
            add_accessors(cls, cls.Settings)
        for name in EXTENDED_METHODS:  # (a user's subclass too)
            method = cls.__dict__.get(name)
            if method is not None and not getattr(method, "__once_per_call__", False):
                setattr(cls, name, _once_per_call(method))

    def __init__(self, si: ob.SpaceInformation, name: str | None = None) -> None:
        if name is not None and not isinstance(name, str):
            self._refuse_argument("name must be a str", name)
        if not isinstance(si, ob.SpaceInformation) or isinstance(si, oc.SpaceInformation):
            # the package's planners plan geometric paths: a control space information is refused
            self._refuse_argument(
                "si must be a geometric ompl.base.SpaceInformation (ss.getSpaceInformation() of an "
                "ompl.geometric.SimpleSetup)",
                type(si),  # a space information's repr is its settings, many lines
            )
        super().__init__(si, name or type(self).__name__)
        # nanobind resolves the C++ side of the Python-only methods now (see _ForPythonCallers).
        ob.Planner.getPlannerData(self, ob.PlannerData(si))
        ob.Planner.printProperties(self)
        ob.Planner.printSettings(self)
        self._cpp_overrides_resolved = True
        self._in_base_call = False  # while OMPL's own setup() or clear() runs (see _once_per_call)
        self.settings: Any = type(self).Settings()
        self._params: ParamSet | None = None  # made at the first params(): a planner constructed is not configured
        self._rng = ou.RNG()  # per-planner stream, seeded from OMPL's global seed
        self._prepared: tuple[int, np.random.Generator] | None = None  # (seed, the next solve's generator)
        self._points: Points | None = None  # how solves see the space (made at setup)
        self.progress = Progress()
        self.stats: Any = None
        release_at_exit(self)  # (OMPL holds planners from C++: see core.exit_release)

    @classmethod
    def _refuse_argument(cls, problem: str, value: Any) -> None:
        raise TypeError(f"{cls.__name__}{cls.SIGNATURE}: {problem}, got {value!r}")

    def params(self) -> ParamSet:
        """This planner's parameters (OMPL's ``ParamSet`` semantics)."""
        if self._params is None:
            self._params = ParamSet.of(self.settings)
        return self._params

    def getSpecs(self) -> PlannerSpecs:  # noqa: N802 (OMPL's names)
        """What the planner is and does, as OMPL's ``PlannerSpecs``."""
        return self.SPECS

    @_ForPythonCallers
    def printProperties(self) -> str:  # noqa: N802
        """The planner's specs and parameter names, in the words of OMPL's ``Planner::printProperties``."""
        specs = self.SPECS

        def yes(flag: bool) -> str:
            return "Yes" if flag else "No"

        return (
            f"Planner {self.getName()} specs:\n"
            f"Multithreaded:                 {yes(specs.multithreaded)}\n"
            f"Reports approximate solutions: {yes(specs.approximateSolutions)}\n"
            f"Can optimize solutions:        {yes(specs.optimizingPaths)}\n"
            f"Aware of the following parameters: {' '.join(self.params().getParamNames())}\n"
        )

    @_ForPythonCallers
    def printSettings(self) -> str:  # noqa: N802
        """The parameters and their values, as OMPL's ``Planner::printSettings``."""
        values = "".join(f"{name} = {value}\n" for name, value in self.params().getParams().items())
        return f"Declared parameters for planner {self.getName()}:\n{values}"

    @_once_per_call
    def setup(self) -> None:
        self._call_base(ob.Planner.setup)
        si = self.getSpaceInformation()
        ensure_counting(si)
        self._points = points_for(si)  # how solves see the space (each restarts it with its seed)
        self._prepare_generator()

    @_once_per_call
    def clear(self) -> None:
        self._call_base(ob.Planner.clear)
        self.stats = None
        self._prepare_generator()

    def _call_base(self, method: Callable[[ob.Planner], None]) -> None:
        """OMPL's own ``method`` (``ob.Planner.setup`` or ``clear``) on this planner, once (see
        :func:`_once_per_call`)."""
        self._in_base_call = True
        try:
            method(self)
        finally:
            self._in_base_call = False

    def _prepare_generator(self) -> None:
        """Make the next solve's generator now (at setup and clear, as OMPL's planners allocate:
        making one costs as much as a short solve's planning); with ``seed = 0`` its seed is
        drawn now, the draw the solve would make."""
        seed = self.settings.seed
        self._prepared = (seed, np.random.default_rng(seed or self._draw_seed()))

    def _generator(self) -> np.random.Generator:
        """A solve's random numbers: a stream started from ``seed`` (every solve starts it
        again), or with ``seed = 0`` from a seed drawn from the planner's OMPL RNG (one draw a
        solve: the generator prepared at setup or clear, else drawn now)."""
        seed = self.settings.seed
        prepared, self._prepared = self._prepared, None
        if prepared is not None and prepared[0] == seed:
            return prepared[1]
        return np.random.default_rng(seed or self._draw_seed())

    def solve(self, ptc: Limit) -> ob.PlannerStatus:
        """Plan until the search ends or ``ptc`` says stop (a condition, seconds or a callable)."""
        ptc = termination_condition(ptc)
        self.checkValidity()
        self._before_solve(ptc)
        si = self.getSpaceInformation()
        tell_validator_the_checker(si)
        began = time.perf_counter()
        work_before = read_work(si)
        rng = self._generator()
        # (how the last solve saw the space serves the next: allocating it costs a short solve's time)
        self._points = points_for(si, rng) if self._points is None else self._points.restarted(rng)
        self.progress = Progress()
        try:
            status, measured = self._plan(ptc, self._points, rng)
        except Exception:
            # An error mid-solve (a user's checker that raised) leaves the trees and OMPL's
            # planner input states half-way (a goal state taken, not added): start afresh next time.
            self.clear()
            raise
        work = read_work(si) - work_before
        self.stats = self._statistics(ob.PlannerStatus(status).asString(), work, time.perf_counter() - began, measured)
        return ob.PlannerStatus(status)

    def _statistics(self, status: str, work: WorkCount, elapsed: float, measured: Any) -> Any:
        """The ``Stats`` record of a solve: its status, the checkers' work, the seconds it took and
        what :meth:`_plan` measured (by default a dict of the other fields of ``Stats``)."""
        return self.Stats(
            status=status,
            states_checked=work.states_checked,
            motions_checked=work.motions_checked,
            distance_queries=work.distance_queries,
            time=elapsed,
            **measured,
        )

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

    def _before_solve(self, ptc: ob.PlannerTerminationCondition) -> None:
        """Checks and one-time work before a solve's statistics start (override); within ``ptc``."""

    def _plan(
        self, ptc: ob.PlannerTerminationCondition, points: Points, rng: np.random.Generator
    ) -> tuple[ob.PlannerStatus.PlannerStatusType, Any]:
        """The search; returns the status and what it measured (see :meth:`_statistics`)."""
        raise NotImplementedError

    # -- output ----------------------------------------------------------------------

    def _add_solution(self, points: Points, path_points: Iterable[Any]) -> og.PathGeometric:
        """Add the path through ``path_points`` (in order) to the problem definition as exact; returns it."""
        path = og.PathGeometric(self.getSpaceInformation())
        for point in path_points:
            path.append(points.ompl_state(point))
        self.getProblemDefinition().addSolutionPath(path, False, 0.0, self.getName())
        return path

    @_ForPythonCallers
    def getPlannerData(self, data: ob.PlannerData) -> None:  # noqa: N802 (OMPL's name)
        """Add the planner's graph to ``data``, as the stock planner's ``getPlannerData``.

        ``data`` owns copies of the states afterwards (``decoupleFromPlanner``). When ``data``
        has ``properties`` (a :class:`PlannerGraph`), they are filled as OMPL fills
        ``PlannerData::properties``: the progress properties' values, and what the planner
        adds (:meth:`_graph_properties`). Called from C++ (``SimpleSetup.getPlannerData``,
        ``ompl.tools.Benchmark``) this is OMPL's ``Planner::getPlannerData``, which adds nothing.
        """
        properties = getattr(data, "properties", None)
        if isinstance(properties, dict):
            properties.update({name: value() for name, value in self.progressProperties().items()})
            properties.update(self._graph_properties())
        if self._points is not None:
            keep_alive: list[ob.State] = []  # the graph points into these until it is decoupled
            self._fill_planner_data(data, self._points, keep_alive)
            data.decoupleFromPlanner()

    def plannerData(self) -> PlannerGraph:  # noqa: N802 (OMPL's style)
        """The planner's graph as a new :class:`PlannerGraph` (see :meth:`getPlannerData`)."""
        data = PlannerGraph(self.getSpaceInformation())
        self.getPlannerData(data)
        return data

    def _graph_properties(self) -> dict[str, str]:
        """``PlannerData`` properties the planner sets in ``getPlannerData`` (override)."""
        return {}

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
        goal_nodes: Sequence[int] = (),
        goal_tree: bool = False,
    ) -> list[int]:
        """Add ``tree``'s nodes (tagged ``tag``) and its edges; returns the vertex index of each node.

        Roots are start vertices and edges run parent -> child; in a ``goal_tree`` (OMPL's
        goal trees) roots are goal vertices and edges run child -> parent. ``goal_nodes``
        are marked as goal vertices.
        """
        goals = set(goal_nodes)
        indices = []
        for node in range(len(tree)):
            state = points.new_state(tree.state(node))
            keep_alive.append(state)
            vertex = ob.PlannerDataVertex(state, tag)
            if tree.parent(node) == NO_PARENT:
                indices.append(data.addGoalVertex(vertex) if goal_tree else data.addStartVertex(vertex))
            elif node in goals:
                indices.append(data.addGoalVertex(vertex))
            else:
                indices.append(data.addVertex(vertex))
        for node, index in enumerate(indices):
            parent = tree.parent(node)
            if parent == NO_PARENT:
                continue
            if goal_tree:
                data.addEdge(index, indices[parent])
            else:
                data.addEdge(indices[parent], index)
        return indices
