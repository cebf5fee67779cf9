"""Executing runs: one process per run, hard wall-clock caps, results appended as they finish.

Every run executes in a fresh process forked from a ``forkserver`` that has imported
OMPL and this package once (a few milliseconds per run, not a new interpreter). The
fresh process matters twice: OMPL's global ``RNG.setSeed`` only works before the first
random number of a process, so each run seeds it with its own seed
(:func:`~ompl_balance.bench.experiment.run_seed`) and stock planners repeat too; and a run
that segfaults, aborts or ignores its time limit takes only its own process down. The
parent waits at most ``task.hard_limit`` seconds (2 x the time limit + a margin:
planning, then simplification bounded by the time limit) and records ``CRASH`` or
``TIMEOUT`` for a process that died or had to be killed.

Results go to ``results.jsonl`` in the output folder, one JSON record per run, written
and flushed as each run finishes (:class:`ResultStore`); runs already there are skipped
when the same sweep is started again, so an interrupted sweep resumes where it stopped.

Runs execute serially, on a local pool of ``jobs`` concurrent processes, or on a Dask
distributed cluster (``dask="tcp://host:port"`` or ``"local:N"``, extra ``distributed``);
each Dask task starts its run's process inside the worker, so the results are the same.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import resource
import signal
import time
import traceback
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ompl import base as ob
from ompl import util as ou

from ..core.counting import measured_solve
from .experiment import Experiment, RunTask, planner_params

#: OMPL's planner status names -> the index the OMPL log's ``status`` enum uses.
STATUS_INDEX = {
    name: member.value
    for name, member in ob.PlannerStatus.PlannerStatusType.__members__.items()
    if name != "TYPE_COUNT"
}

Record = dict[str, Any]


# -- inside the run's process -----------------------------------------------------------


def _typed(name: str, value: Any) -> tuple[str, Any]:
    """An OMPL log property ``"name TYPE"`` for a Python value (bool -> BOOLEAN 0/1)."""
    if isinstance(value, bool):
        return f"{name} BOOLEAN", int(value)
    if isinstance(value, int):
        return f"{name} INTEGER", value
    return f"{name} REAL", float(value)


def _graph_properties(ss, planner: ob.Planner) -> dict[str, Any]:
    """Graph states and motions; start/goal tree sizes from vertex tags 1/2 for the RRT-Connect family."""
    if hasattr(planner, "plannerData"):
        data = planner.plannerData()
    else:
        data = ob.PlannerData(ss.getSpaceInformation())
        planner.getPlannerData(data)
    properties = dict([_typed("graph states", data.numVertices()), _typed("graph motions", data.numEdges())])
    if "RRTConnect" in type(planner).__name__:  # stock og.RRTConnect tags its trees like ours
        tags = [data.getVertex(i).getTag() for i in range(data.numVertices())]
        properties.update([_typed("start tree size", tags.count(1)), _typed("goal tree size", tags.count(2))])
    return properties


def execute(task: RunTask) -> Record:
    """Run ``task`` in this process and return its record (call in a fresh process: it seeds OMPL).

    Properties (OMPL log names and types): time, memory, status, solved, approximate
    solution, solution length and segments, simplification time, simplified solution
    length and segments, graph states and motions, validity checks, motion checks, and
    every numeric field of the planner's ``stats`` (iterations, start/goal tree size,
    tree swaps, sampler checks, ... for this package's planners).
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
    run = measured_solve(ss, task.time_limit)
    status_name = _status_name(run.status)
    properties: dict[str, Any] = {
        "time REAL": run.time,
        "status ENUM": STATUS_INDEX[status_name],
        "solved BOOLEAN": int(run.solved),
        "validity checks INTEGER": run.work.states_checked,
        "motion checks INTEGER": run.work.motions_checked,
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
            if name not in ("status", "time", "states_checked", "motions_checked") and isinstance(value, (int, float)):
                properties.update([_typed(name.replace("_", " "), value)])
    properties["memory REAL"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # MB, peak of the process
    params = planner_params(planner)
    if run_seeded:
        params["seed"] = "run"  # each run's own seed (the run property "seed")
    return _record(task, status_name, properties, params=params)


def _status_name(status: ob.PlannerStatus) -> str:
    """The ``PlannerStatusType`` member name of a ``PlannerStatus`` (``"EXACT_SOLUTION"``, ...)."""
    for name, member in ob.PlannerStatus.PlannerStatusType.__members__.items():
        if status == member:
            return name
    return "UNKNOWN"


def _record(
    task: RunTask, status: str, properties: dict[str, Any], params: dict[str, str] | None = None, error: str = ""
) -> Record:
    return {
        "problem": task.problem.name,
        "planner": task.planner.label,
        "run": task.run,
        "seed": task.seed,
        "status": status,
        "properties": properties,
        "params": params or {},
        "error": error,
    }


def _child(task: RunTask, connection) -> None:
    """Entry point of a run's process: limits, run, send the record (or the traceback)."""
    if task.memory_limit > 0:
        limit = int(task.memory_limit * 1024 * 1024)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    ou.setLogLevel(ou.LOG_ERROR)
    try:
        connection.send(execute(task))
    except BaseException:
        connection.send(_record(task, "CRASH", {}, error=traceback.format_exc(limit=-3)))


# -- around the run's process -----------------------------------------------------------

# "__main__" too: a run's process then need not re-import the main script (spawn semantics)
_PRELOAD = ["__main__", "ompl_balance.bench.runner", "ompl_balance.core.scans"]
_ROBOT_PRELOAD = [
    "ompl_balance.worlds.mbm",
    "ompl_balance.collision.robots",
    "ompl_balance.validity",
    "ompl_balance.collision.warm_kernels",
]


def preload_modules(experiment: Experiment) -> list[str]:
    """Modules the forkserver imports once: the runner, and the robot layer for MotionBenchMaker problems."""
    return _PRELOAD + (_ROBOT_PRELOAD if any(p.kind == "mbm" for p in experiment.problems) else [])


def _context(preload: list[str]):
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(preload)  # takes effect when the forkserver starts (first run)
    return context


def failure_record(task: RunTask, status: str, elapsed: float, error: str) -> Record:
    """The record of a run whose process crashed (``CRASH``) or was killed at its hard limit (``TIMEOUT``)."""
    return _record(
        task, status, {"time REAL": elapsed, "status ENUM": STATUS_INDEX[status], "solved BOOLEAN": 0}, error=error
    )


def run_isolated(task: RunTask, preload: list[str] | None = None) -> Record:
    """Execute ``task`` in a fresh process, killed after ``task.hard_limit`` seconds.

    Always returns a record: the run's own, or ``CRASH`` (the process died: signal or
    exit code in ``error``) or ``TIMEOUT`` (killed at the hard limit).
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
    sender.close()
    try:
        if receiver.poll(task.hard_limit):
            try:
                return receiver.recv()
            except EOFError:  # the process died without a word
                process.join(1.0)
                return failure_record(task, "CRASH", time.perf_counter() - began, _exit_text(process.exitcode))
        return failure_record(
            task, "TIMEOUT", time.perf_counter() - began, f"killed after the hard limit of {task.hard_limit:g} s"
        )
    finally:
        receiver.close()
        if process.is_alive():
            process.kill()
        process.join()


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
        self.path = Path(path)

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

    def finished(self) -> set[tuple[str, str, int]]:
        return {(r["problem"], r["planner"], r["run"]) for r in self.records()}

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
        pending: set[Future] = set()
        queue = iter(tasks)
        try:
            for task in queue:
                pending.add(pool.submit(run_isolated, task, preload))
                if len(pending) >= jobs:
                    break
            while pending:
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for future in finished:
                    task = next(queue, None)
                    if task is not None:
                        pending.add(pool.submit(run_isolated, task, preload))
                    yield future.result()
        finally:
            for future in pending:
                future.cancel()


def dask_client(address: str):
    """A ``dask.distributed.Client`` for ``"tcp://host:port"``, or a loopback ``LocalCluster`` for ``"local:N"``."""
    try:
        import dask
        from dask.distributed import Client, LocalCluster
    except ImportError as error:
        raise ImportError("--dask needs dask.distributed: pip install 'ompl-balance[distributed]'") from error
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
    tasks = [task for task in experiment.tasks() if task.key not in finished]
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
