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
    """
    reports: dict[str, list[dict[str, str]]] = {}  # per planner name, one report per run
    params: dict[str, dict[str, str]] = {}

    def collect(planner: ob.Planner, run: Any) -> None:
        if _is_package_planner(planner):
            name = planner.getName()
            params.setdefault(name, planner_params(planner))
            properties = {**graph_properties(planner), **stats_properties(planner, _MEASURED_BY_BENCHMARK)}
            reports.setdefault(name, []).append({key: ompl_text(value) for key, value in properties.items()})
        if post_run is not None:
            post_run(planner, run)

    benchmark.setPostRunEvent(collect)
    benchmark.benchmark(request)
    for experiment in benchmark.getRecordedExperimentData().planners:  # Benchmark's own data, written in place
        name = experiment.name.removeprefix("geometric_").removeprefix("control_")
        for key, value in params.get(name, {}).items():
            experiment.common[key] = value
        for run, report in zip(experiment.runs, reports.get(name, [])):
            for key, value in report.items():
                run[key] = value
