"""Sweeps: an experiment's missing runs scheduled on this machine or on a Dask cluster.

Runs execute on a local pool of ``jobs`` concurrent run processes, or on a Dask distributed
cluster (``dask="tcp://host:port"`` or ``"local:N"``, extra ``distributed``); each Dask task
starts its run's process inside the worker (:func:`~ompl_balance.bench.isolation.run_isolated`),
so the results are the same. Records go to the results file as they arrive, so an
interrupted sweep resumes where it stopped.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass
from typing import Any

from .errors import ClusterError, MissingExtraError
from .experiment import Experiment, RunTask
from .isolation import preload_modules, run_isolated, start_forkserver, stop_runs
from .results import Record, ResultStore, failure_record


@dataclass
class SweepCounts:
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
            stop_runs(task.key for task in pending.values())


DASK_MISSING = "--dask needs Dask's distributed scheduler: pip install 'ompl-balance[distributed]'"


def require_dask() -> None:
    """:class:`MissingExtraError` saying how to install Dask when ``dask.distributed`` cannot be imported."""
    try:
        import dask.distributed  # noqa: F401
    except ImportError as error:
        raise MissingExtraError(DASK_MISSING) from error


#: Seconds a Dask scheduler at ``tcp://host:port`` has to answer before the sweep gives up.
DASK_CONNECT_TIMEOUT = 5.0


def dask_client(address: str) -> Any:
    """A ``dask.distributed.Client`` for ``"tcp://host:port"``, or a loopback ``LocalCluster`` for ``"local:N"``.

    :class:`~ompl_balance.bench.errors.ClusterError` when no scheduler at ``address`` answers
    within :data:`DASK_CONNECT_TIMEOUT` seconds.
    """
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
    try:
        return Client(address, timeout=DASK_CONNECT_TIMEOUT)
    except OSError as error:
        raise ClusterError(
            f"--dask {address}: no Dask scheduler answered within {DASK_CONNECT_TIMEOUT:g} s (a dask.distributed "
            f"Client tried to connect); start one there with 'dask scheduler' and its workers with "
            f"'dask worker {address}', or run on this machine with --dask local:N or --jobs N"
        ) from error


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


def missing_tasks(experiment: Experiment, store: ResultStore) -> list[RunTask]:
    """The runs of ``experiment`` that ``store`` does not hold under their cell's definition."""
    finished = store.finished()
    return [task for task in experiment.tasks() if (task.key, task.definition) not in finished]


def prepare_local_runs(experiment: Experiment) -> None:
    """Start the forkserver of ``experiment``'s local runs and wait until it can fork them (it
    imports the package and compiles or loads its kernels once), so that a sweep's clock and
    progress estimate start with the runs."""
    start_forkserver(preload_modules(experiment))


def sweep(
    experiment: Experiment,
    store: ResultStore,
    jobs: int = 1,
    dask: str | None = None,
    on_record: Callable[[Record, SweepCounts], None] | None = None,
) -> SweepCounts:
    """Execute every run of ``experiment`` not yet in ``store``, appending each record as it arrives.

    Returns the counts of this sweep. Interrupting it (Ctrl-C) loses only the runs in
    flight; starting it again runs what is missing.
    """
    if jobs < 1:
        raise ValueError(f"jobs must be >= 1, got {jobs}")
    tasks = missing_tasks(experiment, store)
    preload = preload_modules(experiment)
    records: Iterable[Record] = _distributed(tasks, preload, dask) if dask else _local(tasks, preload, jobs)
    counts = SweepCounts()
    for record in records:
        store.append(record)
        counts.done += 1
        counts.unsolved += not record["properties"].get("solved BOOLEAN", 0)
        counts.crashed += bool(record["error"])
        if on_record is not None:
            on_record(record, counts)
    return counts
