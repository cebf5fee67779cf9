"""Each run in a fresh process: the forkserver, the hard wall-clock cap, what a lost run's record says.

Every run executes in a fresh process forked from a ``forkserver`` that has imported OMPL
and this package once (a few milliseconds per run, not a new interpreter). The fresh
process matters twice: OMPL's global ``RNG.setSeed`` seeds only the random generators made
after it, so each run seeds it with its own seed
(:func:`~ompl_balance.bench.experiment.run_seed`) before it builds anything, and stock
planners repeat too, their generators made in the run's process alone; and a run
that segfaults, aborts or ignores its time limit takes only its own process down. The
parent gives the run ``task.hard_limit`` seconds (2 x the time limit + a margin: planning,
then simplification bounded by the time limit), not counting the wait for a planner's compiled
engine (the ``"engine"`` phase: numba compiles it on a first use after installing, which is
no fault of the run; it has :data:`ENGINE_LIMIT` seconds of its own). It records OMPL's
``CRASH`` status for a process that died or had to be killed, saying in which phase of the run
(:data:`~ompl_balance.bench.execution.PHASES`), except a run killed while simplifying its
solution: that run's record is its solve's, with a note that simplification overran. A planner
that did not return from its solve is then solved once more in a plain ``ss.solve(time_limit)``
in a process of its own (no warm-up, no progress or memory thread), and the record says whether
that returned: whether the planner hangs (or dies) by itself or only under the benchmark.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
import time
import traceback
from collections.abc import Iterable
from multiprocessing import forkserver
from typing import Any

from ompl import util as ou

from .execution import KEEP_UNTIL_EXIT, WARM_UP_TIME, execute
from .experiment import Experiment, RunTask
from .first_compile import compile_in_parallel
from .problems import PROBLEM_KINDS
from .results import Record, failure_properties, failure_record, run_record

#: Seconds a run may wait for a planner's compiled engine (numba compiling every kernel once after
#: installing took about four minutes on a loaded 2-core machine), apart from its hard limit.
ENGINE_LIMIT = 900.0

# "__main__" too: a run's process then need not re-import the main script (spawn semantics)
_PRELOAD = ["__main__", "ompl_balance.bench.preload_runs"]


def preload_modules(experiment: Experiment) -> list[str]:
    """Modules the forkserver imports once: the runner's, and those of the experiment's kinds of problem."""
    kinds = dict.fromkeys(problem.kind for problem in experiment.problems)
    return _PRELOAD + list(dict.fromkeys(module for kind in kinds for module in PROBLEM_KINDS[kind].preload))


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


def _nothing() -> None:
    """A process that only starts and ends."""


def start_forkserver(preload: list[str]) -> None:
    """Start the forkserver and wait until it can fork runs: it has imported ``preload``, and
    numba has compiled or loaded the kernels they warm (the first time after installing, the
    forkserver says on standard error that it compiles; see ``preload_robots``), in parallel
    processes the first time (:func:`~ompl_balance.bench.first_compile.compile_in_parallel`)."""
    compile_in_parallel(preload)
    process = _context(preload).Process(target=_nothing, name="forkserver ready")
    process.start()
    process.join()


def _child(task: RunTask, connection: Any) -> None:
    """Entry point of a run's process: run, reporting each phase, then send the record (or the traceback)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C stops the sweep, which ends its runs
    ou.setLogLevel(ou.LogLevel.LOG_ERROR)

    def phase(name: str, record: Record | None) -> None:
        connection.send((name, record))

    try:
        connection.send(execute(task, phase=phase))
    except BaseException:
        connection.send(
            run_record(task, "CRASH", failure_properties("CRASH", 0.0), error=traceback.format_exc(limit=-3))
        )


def _plain_child(task: RunTask, connection: Any) -> None:
    """Entry point of a plain solve's process: ``ss.solve(time_limit)`` as a user calls it; sends its seconds."""
    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    ou.RNG.setSeed(task.seed)
    ss = task.problem.build()
    ss.setPlanner(task.planner.build(ss.getSpaceInformation()))
    KEEP_UNTIL_EXIT.append(ss)
    began = time.perf_counter()
    ss.solve(task.time_limit)
    connection.send(time.perf_counter() - began)


