"""Executing runs: one process per run, hard wall-clock caps, results appended as they finish.

Every run executes in a fresh process forked from a ``forkserver`` that has imported
OMPL and this package once (a few milliseconds per run, not a new interpreter). The
fresh process matters twice: OMPL's global ``RNG.setSeed`` only works before the first
random number of a process, so each run seeds it with its own seed
(:func:`~ompl_balance.bench.experiment.run_seed`) and stock planners repeat too; and a run
that segfaults, aborts or ignores its time limit takes only its own process down. The
parent waits at most ``task.hard_limit`` seconds (2 x the time limit + a margin:
planning, then simplification bounded by the time limit) and records OMPL's ``CRASH``
status for a process that died or had to be killed.

Results go to ``results.jsonl`` in the output folder, one JSON record per run, written
and flushed as each run finishes (:class:`ResultStore`); runs already there are skipped
when the same sweep is started again, so an interrupted sweep resumes where it stopped.

Runs execute serially, on a local pool of ``jobs`` concurrent processes, or on a Dask
distributed cluster (``dask="tcp://host:port"`` or ``"local:N"``, extra ``distributed``);
each Dask task starts its run's process inside the worker, so the results are the same.
"""

from __future__ import annotations

import itertools
import json
import multiprocessing
import os
import resource
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass
from multiprocessing import forkserver
from pathlib import Path
from typing import Any

from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ..core.counting import read_work
from .experiment import Experiment, MissingExtraError, RunTask
from .planner_params import named_by_getters, planner_params
from .progress import ProgressSampler, progress_properties

#: OMPL's planner status names -> the index the OMPL log's ``status`` enum uses.
STATUS_INDEX = {
    name: member.value
    for name, member in ob.PlannerStatus.PlannerStatusType.__members__.items()
    if name != "TYPE_COUNT"
}

Record = dict[str, Any]

#: Stock planners whose ``PlannerData`` tags the start tree's vertices 1 and the goal
#: tree's 2 (``RRTConnect::getPlannerData``); this package's planners report their tree
#: sizes in ``stats``.
TREE_TAGGING_STOCK_PLANNERS = (og.RRTConnect,)


# -- inside the run's process -----------------------------------------------------------


def _typed(name: str, value: Any) -> tuple[str, Any]:
    """An OMPL log property ``"name TYPE"`` for a Python value (bool -> BOOLEAN 0/1)."""
    if isinstance(value, bool):
        return f"{name} BOOLEAN", int(value)
    if isinstance(value, int):
        return f"{name} INTEGER", value
    return f"{name} REAL", float(value)


def _graph_properties(ss: og.SimpleSetup, planner: ob.Planner) -> dict[str, Any]:
    """Graph states and motions of every planner; start and goal tree sizes of stock RRT-Connect."""
    if hasattr(planner, "plannerData"):  # this package's planners (see TreePlanner.plannerData)
        data = planner.plannerData()
    else:
        data = ob.PlannerData(ss.getSpaceInformation())
        planner.getPlannerData(data)
    properties = dict([_typed("graph states", data.numVertices()), _typed("graph motions", data.numEdges())])
    if isinstance(planner, TREE_TAGGING_STOCK_PLANNERS):
        tags = [data.getVertex(i).getTag() for i in range(data.numVertices())]
        properties.update([_typed("start tree size", tags.count(1)), _typed("goal tree size", tags.count(2))])
    return properties


