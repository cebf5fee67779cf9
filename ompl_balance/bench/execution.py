"""One run, executed inside its own process: seeding, the warm-up, the timed solve, the record.

:func:`execute` is what a run's process does (:mod:`ompl_balance.bench.isolation` starts
the process): it seeds OMPL's global random number generator with the run's seed before
anything draws a random number, builds the problem and the planner, warms the planner's
code up on a copy of the problem (:func:`warm_up`), times ``ss.solve`` alone while a thread
samples progress and checks the memory limit (a solve during which numba compiled is timed
again), simplifies the solution, and returns the record with OMPL's run properties.
"""

from __future__ import annotations

import contextlib
import os
import resource
import sys
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ..core.counting import read_work
from .experiment import RunTask
from .planner_params import named_by_getters, planner_params
from .planner_properties import graph_properties, stats_properties, typed
from .progress_sampler import FirstSolutionWatch, ProgressSampler, improves_cost, progress_properties
from .results import STATUS_INDEX, Record, failure_properties, run_record, status_name

#: The run property of a planner that keeps improving its solution: seconds from the start of its
#: solve to its first solution (see :class:`~ompl_balance.bench.progress_sampler.FirstSolutionWatch`).
FIRST_SOLUTION_TIME = "first solution time REAL"

#: What the note of a run timed again says (see :func:`execute`), and of one whose time includes compiling.
TIMED_AGAIN, TIME_INCLUDES_COMPILING = "timed again", "which its time includes"

#: The phases of a run, in order, as :func:`execute` reports them. ``"engine"``: a planner of the
#: package makes its compiled engine ready (loaded, or compiled on a first use after installing),
#: which the run waits for untimed; ``"simplification"`` comes with the record of the solve.
PHASES = ("engine", "warm-up", "solve", "simplification")


