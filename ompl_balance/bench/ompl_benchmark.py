"""OMPL's own ``ompl.tools.Benchmark`` with this package's planners, its log complete.

``Benchmark`` reads a planner's parameters (``params().getParams``) and its graph
(``getPlannerData``) in C++, where OMPL 2.0's bindings show it neither the ``ParamSet`` of
a Python planner nor its graph: its log lists no parameters for them (two configurations
look alike) and ``graph states 0``. Nor can a post-run event fix that, since its run
properties reach Python as a copy. The experiment data ``Benchmark`` records can be written
to from Python, though, once it has run: :func:`run_ompl_benchmark` runs it, collecting what
each run of a package planner reports (:mod:`~ompl_balance.bench.planner_properties`), and
writes it in before you save the log::

    benchmark = ot.Benchmark(ss, "narrow")
    benchmark.addPlanner(BalancedRRTConnect(ss.getSpaceInformation()))
    run_ompl_benchmark(benchmark, ot.Request(1.0, 1000.0, 10))  # instead of benchmark.benchmark(...)
    benchmark.saveResultsToFile("narrow.log")

Stock planners' entries are left as ``Benchmark`` made them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ompl import base as ob
from ompl import tools as ot

from .planner_params import ompl_text, planner_params
from .planner_properties import graph_properties, stats_properties

#: Fields of a planner's ``stats`` that ``Benchmark`` measures itself.
_MEASURED_BY_BENCHMARK = ("status", "time")


def _is_package_planner(planner: ob.Planner) -> bool:
    return hasattr(planner, "plannerData") and hasattr(planner, "stats")


def run_ompl_benchmark(
    benchmark: ot.Benchmark,
    request: ot.Request,
    post_run: Callable[[ob.Planner, Any], None] | None = None,
) -> None:
    """``benchmark.benchmark(request)``, then this package's planners' parameters (as common
    properties) and each run's ``graph states``, ``graph motions`` and ``stats`` fields written
    into ``benchmark``'s recorded experiment, so that ``saveResultsToFile`` logs them.

    ``post_run`` is your own post-run event, if any (this function sets the benchmark's).

    What a run reports is matched to the run ``Benchmark`` recorded by position, not by name:
    ``Benchmark`` runs its planners in the order they were added, all runs of one before the
    next, and calls the post-run event once for every run it records. Two configurations of
    one planner under the same name (two ``BalancedRRTConnect(si)`` with different
    ``max_tree_size_ratio``) are logged each with its own parameters and runs.
    """
    reports: list[_RunReport | None] = []  # one per recorded run, in Benchmark's order (None: a stock planner)

    def collect(planner: ob.Planner, run: Any) -> None:
        reports.append(_report(planner) if _is_package_planner(planner) else None)
        if post_run is not None:
            post_run(planner, run)

    benchmark.setPostRunEvent(collect)
    benchmark.benchmark(request)
    experiments = benchmark.getRecordedExperimentData().planners  # Benchmark's own data, written in place
    recorded = sum(len(experiment.runs) for experiment in experiments)
    if recorded != len(reports):
        raise RuntimeError(
            f"ompl.tools.Benchmark recorded {recorded} runs but called the post-run event {len(reports)} times; "
            "the package planners' properties were not written, as they could not be matched to their runs"
        )
    first = 0
    for experiment in experiments:
        runs = experiment.runs
        own = reports[first : first + len(runs)]
        first += len(runs)
        for run, report in zip(runs, own):
            if report is not None:
                for key, value in report.properties.items():
                    run[key] = value
        params = next((report.params for report in own if report is not None), {})
        for key, value in params.items():
            experiment.common[key] = value


@dataclass(frozen=True)
class _RunReport:
    """What one run of a package planner reports: its parameters and its run properties (OMPL's strings)."""

    params: dict[str, str]
    properties: dict[str, str]


def _report(planner: ob.Planner) -> _RunReport:
    properties = {**graph_properties(planner), **stats_properties(planner, _MEASURED_BY_BENCHMARK)}
    return _RunReport(planner_params(planner), {key: ompl_text(value) for key, value in properties.items()})
