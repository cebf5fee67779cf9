"""Benchmarks: run an experiment into an output folder; ``compare`` is a ready-made experiment.

:func:`bench` executes an :class:`~ompl_balance.bench.experiment.Experiment` (each run in its
own process, see :mod:`ompl_balance.bench.isolation`) and keeps everything in one folder::

    OUT/experiment.json     the experiment and the package versions its runs execute with
    OUT/results.jsonl       one record per finished run, appended as runs finish
    OUT/logs/*.log          one OMPL benchmark log per problem (logs.write_logs)
    OUT/benchmark.db        the logs converted by OMPL's own converter, with its views
    OUT/summary.md, .csv    success; medians of the solved runs, 95 % intervals, ratios to the baseline planner
    OUT/superseded/         what earlier definitions produced: their runs (results.jsonl), logs

Running the same experiment into the folder again runs only what is missing; runs of a
cell whose definition changed (parameters, problem, limits, seed, versions) run again
(:mod:`ompl_balance.bench.resume`). The logs, database and summary are rewritten from the
experiment's records at the end of every sweep, interrupted or not.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from tqdm import tqdm

from ..worlds.boxes import PROBLEMS
from .experiment import Experiment, PlannerSpec
from .logs import to_database, write_logs
from .problems import problem_by_name
from .results import Record, ResultStore
from .resume import RESULTS_FILE, SUPERSEDED, claim, experiment_records, supersede_files
from .scheduling import SweepCounts, missing_tasks, prepare_local_runs, sweep
from .summary import format_csv, format_markdown, summarize

STOCK_LABEL = "RRTConnect"

#: The experiment seed of ``compare`` unless ``--seed`` says otherwise (the same command
#: makes the same runs, so running it again into its folder resumes).
COMPARE_SEED = 1

#: The MotionBenchMaker problems ``compare`` runs by default: problem 1 of each shipped Panda scenario.
COMPARE_MBM_PROBLEMS = ("table_pick.001", "table_under_pick.001", "box.001", "bookshelf_small.001")

#: The rigid-body problems ``compare`` runs by default: one in the plane, one in space.
COMPARE_RIGID_PROBLEMS = ("se2_bugtrap", "se3_room")


def default_planners() -> list[PlannerSpec]:
    """Stock ``og.RRTConnect`` (the baseline) and ``BalancedRRTConnect`` with balancing on and off."""
    return [
        PlannerSpec(STOCK_LABEL, STOCK_LABEL),
        PlannerSpec("BalancedRRTConnect", "BalancedRRTConnect"),
        PlannerSpec(
            "BalancedRRTConnect[balance_tree_sizes=0]", "BalancedRRTConnect", params={"balance_tree_sizes": "0"}
        ),
    ]


def parse_planners(text: str) -> list[PlannerSpec]:
    """Planners from ``"RRTConnect,BalancedRRTConnect[max_tree_size_ratio=0.5;range=0.1]"``.

    Each item is a planner or preset name, optionally with ``[name=value;...]`` parameter
    overrides (``;`` or ``,`` between them); the item as written is its label.
    ``ValueError`` saying what could not be read.
    """
    specs = []
    for item in (part.strip() for part in re.split(r",(?![^\[]*\])", text)):
        match = re.fullmatch(r"([A-Za-z_][\w.]*)(?:\[(.*)\])?", item)
        if not match:
            raise ValueError(f"cannot read planner {item!r}; write NAME or NAME[param=value;...]")
        params: dict[str, str] = {}
        for pair in filter(None, (pair.strip() for pair in re.split(r"[;,]", match.group(2) or ""))):
            name, equals, value = (part.strip() for part in pair.partition("="))
            if not equals or not name:
                raise ValueError(f"cannot read parameter {pair!r} of {item!r}; write NAME[param=value;...]")
            if name in params:
                raise ValueError(f"parameter {name!r} is given twice in {item!r}")
            params[name] = value
        specs.append(PlannerSpec(item, match.group(1), params=params))
    return specs


def compare_experiment(
    problems: Sequence[str] = (*PROBLEMS, *COMPARE_MBM_PROBLEMS, *COMPARE_RIGID_PROBLEMS),
    planners: Sequence[PlannerSpec] | None = None,
    runs: int = 20,
    time_limit: float = 5.0,
    seed: int = COMPARE_SEED,
    warm_up: bool = True,
) -> Experiment:
    """The ``ompl-balance compare`` experiment: the built-in 2-D problems, problem 1 of each
    MotionBenchMaker Panda scenario and two shipped rigid-body problems, stock RRTConnect as the
    baseline."""
    planners = list(planners or default_planners())
    return Experiment(
        name="compare",
        problems=tuple(problem_by_name(name) for name in problems),
        planners=tuple(planners),
        runs=runs,
        time_limit=time_limit,
        seed=seed,
        baseline=STOCK_LABEL if any(p.label == STOCK_LABEL for p in planners) else "",
        warm_up=warm_up,
    )


def write_outputs(experiment: Experiment, records: Sequence[Record], out: Path) -> str:
    """Logs, database and summary from ``records`` (files of earlier definitions go to ``superseded/``);
    returns the markdown summary."""
    logs = write_logs(experiment, records, out / "logs")
    supersede_files(out, "logs", logs)
    database = out / "benchmark.db"
    if logs:
        to_database(logs, database)
    elif database.exists():  # no run counts yet: the database of an earlier definition goes
        (out / SUPERSEDED).mkdir(exist_ok=True)
        database.replace(out / SUPERSEDED / database.name)
    summaries = summarize(records, experiment.baseline_label, [p.label for p in experiment.planners])
    table = format_markdown(summaries, experiment.baseline_label)
    (out / "summary.md").write_text(table + "\n")
    (out / "summary.csv").write_text(format_csv(summaries))
    return table


def _to_stderr(message: str) -> None:
    print(message, file=sys.stderr)


def bench(
    experiment: Experiment,
    out: str | Path,
    jobs: int = 1,
    dask: str | None = None,
    progress: bool = True,
    notify: Callable[[str], None] = _to_stderr,
) -> list[Record]:
    """Run what is missing of ``experiment`` into ``out`` and write the logs, database and summary.

    ``jobs`` runs at a time on this machine, or on the Dask cluster ``dask``. Runs the
    folder holds under another definition of their cell are superseded and run again;
    ``notify`` receives the notice saying so, and a warning when ``jobs`` exceeds the
    machine's cores (the runs' timings then compete for them). Returns the experiment's records (all of
    them, earlier sweeps' included). :class:`~ompl_balance.bench.errors.ExperimentError` when
    ``out`` cannot be this experiment's folder (see :func:`~ompl_balance.bench.resume.claim`).

    The progress bar starts once the local runs' forkserver is ready (it imports the package
    and compiles or loads its kernels once), so its estimate counts runs only.
    """
    out = Path(out)
    claimed = claim(out, experiment)
    if claimed.superseded:
        notify(claimed.message(out))
    store = ResultStore(out / RESULTS_FILE)
    if dask is None and missing_tasks(experiment, store):
        cores = os.cpu_count() or 1
        if jobs > cores:
            notify(
                f"warning: --jobs {jobs} is more than this machine's {cores} core{'s' * (cores > 1)}: the runs' timings then compete "
                f"for cores and come out longer than alone (validity checks stay exact); --jobs {cores} or fewer "
                "times them fairly"
            )
        prepare_local_runs(experiment)
    bar = tqdm(
        total=len(experiment.tasks()),
        initial=claimed.kept,
        disable=not progress,
        unit="run",
        smoothing=0.1,
        dynamic_ncols=True,
    )

    def show(record: Record, counts: SweepCounts) -> None:
        bar.update(1)
        bar.set_postfix(unsolved=counts.unsolved, crashed=counts.crashed, refresh=False)

    try:
        sweep(experiment, store, jobs=jobs, dask=dask, on_record=show)
    finally:
        bar.close()
        records = experiment_records(experiment, store)
        write_outputs(experiment, records, out)
    return records
