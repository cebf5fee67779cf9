"""Summaries of sweep results: medians with bootstrap 95 % intervals, and ratios to a baseline.

Per (problem, planner) cell: the success rate over all its runs, and the median time,
validity checks and nodes of its solved runs only: a run that failed ran until its limit
(or crashed), so its time and work say how long the limit was, not what a solution cost,
and counting them would make a planner that fails quickly look cheap. Ratios are medians of
the cell's solved runs over medians of the baseline planner's solved runs on the same
problem, none where either solved no run; their intervals come from resampling both cells
independently (percentile bootstrap, fixed seed so a table is reproducible from its results).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from .results import Record

BOOTSTRAP_SAMPLES = 2000
Interval = tuple[float, float]


def _bootstrap_medians(values: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    return np.median(rng.choice(values, size=(BOOTSTRAP_SAMPLES, len(values))), axis=1)


def _interval(samples: np.ndarray) -> Interval:
    low, high = np.percentile(samples, [2.5, 97.5])
    return float(low), float(high)


@dataclass(frozen=True)
class Measure:
    """A median with its 95 % interval, and its ratio to the baseline's median with that ratio's interval."""

    median: float
    interval: Interval
    ratio: float
    ratio_interval: Interval


NAN_MEASURE = Measure(math.nan, (math.nan, math.nan), math.nan, (math.nan, math.nan))


def measure(
    values: Sequence[float], baseline: Sequence[float], rng: np.random.Generator, is_baseline: bool = False
) -> Measure:
    """Median of ``values`` and its ratio to the median of ``baseline``, each with a bootstrap 95 % interval.

    The baseline's own ratio is exactly 1 (``is_baseline``); no baseline runs give a NaN ratio.
    """
    mine, base = np.asarray(values, float), np.asarray(baseline, float)
    if len(mine) == 0:
        return NAN_MEASURE
    samples = _bootstrap_medians(mine, rng)
    median = float(np.median(mine))
    if is_baseline:
        return Measure(median, _interval(samples), 1.0, (1.0, 1.0))
    if len(base) == 0 or np.median(base) <= 0:
        return Measure(median, _interval(samples), math.nan, (math.nan, math.nan))
    base_samples = _bootstrap_medians(base, rng)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = samples / base_samples
    return Measure(median, _interval(samples), median / float(np.median(base)), _interval(ratios))


@dataclass(frozen=True)
class CellSummary:
    """One (problem, planner) cell."""

    problem: str
    planner: str
    runs: int
    crashed: int  # CRASH, or killed at the hard limit
    success: float  # fraction of runs with an exact solution
    time: Measure  # s, of the solved runs
    checks: Measure  # validity checks of the solved runs
    nodes: Measure  # states in the planner's graph (both trees for RRT-Connect), of the solved runs


def _solved(records: Iterable[Record]) -> list[Record]:
    """The runs that ended with an exact solution."""
    return [r for r in records if r["properties"].get("solved BOOLEAN")]


def _values(records: Iterable[Record], name: str) -> list[float]:
    return [r["properties"][name] for r in records if r["properties"].get(name) is not None]


def summarize(records: Iterable[Record], baseline: str, order: Sequence[str] = ()) -> list[CellSummary]:
    """One :class:`CellSummary` per cell, problems in first-seen order, planners in ``order`` (then first-seen)."""
    cells: dict[tuple[str, str], list[Record]] = {}
    for record in records:
        cells.setdefault((record["problem"], record["planner"]), []).append(record)
    rank = {label: i for i, label in enumerate(order)}
    problems = list(dict.fromkeys(problem for problem, _ in cells))
    keys = sorted(cells, key=lambda k: (problems.index(k[0]), rank.get(k[1], len(rank))))
    rng = np.random.default_rng(0)
    summaries = []
    for problem, planner in keys:
        runs = cells[problem, planner]
        solved = _solved(runs)
        base = _solved(cells.get((problem, baseline), [])) if planner != baseline else []
        measures = {
            name: measure(_values(solved, name), _values(base, name), rng, planner == baseline)
            for name in ("time REAL", "validity checks INTEGER", "graph states INTEGER")
        }
        summaries.append(
            CellSummary(
                problem=problem,
                planner=planner,
                runs=len(runs),
                crashed=sum(bool(r["error"]) for r in runs),
                success=len(solved) / len(runs),
                time=measures["time REAL"],
                checks=measures["validity checks INTEGER"],
                nodes=measures["graph states INTEGER"],
            )
        )
    return summaries


def pooled_by_scenario(records: Iterable[Record]) -> list[Record]:
    """The records with each MotionBenchMaker problem (``scenario.NNN``) renamed to its scenario.

    Summarizing these pools every run of a scenario's problems into one cell per planner.
    """
    return [{**record, "problem": record["problem"].split(".")[0]} for record in records]


def _with_interval(value: float, interval: Interval, digits: int) -> str:
    if math.isnan(value):
        return "-"
    return f"{value:.{digits}f} [{interval[0]:.{digits}f}, {interval[1]:.{digits}f}]"


def legend(baseline: str) -> str:
    """What the summary's medians and ratios are taken over, in one line."""
    return (
        "Success over all runs; times, validity checks and nodes are medians [95 % intervals] of the solved "
        f"runs only, ratios are to {baseline}'s solved runs; - where a planner or {baseline} solved no run."
    )