#: What the plain solves of a cell did, by cell definition (see plain_solve).
_PLAIN_SOLVES: dict[str, str] = {}
_PLAIN_LOCK = threading.Lock()
#: Plain solves tried before a run that did not return is put down to the benchmark: a planner
#: may hang in some solves and return in others of the same seed (OMPL 2.0.1's SORRTstar on the
#: open square), and one plain solve that returned would blame the benchmark for the planner.
PLAIN_TRIES = 3


def plain_solve(task: RunTask) -> str:
    """What a plain ``ss.solve(task.time_limit)`` of ``task``'s problem and planner does in a fresh
    process (no warm-up, no progress or memory thread), each waited for ``task.hard_limit``
    seconds, tried up to :data:`PLAIN_TRIES` times until one does not return or dies:
    ``"returns in 0.51 s (each of 3 tries)"`` (the slowest), ``"does not return"`` or
    ``"ends its process (... killed by SIGSEGV)"``. Found once per cell and sweep process."""
    with _PLAIN_LOCK:
        if task.definition in _PLAIN_SOLVES:
            return _PLAIN_SOLVES[task.definition]
    slowest = 0.0
    for _ in range(PLAIN_TRIES):
        seconds = plain_solve_once(task)
        if isinstance(seconds, str):
            outcome = seconds
            break
        slowest = max(slowest, seconds)
    else:
        outcome = f"returns in {slowest:.2f} s (each of {PLAIN_TRIES} tries)"
    with _PLAIN_LOCK:
        _PLAIN_SOLVES[task.definition] = outcome
    return outcome


def plain_solve_once(task: RunTask) -> float | str:
    """One plain solve of ``task`` (see :func:`plain_solve`): its seconds, or what happened instead
    (``"does not return"``, ``"ends its process (...)"``)."""
    context = _context(_PRELOAD)
    receiver, sender = context.Pipe(duplex=False)
    process = context.Process(target=_plain_child, args=(task, sender), name=f"plain solve {task.key}")
    process.start()
    sender.close()
    try:
        outcome: float | str = float(receiver.recv()) if receiver.poll(task.hard_limit) else "does not return"
    except EOFError:  # the process died before it could report
        process.join(1.0)
        outcome = f"ends its process ({_exit_text(process.exitcode)})"
    finally:
        receiver.close()
        if process.is_alive():
            process.kill()
        process.join()
    return outcome


_PHASE_WORDS = {
    None: "while building its problem and planner",
    "engine": "while loading its compiled engine",
    "warm-up": "in the untimed warm-up solve",
    "solve": "in the timed solve",
    "simplification": "in the path simplification",
}


def _not_returned(task: RunTask, phase: str | None, phase_began: float, killed: float) -> str:
    """What happened to a run killed at its hard limit, in words, from the phase it was in."""
    planner = task.planner.name or task.planner.label
    kill = (
        f"the process was killed {killed - phase_began:.1f} s after it began, at the run's hard limit of "
        f"{task.hard_limit:g} s (2 x the time limit + the margin)"
    )
    if phase is None:
        return f"the run did not get to planning ({_PHASE_WORDS[None]}); {kill}"
    if phase == "engine":
        return (
            f"{planner}'s compiled engine was not ready after {killed - phase_began:.0f} s "
            f"(the limit of {ENGINE_LIMIT:g} s for loading or compiling it); the process was killed"
        )
    if phase == "warm-up":
        ended = (
            "the untimed warm-up solve, which its termination condition ended after at most "
            f"{min(WARM_UP_TIME, task.time_limit):g} s"
        )
    else:
        ended = f"the timed solve, which its termination condition ended at the time limit of {task.time_limit:g} s"
    check = f"a plain ss.solve({task.time_limit:g}) in a fresh process (no warm-up, no progress or memory thread)"
    plain = plain_solve(task)
    if plain.startswith("returns"):
        verdict = (
            f"{check} {plain}, so the benchmark kept it from returning: please report this as a bug of ompl-balance"
        )
    else:
        how = "hangs" if plain == "does not return" else "fails"
        verdict = f"{check} {plain} either: the planner {how} by itself, not under the benchmark"
    return f"{planner} did not return from {ended}; {kill}; {verdict}"


