"""Benchmarks: run an experiment into an output folder; ``compare`` is a ready-made experiment.

:func:`bench` executes an :class:`~ompl_balance.bench.experiment.Experiment` (each run in its
own process, see :mod:`ompl_balance.bench.runner`) and keeps everything in one folder::

    OUT/experiment.json     the experiment (a later run of the same experiment resumes)
    OUT/results.jsonl       one record per finished run, appended as runs finish
    OUT/logs/*.log          one OMPL benchmark log per problem (ompl_log.write_logs)
    OUT/benchmark.db        the logs converted by OMPL's own converter
    OUT/summary.md, .csv    medians, 95 % intervals, ratios to the baseline planner

The logs, database and summary are rewritten from ``results.jsonl`` at the end of every
sweep, interrupted or not.
"""

from __future__ import annotations

import json
import random
import re
from collections.abc import Sequence
from pathlib import Path

from tqdm import tqdm

from ..worlds.boxes import PROBLEMS
from .experiment import Experiment, ExperimentError, PlannerSpec, ProblemSpec
from .logs import to_database, write_logs
from .runner import Progress, Record, ResultStore, sweep
from .summary import format_csv, format_markdown, summarize

STOCK_LABEL = "RRTConnect"


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

    Each item is a planner or preset name, optionally with ``[name=value;...]``
    parameter overrides; the item as written is its label.
    """
    specs = []
    for item in (part.strip() for part in re.split(r",(?![^\[]*\])", text)):
        match = re.fullmatch(r"([A-Za-z_][\w.]*)(?:\[(.*)\])?", item)
        if not match:
            raise ValueError(f"cannot read planner {item!r}; write NAME or NAME[param=value;...]")
        params = dict(pair.split("=", 1) for pair in filter(None, (match.group(2) or "").split(";")) if "=" in pair)
        specs.append(PlannerSpec(item, match.group(1), params=params))
    return specs


def compare_experiment(
    problems: Sequence[str] = tuple(PROBLEMS),
    planners: Sequence[PlannerSpec] | None = None,
    runs: int = 20,
    time_limit: float = 5.0,
    seed: int | None = None,
) -> Experiment:
    """The ``ompl-balance compare`` experiment: built-in problems, stock RRTConnect as the baseline.

    ``seed=None`` draws one (it is recorded in ``experiment.json`` and the logs).
    """
    planners = list(planners or default_planners())
    return Experiment(
        name="compare",
        problems=tuple(ProblemSpec(name, "builtin", name) for name in problems),
        planners=tuple(planners),
        runs=runs,
        time_limit=time_limit,
        seed=random.randrange(1, 2**31 - 1) if seed is None else seed,
        baseline=STOCK_LABEL if any(p.label == STOCK_LABEL for p in planners) else "",
    )


def _claim(out: Path, experiment: Experiment) -> None:
    """Record ``experiment`` in ``out``; refuse a folder holding results of a different experiment."""
    path = out / "experiment.json"
    if path.exists() and (out / "results.jsonl").exists():
        previous = Experiment.from_dict(json.loads(path.read_text()))
        mine, theirs = experiment.results_identity(), previous.results_identity()
        differing = sorted(key for key in mine if mine[key] != theirs.get(key))
        if differing:
            raise ExperimentError(
                str(out), f"holds results of an experiment with other {', '.join(differing)}; use another output folder"
            )
    out.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(experiment.as_dict(), indent=1))


def write_outputs(experiment: Experiment, records: Sequence[Record], out: Path) -> str:
    """Logs, database and summary from ``records``; returns the markdown summary."""
    logs = write_logs(experiment, records, out / "logs")
    if logs:
        to_database(logs, out / "benchmark.db")
    summaries = summarize(records, experiment.baseline_label, [p.label for p in experiment.planners])
    table = format_markdown(summaries, experiment.baseline_label)
    (out / "summary.md").write_text(table + "\n")
    (out / "summary.csv").write_text(format_csv(summaries))
    return table


def experiment_records(experiment: Experiment, store: ResultStore) -> list[Record]:
    """The records in ``store`` that belong to ``experiment`` (its problems, planners and run indices)."""
    keys = {task.key for task in experiment.tasks()}
    return [r for r in store.records() if (r["problem"], r["planner"], r["run"]) in keys]


def bench(
    experiment: Experiment, out: str | Path, jobs: int = 1, dask: str | None = None, progress: bool = True
) -> list[Record]:
    """Run what is missing of ``experiment`` into ``out`` and write the logs, database and summary.

    ``jobs`` runs at a time on this machine, or on the Dask cluster ``dask``. Returns
    the experiment's records (all of them, earlier sweeps' included).
    """
    out = Path(out)
    _claim(out, experiment)
    store = ResultStore(out / "results.jsonl")
    total = len(experiment.tasks())
    bar = tqdm(
        total=total,
        initial=len(experiment_records(experiment, store)),
        disable=not progress,
        unit="run",
        smoothing=0.1,
        dynamic_ncols=True,
    )

    def show(record: Record, counts: Progress) -> None:
        bar.update(1)
        bar.set_postfix(unsolved=counts.unsolved, crashed=counts.crashed, refresh=False)

    try:
        sweep(experiment, store, jobs=jobs, dask=dask, on_record=show)
    finally:
        bar.close()
        records = experiment_records(experiment, store)
        write_outputs(experiment, records, out)
    return records