def format_markdown(summaries: Sequence[CellSummary], baseline: str) -> str:
    """The :func:`legend`, then a markdown table per problem: success, medians of time, validity checks
    and nodes of the solved runs, and their ratios to ``baseline``, each with its 95 % interval."""
    header = (
        f"| planner | runs | success | median time (ms) | time ratio to {baseline} | median validity checks "
        f"| checks ratio to {baseline} | median nodes | nodes ratio to {baseline} |\n|---|---|---|---|---|---|---|---|---|"
    )
    blocks = []
    for problem in dict.fromkeys(s.problem for s in summaries):
        rows = []
        for s in (s for s in summaries if s.problem == problem):
            crashed = f" ({s.crashed} crashed)" if s.crashed else ""
            time_ms = (s.time.median * 1e3, (s.time.interval[0] * 1e3, s.time.interval[1] * 1e3))
            rows.append(
                f"| {s.planner} | {s.runs}{crashed} | {s.success:.0%} | {_with_interval(*time_ms, 1)} "
                f"| {_with_interval(s.time.ratio, s.time.ratio_interval, 2)} | {_with_interval(s.checks.median, s.checks.interval, 0)} "
                f"| {_with_interval(s.checks.ratio, s.checks.ratio_interval, 2)} "
                f"| {_with_interval(s.nodes.median, s.nodes.interval, 0)} | {_with_interval(s.nodes.ratio, s.nodes.ratio_interval, 2)} |"
            )
        blocks.append(f"### {problem}\n\n{header}\n" + "\n".join(rows))
    return "\n\n".join([legend(baseline), *blocks])


def format_csv(summaries: Sequence[CellSummary]) -> str:
    """The summaries as CSV, one row per cell, intervals as ``_low``/``_high`` columns (medians and
    ratios of the solved runs, nan where there are none)."""
    columns = ["problem", "planner", "runs", "crashed", "success"]
    for name in ("time", "checks", "nodes"):
        columns += [
            f"{name}_median",
            f"{name}_low",
            f"{name}_high",
            f"{name}_ratio",
            f"{name}_ratio_low",
            f"{name}_ratio_high",
        ]
    out = io.StringIO()
    writer = csv.writer(out)
    writer.writerow(columns)
    for s in summaries:
        row = [s.problem, s.planner, s.runs, s.crashed, s.success]
        for m in (s.time, s.checks, s.nodes):
            row += [m.median, *m.interval, m.ratio, *m.ratio_interval]
        writer.writerow(row)
    return out.getvalue()