def _peak_memory() -> float:
    """Peak resident memory of this process so far, in MB."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / 2**20 if sys.platform == "darwin" else peak / 1024.0  # bytes on macOS, KiB elsewhere


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
_KEEP_UNTIL_EXIT: list[og.SimpleSetup] = []


#: Iterations (termination-condition checks) of the warm-up solve.
WARM_UP_ITERATIONS = 20


def warm_up(task: RunTask) -> None:
    """An untimed, uncounted solve of a fresh copy of the run's problem and planner, stopped
    after :data:`WARM_UP_ITERATIONS` iterations.

    A run's process is fresh, and the first execution of a planner's code in a process is
    slow: cold caches and pages, and Python's bytecode not yet specialised. On
    MotionBenchMaker problems this costs a Python planner about 4 ms more than a C++ one,
    as much as a whole solve, so without the warm-up the timed solve would measure the
    process's start rather than the planning. Stock and package planners are warmed alike;
    the warm-up draws random numbers after the run's seed was set, so the run stays
    reproducible from its seed.
    """
    ss = task.problem.build()
    ss.setPlanner(task.planner.build(ss.getSpaceInformation()))
    _KEEP_UNTIL_EXIT.append(ss)
    checks = itertools.count()
    ss.solve(ob.PlannerTerminationCondition(lambda: next(checks) >= WARM_UP_ITERATIONS))


def execute(task: RunTask) -> Record:
    """Run ``task`` in this process and return its record (call in a fresh process: it seeds OMPL).

    Properties (OMPL log names and types): time, memory, status, solved, approximate
    solution, solution length and segments, simplification time, simplified solution
    length and segments, graph states and motions, validity checks, motion checks,
    distance queries, and every numeric field of the planner's ``stats`` (iterations,
    start/goal tree size, tree swaps, sampler checks, ... for this package's planners).
    The planner's progress properties, sampled every 0.05 s during the solve, go to the
    record's ``progress``. A solve that raises is recorded with OMPL's ``CRASH`` status.
    """
    ou.RNG.setSeed(task.seed)  # before anything draws a random number in this process
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
    _KEEP_UNTIL_EXIT.append(ss)
    ss.setup()  # not timed: setup wraps the checker to count, loads compiled scans, ...
    params = planner_params(planner)
    if run_seeded:
        params["seed"] = "run"  # each run's own seed (the run property "seed")
    memory = MemoryLimit(task.memory_limit)
    sampler = ProgressSampler(progress_properties(planner), check=memory.check if task.memory_limit > 0 else None)
    work_before = read_work(si)
    began = time.perf_counter()
    try:
        if task.warm_up:
            warm_up(task)  # its own problem and planner: neither timed nor counted
            work_before, began = read_work(si), time.perf_counter()
        ptc = ob.timedPlannerTerminationCondition(task.time_limit)
        with memory.watch(ptc), sampler:
            # The sampling and memory threads run already: their start and end are the
            # harness's cost, not the planner's (a Python thread's start costs as much as a
            # millisecond, a C++ one in OMPL's Benchmark microseconds), so only the solve is timed.
            began = sampler.begin()
            status = ss.solve(ptc)
            elapsed = time.perf_counter() - began
    except Exception:
        work = read_work(si) - work_before
        crashed = failure_properties("CRASH", time.perf_counter() - began)
        crashed.update(_work_properties(work.states_checked, work.motions_checked, work.distance_queries))
        return _named(_record(task, "CRASH", crashed, params, traceback.format_exc(limit=-3), sampler), planner)
    work = read_work(si) - work_before
    status_name = _status_name(status)
    properties: dict[str, Any] = {
        "time REAL": elapsed,
        "status ENUM": STATUS_INDEX[status_name],
        "solved BOOLEAN": int(ss.haveExactSolutionPath()),
        **_work_properties(work.states_checked, work.motions_checked, work.distance_queries),
    }
    if ss.haveSolutionPath():
        path = ss.getSolutionPath()  # keep the owner while reading it
        properties.update(
            [
                _typed("approximate solution", not ss.haveExactSolutionPath()),
                _typed("solution length", path.length()),
                _typed("solution segments", path.getStateCount() - 1),
            ]
        )
        began = time.perf_counter()
        ss.simplifySolution(task.time_limit)
        properties["simplification time REAL"] = time.perf_counter() - began
        simplified = ss.getSolutionPath()
        properties.update(
            [
                _typed("simplified solution length", simplified.length()),
                _typed("simplified solution segments", simplified.getStateCount() - 1),
            ]
        )
    properties.update(_graph_properties(ss, planner))
    stats = getattr(planner, "stats", None)
    if stats is not None:
        for name, value in stats.as_dict().items():
            if name not in _MEASURED_HERE and isinstance(value, (int, float)):
                properties.update([_typed(name.replace("_", " "), value)])
    properties["memory REAL"] = _peak_memory() - memory.start  # MB the run added (OMPL: after minus before)
    record = _record(task, status_name, properties, params, "", sampler)
    if memory.reached:
        record["note"] = f"stopped at the memory limit of {task.memory_limit:g} MB"
    return _named(record, planner)


def _named(record: Record, planner: ob.Planner) -> Record:
    """``record``, marked when its parameters are named after getters, not OMPL's declared names."""
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