def _peak_memory() -> float:
    """Peak resident memory of this process so far, in MB."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 2**20 if sys.platform == "darwin" else peak / 1024.0  # bytes on macOS, KiB elsewhere


#: MB of address space allowed besides 2 x the memory limit (threads reserve malloc arenas of 64 MB).
ADDRESS_SPACE_MARGIN = 256.0


def _limit_address_space(growth: float) -> None:
    """Let this process's address space grow by at most ``growth`` MB from now (Linux only)."""
    try:
        pages = int(Path("/proc/self/statm").read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return
    limit = pages * os.sysconf("SC_PAGE_SIZE") + int(growth * 2**20)
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


class MemoryLimit:
    """OMPL's memory limit: ends the solve through its termination condition once the process's
    peak resident memory has grown by ``limit`` MB since the ``with`` block began; the planner
    then returns what it has, as under a time limit. :meth:`check` decides, called every 0.05 s
    by the run's sampling thread (as ``Benchmark``'s condition checks ``getProcessMemoryUsage``
    periodically). ``limit <= 0``: no limit.

    Behind it, for a planner that ignores its termination condition, the process's address
    space may grow by at most 2 x ``limit`` + :data:`ADDRESS_SPACE_MARGIN` MB (Linux only):
    past that an allocation fails and the run is recorded as ``CRASH``.
    """

    def __init__(self, limit: float) -> None:
        self.limit, self.reached = limit, False
        self.ptc: ob.PlannerTerminationCondition | None = None  # the solve's, set by watch()
        self.start = 0.0  # MB, peak resident memory when the block began

    def watch(self, ptc: ob.PlannerTerminationCondition) -> MemoryLimit:
        """This limit as the ``with`` block of the solve that ``ptc`` ends."""
        self.ptc = ptc
        return self

    def __enter__(self) -> MemoryLimit:
        self.start = _peak_memory()
        if self.limit > 0:
            _limit_address_space(2 * self.limit + ADDRESS_SPACE_MARGIN)
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.ptc = None

    def check(self) -> None:
        """End the solve if its memory has grown past the limit."""
        if self.ptc is not None and not self.reached and _peak_memory() - self.start > self.limit:
            self.reached = True
            self.ptc.terminate()


#: The run's OMPL objects, never destroyed: the process ends with ``os._exit`` after sending its
#: record, and some planners crash when destroyed (OMPL 2.0.1's ``AORRTC``), which must not
#: cost the run its record.
KEEP_UNTIL_EXIT: list[og.SimpleSetup] = []

#: Longest warm-up solve (s; at most the run's time limit); it ends sooner at its first exact solution.
WARM_UP_TIME = 0.02


def warm_up(task: RunTask) -> None:
    """An untimed, uncounted solve of a fresh copy of the run's problem and planner, ended by
    a termination condition built in C++: its first exact solution or :data:`WARM_UP_TIME`
    seconds (at most the run's time limit), whichever comes first.

    A run's process is fresh, and the first execution of a planner's code in a process is
    slow: cold caches and pages, and Python's bytecode not yet specialised. On
    MotionBenchMaker problems this costs a Python planner about 4 ms more than a C++ one,
    as much as a whole solve, so without the warm-up the timed solve would measure the
    process's start rather than the planning. Stock and package planners are warmed alike.

    The condition is OMPL's own (``timedPlannerTerminationCondition`` or
    ``exactSolnPlannerTerminationCondition``), not a Python function: a planner that checks
    its condition in a thread of its own (``PRM``, ``PRMstar``) deadlocks on a Python one.
    The warm-up draws its random numbers from generators of its own planner and problem; the
    timed solve's generators are seeded from the run's seed whatever the warm-up drew, so the
    run stays reproducible from its seed.
    """
    ss = task.problem.build()
    ss.setPlanner(task.planner.build(ss.getSpaceInformation()))
    KEEP_UNTIL_EXIT.append(ss)
    pdef = ss.getProblemDefinition()
    ptc = ob.plannerOrTerminationCondition(
        ob.timedPlannerTerminationCondition(min(WARM_UP_TIME, task.time_limit)),
        ob.exactSolnPlannerTerminationCondition(pdef),
    )
    ss.solve(ptc)


def seed_ompl(seed: int) -> None:
    """Seed OMPL's seed generator, from which every random generator made after this call (the
    run's problem, planner and samplers) takes its own seed.

    In a run forked from a sweep's forkserver the generator has already handed out seeds, to
    what the forkserver's warm-up made (which no run uses), so OMPL logs an error that changing
    the seed now will not be deterministic. It reseeds the generator all the same, and for the
    run it is: its runs repeat their results (the benchmark's tests). That message, one per run,
    is not shown.
    """
    level = ou.getLogLevel()
    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    try:
        ou.RNG.setSeed(seed)
    finally:
        ou.setLogLevel(level)


def _no_phase(phase: str, record: Record | None = None) -> None:
    """The default phase report of :func:`execute`: none."""


class NumbaCompiling:
    """The seconds numba spends compiling while the ``with`` block runs (:attr:`seconds`; 0 where
    numba is not loaded, as then nothing compiles), measured by numba's event API.

    A compilation inside a timed solve is the first call of some compiled code in the run's
    process that its warm-up did not make (such as a user's function compiled at its first
    call), which numba keeps for the process: it is the process's start, not planning (see
    :func:`execute`)."""

    def __init__(self) -> None:
        self.seconds = 0.0
        self._listening = contextlib.ExitStack()
        self._listener: Any = None

    def __enter__(self) -> NumbaCompiling:
        if "numba" in sys.modules:
            from numba.core import event

            self._listener = event.TimingListener()
            self._listening.enter_context(event.install_listener("numba:compile", self._listener))
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._listening.close()
        if self._listener is not None and self._listener.done:
            self.seconds = self._listener.duration


def execute(task: RunTask, phase: Callable[[str, Record | None], None] = _no_phase) -> Record:
    """Run ``task`` in this process and return its record (call in a fresh process: it seeds OMPL).

    ``phase`` is told each of :data:`PHASES` as it starts (the process that waits for the
    run says which one a killed run was in), and with ``"simplification"`` the record of the
    solve as it stands before the path is simplified: a run killed while simplifying is
    recorded with what its solve did, not as a crash of the planner.

    Properties (OMPL log names and types): time, memory, status, solved, approximate
    solution, solution length and segments, simplification time, simplified solution
    length and segments, graph states and motions, validity checks, motion checks,
    distance queries, every numeric field of the planner's ``stats`` (iterations,
    start/goal tree size, tree swaps, sampler checks, ... for this package's planners) and,
    for a planner that keeps improving its solution until the time limit (RRT*), the first
    solution time (:data:`FIRST_SOLUTION_TIME`: its termination condition looks at its best
    cost once an iteration, a Python call the solve's time includes).
    The planner's progress properties, sampled every 0.05 s during the solve, go to the
    record's ``progress``. A solve that raises is recorded with OMPL's ``CRASH`` status.

    A short timed solve during which numba compiled code (:class:`NumbaCompiling`) is run again
    in the same process, from its seed as the first time (problem, planner and warm-up made
    anew), and the run's record is the second's, with a note saying so: the compiled code is
    then ready, as the warm-up means it to be. Short: within half the hard limit's margin over
    planning and simplifying, so that both fit in it; a longer solve that compiled keeps its
    record, with a note that its time includes the compiling. (Peak memory is the process's, so
    a run timed again counts its ``memory REAL`` from the peak the first try left.)
    """
    record, compiled = _execute(task, phase, retime=True)
    if compiled > 0.0:
        record, _ = _execute(task, phase, retime=False, compiled_before=compiled)
    return record


def _execute(
    task: RunTask, phase: Callable[[str, Record | None], None], retime: bool, compiled_before: float = 0.0
) -> tuple[Record, float]:
    """:func:`execute`'s run, and the seconds numba compiled during its timed solve when it is to
    be timed again (``retime``, a short solve: returned at once, its path not simplified), else
    0; ``compiled_before``: the seconds the first try's solve compiled, for the note."""
    seed_ompl(task.seed)  # before this run makes anything that draws random numbers
    ss = task.problem.build()
    si = ss.getSpaceInformation()
    planner = task.planner.build(si)
    # This package's planners get the run's seed, unless the experiment sets one or the
    # planner draws from OMPL's RNG (a valid-state sampler), which the setSeed above repeats.
    run_seeded = (
        "seed" not in task.planner.params
        and hasattr(planner, "setSeed")
        and not getattr(planner, "draws_from_ompl_rng", False)
    )
    if run_seeded:
        planner.setSeed(task.seed)
    ss.setPlanner(planner)
    KEEP_UNTIL_EXIT.append(ss)
    ss.setup()  # not timed: setup wraps the checker to count, loads compiled scans, ...
    wait_for_engine = getattr(planner, "wait_for_engine", None)
    if wait_for_engine is not None:
        phase("engine", None)
        wait_for_engine()  # every solve on the compiled engine, where it applies (not timed)
    params = planner_params(planner)
    if run_seeded:
        params["seed"] = "run"  # each run's own seed (the run property "seed")
    improving = improves_cost(planner)
    memory = MemoryLimit(task.memory_limit)
    progress = progress_properties(planner)
    sampler = ProgressSampler(progress, check=memory.check if task.memory_limit > 0 else None)
    first_solution = FirstSolutionWatch.of(progress) if improving else None
    work_before = read_work(si)
    began = time.perf_counter()
    try:
        if task.warm_up:
            phase("warm-up", None)
            warm_up(task)  # its own problem and planner: neither timed nor counted
            work_before, began = read_work(si), time.perf_counter()
        ptc = ob.timedPlannerTerminationCondition(task.time_limit)
        if first_solution is not None:
            ptc = ob.plannerOrTerminationCondition(ptc, first_solution.condition())
        phase("solve", None)
        with memory.watch(ptc), sampler, NumbaCompiling() as compiling:
            # The sampling and memory threads run already: their start and end are the
            # harness's cost, not the planner's (a Python thread's start costs as much as a
            # millisecond, a C++ one in OMPL's Benchmark microseconds), so only the solve is timed.
            began = sampler.begin()
            status = ss.solve(ptc)
            elapsed = sampler.end()
    except Exception:
        work = read_work(si) - work_before
        crashed = failure_properties("CRASH", time.perf_counter() - began)
        crashed.update(_work_properties(work.states_checked, work.motions_checked, work.distance_queries))
        record = run_record(task, "CRASH", crashed, params, traceback.format_exc(limit=-3), improving)
        return _finish(record, planner, sampler), 0.0
    work = read_work(si) - work_before
    status_text = status_name(status)
    properties: dict[str, Any] = {
        "time REAL": elapsed,
        "status ENUM": STATUS_INDEX[status_text],
        "solved BOOLEAN": int(ss.haveExactSolutionPath()),
        **_work_properties(work.states_checked, work.motions_checked, work.distance_queries),
    }
    if first_solution is not None and first_solution.found_at is not None:
        properties[FIRST_SOLUTION_TIME] = first_solution.found_at - began
    solved = ss.haveSolutionPath()
    if solved:
        path = ss.getSolutionPath()  # keep the owner while reading it
        properties.update(
            [
                typed("approximate solution", not ss.haveExactSolutionPath()),
                typed("solution length", path.length()),
                typed("solution segments", path.getStateCount() - 1),
            ]
        )
    properties.update(graph_properties(planner))
    properties.update(stats_properties(planner, _MEASURED_HERE))
    properties["memory REAL"] = _peak_memory() - memory.start  # MB the run added (OMPL: after minus before)
    record = run_record(task, status_text, properties, params, "", improving)
    notes = [f"stopped at the memory limit of {task.memory_limit:g} MB"] if memory.reached else []
    compiled = compiling.seconds
    if retime and compiled > 0.0 and elapsed <= (task.hard_limit - 2 * task.time_limit) / 2:
        return record, compiled  # (timed again: see execute)
    if compiled_before > 0.0:
        notes.append(f"{TIMED_AGAIN}: numba compiled for {compiled_before * 1e3:.0f} ms during its first solve")
    if compiled > 0.0:
        notes.append(f"numba compiled for {compiled * 1e3:.0f} ms during this solve, {TIME_INCLUDES_COMPILING}")
    if notes:
        record["note"] = "; ".join(notes)
    if solved:
        phase("simplification", _finish(record, planner, sampler))
        began = time.perf_counter()
        ss.simplifySolution(task.time_limit)
        properties["simplification time REAL"] = time.perf_counter() - began
        simplified = ss.getSolutionPath()
        properties.update(
            [
                typed("simplified solution length", simplified.length()),
                typed("simplified solution segments", simplified.getStateCount() - 1),
            ]
        )
    return _finish(record, planner, sampler), 0.0


def _finish(record: Record, planner: ob.Planner, sampler: ProgressSampler) -> Record:
    """``record`` with the sampled progress, and marked when its parameters are named after getters."""
    if len(sampler.names) > 1:
        record["progress"] = {"properties": sampler.names, "samples": sampler.samples}
    if named_by_getters(planner):
        record["param_names"] = "getters"
    return record


#: Fields of a planner's ``stats`` the runner measures itself (for every planner alike).
_MEASURED_HERE = ("status", "time", "states_checked", "motions_checked", "distance_queries")


def _work_properties(states: int, motions: int, distance_queries: int) -> dict[str, int]:
    return {
        "validity checks INTEGER": states,
        "motion checks INTEGER": motions,
        "distance queries INTEGER": distance_queries,
    }
