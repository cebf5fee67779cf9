"""OMPL benchmark logs from sweep results, and their SQLite database.

:func:`write_logs` writes one log per problem in the grammar of OMPL's
``Benchmark::saveResultsToStream`` (``src/ompl/tools/benchmark/src/Benchmark.cpp``):
header, the ``status`` enum, then per planner its parameters as *common properties*
(``name = value``), the sorted union of the run properties (``"time REAL"``,
``"validity checks INTEGER"``, ...) and one ``value; value; ...; `` line per run (empty
where a run lacks a property, e.g. tree sizes of a crashed run), and, for a planner with
progress properties, the progress section: ``N progress properties for each run``, their
names (``"time REAL"`` among them, sorted), ``R runs`` and per run one line of samples,
each ``value,value,...,`` followed by ``;``. Unlike a stock ``ompl.tools.Benchmark`` log
made from Python, the parameters, counters and progress of this package's planners are in it.

:func:`to_database` converts logs with the converter that ships with the ``ompl``
package (``ompl.tools.readBenchmarkLog``) and adds its views (``computeViews``), exactly
as ``ompl_benchmark_statistics logs/*.log -d benchmark.db`` does, so the database is the
one Planner Arena and OMPL's plotting scripts read.
"""

from __future__ import annotations

import contextlib
import datetime
import io
import platform
import socket
from collections.abc import Iterable, Sequence
from importlib import metadata
from pathlib import Path

from ompl import base as ob
from ompl import tools as ot

from .experiment import Experiment
from .results import STATUS_INDEX, Record


def _status_enum_line() -> str:
    members = ob.PlannerStatus.PlannerStatusType.__members__
    names = [ob.PlannerStatus(members[name]).asString() for name in sorted(STATUS_INDEX, key=STATUS_INDEX.__getitem__)]
    return "status|" + "|".join(names)


def _value(value: object) -> str:
    text = repr(value) if isinstance(value, float) else str(value)
    if "; " in text or "\n" in text:
        raise ValueError(f"a run property value may not contain '; ' or a newline: {text!r}")
    return text


def format_log(experiment: Experiment, problem: str, records: Sequence[Record], started: str = "") -> str:
    """The OMPL log text of ``problem``: its records, grouped by planner in the experiment's order."""
    planners = [p for p in experiment.planners if any(r["planner"] == p.label for r in records)]
    spec = next(p for p in experiment.problems if p.name == problem)
    named_by_getters = {r["planner"] for r in records if r.get("param_names") == "getters"}
    setup = f"problem {problem}: {spec.description}\n" + "".join(
        f"planner {p.label}: {p.name or p.factory} {dict(p.params)}"
        + (
            " (parameters named after its get/set methods: OMPL's declared names are not known)"
            if p.label in named_by_getters
            else ""
        )
        + "\n"
        for p in planners
    )
    lines = [
        f"OMPL version {metadata.version('ompl')}",
        f"Experiment {experiment.name}.{problem}",
        "0 experiment properties",
        f"Running on {socket.gethostname()}",
        f"Starting at {started or datetime.datetime.now().strftime('%Y-%b-%d %H:%M:%S')}",
        "<<<|",
        setup + "|>>>",
        "<<<|",
        f"{platform.platform()}, {platform.processor() or platform.machine()}\n|>>>",
        f"{experiment.seed} is the random seed",
        f"{experiment.time_limit!r} seconds per run",
        f"{experiment.memory_limit!r} MB per run",
        f"{experiment.runs} runs per planner",
        f"{sum(r['properties'].get('time REAL', 0.0) for r in records)!r} seconds spent to collect the data",
        "1 enum type",
        _status_enum_line(),
        f"{len(planners)} planners",
    ]
    for planner in planners:
        runs = sorted((r for r in records if r["planner"] == planner.label), key=lambda r: r["run"])
        params = next((r["params"] for r in runs if r["params"]), dict(planner.params))
        properties = sorted({name for r in runs for name in r["properties"]} | {"seed INTEGER"})
        lines += [planner.label, f"{len(params)} common properties"]
        lines += [f"{name} = {params[name]}" for name in sorted(params)]
        lines += [f"{len(properties)} properties for each run", *properties, f"{len(runs)} runs"]
        for run in runs:
            values = {**run["properties"], "seed INTEGER": run["seed"]}
            lines.append("".join(f"{_value(values[name]) if name in values else ''}; " for name in properties))
        lines += _progress_section(runs)
        lines.append(".")
    return "\n".join(lines) + "\n"


def _progress_section(runs: Sequence[Record]) -> list[str]:
    """The progress lines of a planner's runs (none when no run reports progress).

    Every run has its line, in the order of the run lines (OMPL's converter pairs them by
    position); a run without samples (it ended within the first period, or crashed) has
    an empty one.
    """
    if not any("progress" in run for run in runs):
        return []
    names = sorted({name for run in runs for name in run.get("progress", {}).get("properties", ())})
    lines = [f"{len(names)} progress properties for each run", *names, f"{len(runs)} runs"]
    for run in runs:
        progress = run.get("progress", {"properties": [], "samples": []})
        column = {name: i for i, name in enumerate(progress["properties"])}
        lines.append(
            "".join(
                "".join(f"{_progress_value(sample[column[n]]) if n in column else ''}," for n in names) + ";"
                for sample in progress["samples"]
            )
        )
    return lines


def _progress_value(text: str) -> str:
    if "," in text or ";" in text or "\n" in text:
        raise ValueError(f"a progress value may not contain ',', ';' or a newline: {text!r}")
    return text


def write_logs(experiment: Experiment, records: Iterable[Record], folder: str | Path) -> list[Path]:
    """One ``<experiment>.<problem>.log`` per problem that has records; returns the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    records = list(records)
    paths = []
    for problem in experiment.problems:
        mine = [r for r in records if r["problem"] == problem.name]
        if mine:
            path = folder / f"{experiment.name}.{problem.name}.log"
            path.write_text(format_log(experiment, problem.name, mine))
            paths.append(path)
    return paths


def to_database(logs: Sequence[str | Path], database: str | Path) -> Path:
    """Convert OMPL logs to a fresh SQLite database with OMPL's own converter and views
    (``bestPlannerConfigs``, ``bestPlannerConfigsPerExperiment``); returns its path."""
    database = Path(database)
    database.unlink(missing_ok=True)
    with contextlib.redirect_stdout(io.StringIO()):  # the converter prints a line per log and planner
        ot.readBenchmarkLog(str(database), [str(log) for log in logs], False)
    ot.computeViews(str(database), False)
    return database