def _status_name(status: ob.PlannerStatus) -> str:
    """The ``PlannerStatusType`` member name of a ``PlannerStatus`` (``"EXACT_SOLUTION"``, ...)."""
    for name, member in ob.PlannerStatus.PlannerStatusType.__members__.items():
        if status == member:
            return name
    return "UNKNOWN"


def failure_properties(status: str, elapsed: float) -> dict[str, Any]:
    """The run properties of a run that failed: its time, OMPL's status index and not solved."""
    return {"time REAL": elapsed, "status ENUM": STATUS_INDEX[status], "solved BOOLEAN": 0}


def _record(
    task: RunTask,
    status: str,
    properties: dict[str, Any],
    params: dict[str, str] | None = None,
    error: str = "",
    sampler: ProgressSampler | None = None,
) -> Record:
    record: Record = {
        "problem": task.problem.name,
        "planner": task.planner.label,
        "run": task.run,
        "seed": task.seed,
        "definition": task.definition,
        "status": status,
        "properties": properties,
        "params": params or {},
        "error": error,
    }
    if sampler is not None and len(sampler.names) > 1:
        record["progress"] = {"properties": sampler.names, "samples": sampler.samples}
    return record


def _child(task: RunTask, connection: Any) -> None:
    """Entry point of a run's process: limits, run, send the record (or the traceback)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C stops the sweep, which ends its runs
    ou.setLogLevel(ou.LOG_ERROR)
    try:
        connection.send(execute(task))
    except BaseException:
        connection.send(_record(task, "CRASH", failure_properties("CRASH", 0.0), error=traceback.format_exc(limit=-3)))


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


# -- around the run's process -----------------------------------------------------------

# "__main__" too: a run's process then need not re-import the main script (spawn semantics)
_PRELOAD = ["__main__", "ompl_balance.bench.runner", "ompl_balance.core.scans"]
_ROBOT_PRELOAD = [
    "ompl_balance.worlds.mbm",
    "ompl_balance.collision.robots",
    "ompl_balance.validity",
    "ompl_balance.collision.warm_kernels",
    "ompl_balance.bench.preload_mbm",
]


def preload_modules(experiment: Experiment) -> list[str]:
    """Modules the forkserver imports once: the runner, and the robot layer for MotionBenchMaker problems."""
    return _PRELOAD + (_ROBOT_PRELOAD if any(p.kind == "mbm" for p in experiment.problems) else [])


_FORKSERVER_LOCK = threading.Lock()


def _context(preload: list[str]) -> Any:
    """The forkserver context, its server started without the current folder on its ``sys.path``.

    Python starts the forkserver with ``python -c``, which puts the current folder first on
    its ``sys.path``: started from a folder holding another copy of ``ompl_balance`` (a
    source checkout), the forkserver would import that copy and every run forked from it
    would execute it. ``PYTHONSAFEPATH`` (Python 3.11 and later) tells it not to, so it
    imports the package this interpreter imports. (On Python 3.10, start sweeps from a
    folder that holds no other copy of the package.)
    """
    context = multiprocessing.get_context("forkserver")
    with _FORKSERVER_LOCK:
        context.set_forkserver_preload(preload)  # takes effect when the forkserver starts
        saved = os.environ.get("PYTHONSAFEPATH")
        os.environ["PYTHONSAFEPATH"] = "1"
        try:
            forkserver.ensure_running()  # starts it once per process (again if it died)
        finally:
            if saved is None:
                del os.environ["PYTHONSAFEPATH"]
            else:
                os.environ["PYTHONSAFEPATH"] = saved
    return context


def failure_record(task: RunTask, status: str, elapsed: float, error: str) -> Record:
    """The record of a run whose process died or had to be killed (OMPL's ``CRASH`` status)."""
    return _record(task, status, failure_properties(status, elapsed), error=error)


#: Run processes in flight by run, so that an interrupted sweep can end its own.
_RUNNING: dict[tuple[str, str, int], Any] = {}


def run_isolated(task: RunTask, preload: list[str] | None = None) -> Record:
    """Execute ``task`` in a fresh process, killed after ``task.hard_limit`` seconds.

    Always returns a record: the run's own, or ``CRASH`` when the process died (signal or
    exit code in ``error``) or was killed at the hard limit: the planner ignored its
    termination condition, which OMPL's Benchmark also recorded as a crash.
    """
    if multiprocessing.current_process().daemon:
        raise RuntimeError(
            "runs start their own process, which a daemonic process may not: start Dask workers with "
            "DASK_DISTRIBUTED__WORKER__DAEMON=False (or --no-nanny)"
        )
    context = _context(preload or _PRELOAD)
    receiver, sender = context.Pipe(duplex=False)
    process = context.Process(target=_child, args=(task, sender), name=f"run {task.key}")
    began = time.perf_counter()
    process.start()
    _RUNNING[task.key] = process
    sender.close()
    try:
        if receiver.poll(task.hard_limit):
            try:
                record: Record = receiver.recv()
                return record
            except EOFError:  # the process died without a word
                process.join(1.0)
                return failure_record(task, "CRASH", time.perf_counter() - began, _exit_text(process.exitcode))
        return failure_record(
            task,
            "CRASH",
            time.perf_counter() - began,
            f"killed after the hard limit of {task.hard_limit:g} s (the planner ignored its termination condition)",
        )
    finally:
        receiver.close()
        if process.is_alive():
            process.kill()
        process.join()
        _RUNNING.pop(task.key, None)


def _stop_runs(keys: Iterable[tuple[str, str, int]]) -> None:
    """Kill the processes of the runs ``keys`` that are in flight (an interrupted sweep)."""
    for key in keys:
        process = _RUNNING.get(key)
        if process is not None and process.is_alive():
            process.kill()


def _exit_text(exitcode: int | None) -> str:
    if exitcode is not None and exitcode < 0:
        return f"the run's process was killed by {signal.Signals(-exitcode).name}"
    return f"the run's process exited with code {exitcode} before reporting"


# -- the results file -------------------------------------------------------------------


class ResultStore:
    """``results.jsonl``: one JSON record per finished run, appended and flushed at once.

    A line cut short by a killed process is ignored when reading (and the next record
    starts on a fresh line).
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path).absolute()

    def records(self) -> list[Record]:
        if not self.path.exists():
            return []
        records = []
        for line in self.path.read_text().splitlines():
            try:
                records.append(json.loads(line))
            except json.JSONDecodeError:
                continue  # the tail of an interrupted write
        return records

    def finished(self) -> set[tuple[tuple[str, str, int], str]]:
        """``(key, definition)`` of every recorded run."""
        return {((r["problem"], r["planner"], r["run"]), r.get("definition", "")) for r in self.records()}

    def append(self, record: Record) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with self.path.open("a+") as file:
            file.seek(0, os.SEEK_END)
            if file.tell() > 0:
                file.seek(file.tell() - 1)
                if file.read(1) != "\n":
                    file.write("\n")
            file.write(json.dumps(record) + "\n")
            file.flush()
            os.fsync(file.fileno())


# -- sweeps -----------------------------------------------------------------------------


@dataclass
class Progress:
    """Counts of one sweep so far: runs recorded, of which unsolved, of which crashed or killed."""

    done: int = 0
    unsolved: int = 0
    crashed: int = 0


def _local(tasks: list[RunTask], preload: list[str], jobs: int) -> Iterator[Record]:
    """Records as runs finish, ``jobs`` run processes at a time (threads only wait for them)."""
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        pending: dict[Future, RunTask] = {}
        queue = iter(tasks)
        try:
            for task in queue:
                pending[pool.submit(run_isolated, task, preload)] = task
                if len(pending) >= jobs:
                    break
            while pending:
                finished, _ = wait(pending, return_when=FIRST_COMPLETED)
                for future in finished:
                    del pending[future]
                    following = next(queue, None)
                    if following is not None:
                        pending[pool.submit(run_isolated, following, preload)] = following
                    yield future.result()
        finally:  # interrupted (or done, then nothing is pending): end the runs in flight
            for future in pending:
                future.cancel()
            _stop_runs(task.key for task in pending.values())


DASK_MISSING = "--dask needs Dask's distributed scheduler: pip install 'ompl-balance[distributed]'"


def require_dask() -> None:
    """:class:`MissingExtraError` saying how to install Dask when ``dask.distributed`` cannot be imported."""
    try:
        import dask.distributed  # noqa: F401
    except ImportError as error:
        raise MissingExtraError(DASK_MISSING) from error


def dask_client(address: str) -> Any:
    """A ``dask.distributed.Client`` for ``"tcp://host:port"``, or a loopback ``LocalCluster`` for ``"local:N"``."""
    require_dask()
    import dask
    from dask.distributed import Client, LocalCluster

    if address.startswith("local:"):
        workers = int(address.partition(":")[2])
        with dask.config.set({"distributed.worker.daemon": False}):  # workers start run processes
            cluster = LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
            )
        return Client(cluster)
    return Client(address)


def _distributed(tasks: list[RunTask], preload: list[str], address: str) -> Iterator[Record]:
    """Records as runs finish on a Dask cluster; each task runs :func:`run_isolated` in a worker."""
    from dask.distributed import as_completed

    client = dask_client(address)
    try:
        futures = {client.submit(run_isolated, task, preload, pure=False): task for task in tasks}
        for future in as_completed(futures):
            try:
                yield future.result()
            except Exception as error:
                yield failure_record(futures[future], "CRASH", float("nan"), f"{type(error).__name__}: {error}")
    finally:
        cluster = getattr(client, "cluster", None)
        client.close()
        if cluster is not None:
            cluster.close()


def sweep(
    experiment: Experiment,
    store: ResultStore,
    jobs: int = 1,
    dask: str | None = None,
    on_record: Callable[[Record, Progress], None] | None = None,
) -> Progress:
    """Execute every run of ``experiment`` not yet in ``store``, appending each record as it arrives.

    Returns the counts of this sweep. Interrupting it (Ctrl-C) loses only the runs in
    flight; starting it again runs what is missing.
    """
    if jobs < 1:
        raise ValueError(f"jobs must be >= 1, got {jobs}")
    finished = store.finished()
    tasks = [task for task in experiment.tasks() if (task.key, task.definition) not in finished]
    preload = preload_modules(experiment)
    records: Iterable[Record] = _distributed(tasks, preload, dask) if dask else _local(tasks, preload, jobs)
    progress = Progress()
    for record in records:
        store.append(record)
        progress.done += 1
        progress.unsolved += not record["properties"].get("solved BOOLEAN", 0)
        progress.crashed += bool(record["error"])
        if on_record is not None:
            on_record(record, progress)
    return progress