#: Run processes in flight by run, so that an interrupted sweep can end its own.
_RUNNING: dict[tuple[str, str, int], Any] = {}


def run_isolated(task: RunTask, preload: list[str] | None = None) -> Record:
    """Execute ``task`` in a fresh process, killed after ``task.hard_limit`` seconds.

    Always returns a record: the run's own, or ``CRASH`` when the process died (signal or
    exit code and the phase in ``error``) or was killed at the hard limit (what did not
    return, and whether it returns outside the benchmark, in ``error``; OMPL's Benchmark
    also recorded a planner that overran its time as a crash).
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
    clock = _RunClock(task.hard_limit, began)
    solved: Record | None = None  # the solve's record, once the run simplifies its solution
    try:
        while receiver.poll(max(0.0, clock.deadline() - time.perf_counter())):
            try:
                message = receiver.recv()
            except EOFError:  # the process died without a word
                process.join(1.0)
                return failure_record(
                    task,
                    "CRASH",
                    time.perf_counter() - began,
                    f"{_exit_text(process.exitcode)} {_PHASE_WORDS[clock.phase]}",
                )
            if isinstance(message, dict):
                return message
            phase, record = message
            clock.enter(phase, time.perf_counter())
            if record is not None:
                solved = record
        killed = time.perf_counter()
        if process.is_alive():
            process.kill()
        if clock.phase == "simplification" and solved is not None:
            return _simplification_overran(task, solved, killed - clock.phase_began)
        return failure_record(
            task, "CRASH", killed - began, _not_returned(task, clock.phase, clock.phase_began, killed)
        )
    finally:
        receiver.close()
        if process.is_alive():
            process.kill()
        process.join()
        _RUNNING.pop(task.key, None)


class _RunClock:
    """The deadline of a run's process: ``hard_limit`` seconds of its phases but the ``"engine"``
    phase, which has :data:`ENGINE_LIMIT` seconds of its own."""

    def __init__(self, hard_limit: float, began: float) -> None:
        self.phase: str | None = None
        self.phase_began = began
        self._left = hard_limit  # s of the hard limit not spent before the current phase

    def enter(self, phase: str, now: float) -> None:
        if self.phase != "engine":
            self._left -= now - self.phase_began
        self.phase, self.phase_began = phase, now

    def deadline(self) -> float:
        return self.phase_began + (ENGINE_LIMIT if self.phase == "engine" else self._left)


def _simplification_overran(task: RunTask, solved: Record, seconds: float) -> Record:
    """The record of a run killed while simplifying its solution: its solve's own record (the
    planner solved), with how long simplification ran and a note saying it did not return."""
    record = dict(solved)
    record["properties"] = {**solved["properties"], "simplification time REAL": seconds}
    record["note"] = (
        f"path simplification, bounded by the time limit of {task.time_limit:g} s, did not return within "
        f"the run's hard limit of {task.hard_limit:g} s (2 x the time limit + the margin) and was killed after "
        f"{seconds:.1f} s; the solve's results stand, the simplified path is not recorded"
    )
    return record


def stop_runs(keys: Iterable[tuple[str, str, int]]) -> None:
    """Kill the processes of the runs ``keys`` that are in flight (an interrupted sweep)."""
    for key in keys:
        process = _RUNNING.get(key)
        if process is not None and process.is_alive():
            process.kill()


def _exit_text(exitcode: int | None) -> str:
    if exitcode is not None and exitcode < 0:
        return f"the run's process was killed by {signal.Signals(-exitcode).name}"
    return f"the run's process exited with code {exitcode} before reporting"
