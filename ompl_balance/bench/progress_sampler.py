"""Planner progress sampled while a run solves, as ``ompl.tools.Benchmark`` samples it.

OMPL's Benchmark starts a thread next to ``solve`` that, every ``timeBetweenUpdates``
seconds (0.05 by default), reads each of the planner's progress properties
(``getPlannerProgressProperties()``: ``"name TYPE"`` -> a function returning the value
as a string) and stores them with ``"time REAL"``, the seconds since the solve started;
the first sample is taken one period after the start, none after the solve returns.
:class:`ProgressSampler` does the same in a Python thread of the run's process.

Where the properties come from (:func:`progress_properties`):

* this package's planners: ``planner.progressProperties()`` (``iterations``, ``best cost``,
  tree sizes);
* stock planners: OMPL 2.0's bindings cannot return ``getPlannerProgressProperties()``, so
  the properties are rebuilt from the bound methods that read the same counters
  (:data:`STOCK_PROGRESS`): ``RRTstar`` and its informed variants, ``BITstar``, ``AORRTC``
  and ``PRM``. These methods are safe to call during ``solve`` from Python because the run's
  validity checker is a Python callable (the run counts checks), so the solving thread
  returns to Python, where the sampler can take its turn, at every check.

A planner that keeps improving its solution solves until its time limit; when it first had a
solution, :class:`FirstSolutionWatch` notes to the iteration from its best cost.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from types import TracebackType
from typing import Any

from ompl import base as ob
from ompl import geometric as og

#: OMPL's ``Benchmark::Request::timeBetweenUpdates`` default (s).
SAMPLE_PERIOD = 0.05

#: Progress properties that carry the best cost so far (RRTstar: REAL, BITstar: DOUBLE).
BEST_COST_PROPERTIES = ("best cost REAL", "best cost DOUBLE")

ProgressProperties = dict[str, Callable[[], str]]


def _real(value: float) -> str:
    """A real as OMPL's ``ompl::toString`` writes it (``operator<<``: 6 significant digits)."""
    return f"{value:g}"


def _rrtstar_progress(planner: Any) -> ProgressProperties:
    """``RRTstar``'s properties (RRTstar.cpp: ``iterations INTEGER``, ``best cost REAL``)."""
    return {
        "iterations INTEGER": lambda: str(planner.numIterations()),
        "best cost REAL": lambda: _real(planner.bestCost().value()),
    }


def _bitstar_progress(planner: Any) -> ProgressProperties:
    """The bound ones of ``BITstar``'s properties (BITstar.cpp names them ``best cost DOUBLE``, ...)."""
    return {
        "best cost DOUBLE": lambda: _real(planner.bestCost().value()),
        "iterations INTEGER": lambda: str(planner.numIterations()),
        "batches INTEGER": lambda: str(planner.numBatches()),
    }


def _aorrtc_progress(planner: Any) -> ProgressProperties:
    """``AORRTC``'s best cost (AORRTC.cpp declares no progress properties; ``bestCost`` is bound)."""
    return {"best cost REAL": lambda: _real(planner.bestCost().value())}


def _prm_progress(planner: Any) -> ProgressProperties:
    """The bound ones of ``PRM``'s properties (PRM.cpp: ``milestone count``, ``edge count``)."""
    return {
        "milestone count INTEGER": lambda: str(planner.milestoneCount()),
        "edge count INTEGER": lambda: str(planner.edgeCount()),
    }


#: Stock planner classes (and their subclasses) -> their progress properties from bound methods.
STOCK_PROGRESS: tuple[tuple[type, Callable[[Any], ProgressProperties]], ...] = (
    (og.RRTstar, _rrtstar_progress),  # InformedRRTstar and SORRTstar derive from it
    (og.BITstar, _bitstar_progress),
    (og.AORRTC, _aorrtc_progress),
    (og.PRM, _prm_progress),
)

#: Stock planners that keep improving their solution until their termination condition ends
#: the solve, and whose best cost the bindings can read (``PRMstar`` improves too, but its
#: cost is not bound).
STOCK_IMPROVING = (og.RRTstar, og.BITstar, og.AORRTC)


def progress_properties(planner: ob.Planner) -> ProgressProperties:
    """The planner's progress properties (``{}`` when it reports none)."""
    if hasattr(planner, "progressProperties"):
        return dict(planner.progressProperties())
    for cls, properties in STOCK_PROGRESS:
        if isinstance(planner, cls):
            return properties(planner)
    return {}


def improves_cost(planner: ob.Planner) -> bool:
    """Whether ``planner`` keeps improving its solution's cost until its time limit (OMPL's
    ``optimizingPaths``; for stock planners :data:`STOCK_IMPROVING`, as OMPL 2.0's bindings
    cannot return their ``PlannerSpecs``)."""
    try:
        return bool(planner.getSpecs().optimizingPaths)
    except TypeError:
        return isinstance(planner, STOCK_IMPROVING)


class FirstSolutionWatch:
    """When a planner that keeps improving its solution first has one: the moment its best cost
    (``best_cost``, a progress property's function) is first finite, looked at each time the
    planner evaluates :meth:`condition` (joined to its termination condition: once an
    iteration). Such a planner's solve ends at its time limit, and its progress samples, every
    :data:`SAMPLE_PERIOD` seconds, would only bound the moment from above.

    :meth:`condition` never says stop; ``found_at`` is the ``time.perf_counter()`` of that first
    look (``None`` until then).
    """

    def __init__(self, best_cost: Callable[[], str]) -> None:
        self._best_cost = best_cost
        self.found_at: float | None = None

    @classmethod
    def of(cls, properties: ProgressProperties) -> FirstSolutionWatch | None:
        """The watch of a planner with these progress properties; ``None`` when none is its best cost."""
        name = next((name for name in BEST_COST_PROPERTIES if name in properties), None)
        return None if name is None else cls(properties[name])

    def condition(self) -> ob.PlannerTerminationCondition:
        return ob.PlannerTerminationCondition(self._look)

    def _look(self) -> bool:
        if self.found_at is None and math.isfinite(float(_read(self._best_cost) or "inf")):
            self.found_at = time.perf_counter()
        return False


class ProgressSampler:
    """Samples ``properties`` every ``period`` seconds in a thread, from :meth:`begin` to :meth:`end`.

    The thread starts when the ``with`` block is entered and waits for :meth:`begin`, so
    that its start (about half a millisecond for a Python thread) is not part of the solve
    the caller times, and it stops with the block. Sample times count from :meth:`begin`;
    a sample taken after :meth:`end` (the solve had returned) is dropped, as OMPL's
    Benchmark takes none after ``solve`` returns. ``names`` are ``"time REAL"`` and the
    property names, sorted (the order of OMPL's log); ``samples`` one list of values per
    sample in that order. A property whose function raises is recorded empty for that sample.

    ``check``, if given, is called by the same thread before each sample: the run's memory
    limit, which OMPL's ``Benchmark`` also evaluates periodically in a thread of its own.
    """

    def __init__(
        self, properties: ProgressProperties, period: float = SAMPLE_PERIOD, check: Callable[[], None] | None = None
    ) -> None:
        self.period = period
        self.names = sorted(["time REAL", *properties])
        self.samples: list[list[str]] = []
        self._times: list[float] = []  # s since begin() of each sample
        self._properties = properties
        self._check = check
        self._began_event = threading.Event()
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._sample, name="progress sampler", daemon=True)
        self._began = 0.0
        self._ended = math.inf  # s since begin() when end() was called

    def __enter__(self) -> ProgressSampler:
        if self._properties or self._check is not None:
            self._thread.start()
        return self

    def begin(self) -> float:
        """Start sampling now; returns the time it began (``time.perf_counter()``, s)."""
        self._began = time.perf_counter()
        self._began_event.set()
        return self._began

    def end(self) -> float:
        """Stop sampling now; returns the seconds since :meth:`begin`."""
        self._ended = time.perf_counter() - self._began
        self._done.set()
        return self._ended

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, traceback: TracebackType | None
    ) -> None:
        self._done.set()
        self._began_event.set()  # a thread still waiting for begin() ends at once
        if self._thread.is_alive():
            self._thread.join()
        self.samples = [sample for sample, at in zip(self.samples, self._times) if at <= self._ended]

    def _sample(self) -> None:
        self._began_event.wait()
        while not self._done.wait(self.period):
            if self._check is not None:
                self._check()
            if not self._properties:
                continue
            at = time.perf_counter() - self._began
            values = {name: _read(read) for name, read in self._properties.items()}
            values["time REAL"] = repr(at)
            self.samples.append([values[name] for name in self.names])
            self._times.append(at)


def _read(read: Callable[[], str]) -> str:
    """A property's value now, or empty when it cannot be read yet."""
    try:
        return read()
    except Exception:  # a counter not readable yet: leave the sample empty there
        return ""
