"""Plots of a benchmark output folder (matplotlib: ``pip install 'ompl-balance[plot]'``).

:func:`plot_folder` writes into ``OUT/plots/``:

* ``<problem>.png``: box plots of time and of validity checks per planner;
* ``success_vs_time.png``: per problem, the fraction of runs solved within ``t``
  seconds, ``t`` over the range of the observed times (log scale when they span more
  than a decade);
* ``progress_<problem>.png`` for problems where planners report a best cost while they
  run (RRT*): the median over runs of the best cost so far against time, per planner;
* ``summary.md`` and ``summary.csv``: medians, bootstrap 95 % intervals, ratios to
  the baseline planner (and pooled per scenario for MotionBenchMaker problems);
* ``trees_<problem>.png`` for each built-in 2-D problem: the start tree and the goal
  tree of ``BalancedRRTConnect`` with balancing on and off, seeded alike and stopped
  after the same number of iterations.

Curves differ by colour, marker and line style, so they stay apart where they overlap
and in grey print.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator, Sequence
from itertools import count
from pathlib import Path
from typing import Any

import numpy as np
from ompl import base as ob

from ..core.planner import GOAL_TAG, START_TAG
from ..planners import BalancedRRTConnect
from ..worlds.boxes import PROBLEMS
from .errors import ExperimentError, MissingExtraError
from .experiment import Experiment
from .results import Record, ResultStore
from .resume import experiment_records
from .summary import format_csv, format_markdown, pooled_by_scenario, summarize

MATPLOTLIB_MISSING = "plots need matplotlib: pip install 'ompl-balance[plot]'"

#: Progress properties that carry the best cost so far (RRTstar: REAL, BITstar: DOUBLE).
BEST_COST_PROPERTIES = ("best cost REAL", "best cost DOUBLE")


def require_matplotlib() -> None:
    """:class:`MissingExtraError` naming the install command when matplotlib cannot be imported."""
    try:
        import matplotlib  # noqa: F401
    except ImportError as error:
        raise MissingExtraError(MATPLOTLIB_MISSING) from error


def _pyplot() -> Any:
    require_matplotlib()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _styles() -> Iterator[dict[str, Any]]:
    """Colour, marker and line style per curve, all three changing from one curve to the next."""
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive"]
    markers = ["o", "s", "^", "D", "v", "P", "X", "*"]
    lines = ["-", "--", "-.", ":"]
    for i in count():
        yield {"color": colours[i % 8], "marker": markers[i % 8], "linestyle": lines[i % 4]}


def _time_axis(axis: Any, times: Sequence[float]) -> None:
    """Limit a time axis to the observed range, on a log scale when it spans more than a decade."""
    positive = [t for t in times if t > 0 and math.isfinite(t)]
    if not positive:
        return
    low, high = min(positive), max(positive)
    if high > 10 * low:
        from matplotlib.ticker import NullFormatter

        axis.set_xscale("log")
        axis.set_xlim(low / 1.2, high * 1.2)
        axis.xaxis.set_minor_formatter(NullFormatter())  # labels at the decades only: no overlaps
    else:
        margin = 0.05 * (high - low) or 0.05 * high
        axis.set_xlim(max(0.0, low - margin), high + margin)


def _by_planner(records: Sequence[Record], labels: Sequence[str], name: str) -> list[list[float]]:
    return [
        [r["properties"][name] for r in records if r["planner"] == label and r["properties"].get(name) is not None]
        for label in labels
    ]


def plot_problem(records: Sequence[Record], problem: str, labels: Sequence[str], path: Path) -> Path:
    """Box plots of time (s) and validity checks per planner on ``problem``."""
    plt = _pyplot()
    mine = [r for r in records if r["problem"] == problem]
    figure, axes = plt.subplots(1, 2, figsize=(4 + 1.2 * len(labels), 4.5), layout="constrained")
    for axis, (name, title) in zip(axes, (("time REAL", "time (s)"), ("validity checks INTEGER", "validity checks"))):
        values = _by_planner(mine, labels, name)
        axis.boxplot([v or [math.nan] for v in values], showfliers=True)
        axis.set_xticks(range(1, len(labels) + 1), labels, rotation=20, ha="right", fontsize=8)
        if all(x > 0 for v in values for x in v):
            axis.set_yscale("log")
        axis.set_ylabel(title)
    figure.suptitle(f"{problem}: time and validity checks per run ({len(mine)} runs)")
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


def _grid(count: int) -> tuple[int, int]:
    columns = min(4, count)
    return -(-count // columns), columns


def plot_success(records: Sequence[Record], experiment: Experiment, path: Path) -> Path:
    """Per problem, the fraction of runs solved within ``t`` seconds over the observed times."""
    plt = _pyplot()
    problems = [p.name for p in experiment.problems if any(r["problem"] == p.name for r in records)]
    rows, columns = _grid(len(problems))
    figure, axes = plt.subplots(
        rows, columns, figsize=(4 * columns, 3.2 * rows + 0.6), squeeze=False, layout="constrained"
    )
    for axis, problem in zip(axes.flat, problems):
        mine = [r for r in records if r["problem"] == problem]
        times = [r["properties"]["time REAL"] for r in mine if r["properties"].get("time REAL") is not None]
        _time_axis(axis, times)
        low, high = axis.get_xlim()
        grid = np.geomspace(low, high, 200) if axis.get_xscale() == "log" else np.linspace(low, high, 200)
        for planner, style in zip(experiment.planners, _styles()):
            runs = [r for r in mine if r["planner"] == planner.label]
            if not runs:
                continue
            solved_at = np.array([r["properties"]["time REAL"] for r in runs if r["properties"].get("solved BOOLEAN")])
            fraction = [(solved_at <= t).sum() / len(runs) for t in grid]
            axis.plot(grid, fraction, label=planner.label, markevery=20, markersize=4, **style)
        axis.set_title(problem, fontsize=9)
        axis.set_xlabel("time (s)")
        axis.set_ylim(-0.02, 1.05)
    for axis in axes[:, 0]:
        axis.set_ylabel("fraction solved")
    axes.flat[0].legend(fontsize=7)
    for axis in list(axes.flat)[len(problems) :]:
        axis.set_visible(False)
    figure.suptitle(f"{experiment.name}: runs solved within t seconds (time limit {experiment.time_limit:g} s)")
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


def _best_cost_series(record: Record) -> tuple[np.ndarray, np.ndarray] | None:
    """``(times, best costs)`` of a run whose planner reports its best cost while it runs: the
    progress samples (``inf`` before a path), then the cost of its solution when the solve
    ended (``time REAL``). ``None`` for a run without that progress property."""
    progress = record.get("progress") or {"properties": [], "samples": []}
    names = progress["properties"]
    column = next((names.index(n) for n in BEST_COST_PROPERTIES if n in names), None)
    if column is None or record["properties"].get("time REAL") is None:
        return None
    time_column = names.index("time REAL")
    times = [float(sample[time_column]) for sample in progress["samples"]]
    costs = [float(sample[column]) if sample[column] else math.inf for sample in progress["samples"]]
    end = record["properties"]["time REAL"]
    solved = record["properties"].get("solved BOOLEAN") and "solution length REAL" in record["properties"]
    if not times or end > times[-1]:
        times.append(end)
        costs.append(record["properties"]["solution length REAL"] if solved else (costs or [math.inf])[-1])
    return np.array(times), np.array(costs)


def median_best_cost(records: Sequence[Record], grid: np.ndarray) -> np.ndarray:
    """Median over runs of the best cost at each time of ``grid``: each run's value at or before
    it (``inf`` before its first value or path), its last value holding after it ends."""
    values = []
    for record in records:
        series = _best_cost_series(record)
        if series is None:
            continue
        times, costs = series
        index = np.searchsorted(times, grid, side="right") - 1
        values.append(np.where(index >= 0, costs[np.maximum(index, 0)], math.inf))
    if not values:
        return np.full(len(grid), math.nan)
    return np.median(np.array(values), axis=0)


def plot_progress(records: Sequence[Record], experiment: Experiment, problem: str, path: Path) -> Path | None:
    """Median best cost against time per planner that reports it while it runs, on ``problem``;
    ``None`` when no such planner has a median path at any time."""
    series = {id(r): s for r in records if r["problem"] == problem and (s := _best_cost_series(r)) is not None}
    mine = [r for r in records if id(r) in series]
    if not mine:
        return None
    plt = _pyplot()
    figure, axis = plt.subplots(figsize=(7, 4.5), layout="constrained")
    _time_axis(axis, [t for times, _ in series.values() for t in times])
    low, high = axis.get_xlim()
    grid = np.geomspace(low, high, 300) if axis.get_xscale() == "log" else np.linspace(low, high, 300)
    drawn = False
    for planner, style in zip(experiment.planners, _styles()):
        runs = [r for r in mine if r["planner"] == planner.label]
        median = median_best_cost(runs, grid)
        if runs and np.isfinite(median).any():
            shown = np.where(np.isfinite(median), median, np.nan)  # no line until half the runs have a path
            axis.plot(grid, shown, label=f"{planner.label} ({len(runs)} runs)", markevery=30, markersize=4, **style)
            drawn = True
    if not drawn:
        plt.close(figure)
        return None
    axis.set_xlabel("time (s)")
    axis.set_ylabel("median best cost (path length)")
    axis.legend(fontsize=8)
    figure.suptitle(f"{problem}: median best cost while planning (sampled every 0.05 s, then at the end)")
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


def grow_trees(problem: str, balance: bool, iterations: int, seed: int = 1) -> tuple[ob.PlannerData, int]:
    """``BalancedRRTConnect`` on built-in ``problem`` stopped after ``iterations`` iterations
    (or at the solution); returns its trees and the iterations run."""
    ss = PROBLEMS[problem].setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setBalanceTreeSizes(balance)
    planner.setSeed(seed)
    ss.setPlanner(planner)
    ss.setup()
    checks = 0

    def stop() -> bool:  # the planner asks once per iteration
        nonlocal checks
        checks += 1
        return checks > iterations

    ss.solve(ob.PlannerTerminationCondition(stop))
    return planner.plannerData(), planner.stats.iterations


TREES_CAPTION = (
    "Both panels use the same seed. Balanced growth departs from alternating growth only once the tree "
    "sizes differ by max_tree_size_ratio; until then the two draw the same samples, so on problems where "
    "the trees stay alike (open space, or a solution within a few iterations) the panels can look the same."
)


def plot_trees(problem: str, iterations: int, path: Path, seed: int = 1) -> Path:
    """Start tree (blue) and goal tree (orange) of balanced vs alternating growth, side by side."""
    plt = _pyplot()
    figure, axes = plt.subplots(1, 2, figsize=(10, 5.8), layout="constrained")
    query = PROBLEMS[problem]
    for axis, balance in zip(axes, (True, False)):
        data, done = grow_trees(problem, balance, iterations, seed)
        for x_min, y_min, x_max, y_max in query.boxes:
            axis.add_patch(plt.Rectangle((x_min, y_min), x_max - x_min, y_max - y_min, color="0.6"))
        points = np.array(
            [[data.getVertex(i).getState()[0], data.getVertex(i).getState()[1]] for i in range(data.numVertices())]
        )
        tags = np.array([data.getVertex(i).getTag() for i in range(data.numVertices())])
        for tag, colour, name in ((START_TAG, "tab:blue", "start tree"), (GOAL_TAG, "tab:orange", "goal tree")):
            for i in np.flatnonzero(tags == tag):
                for j in data.getEdges(int(i)):
                    axis.plot(points[[i, j], 0], points[[i, j], 1], color=colour, linewidth=0.6)
            axis.scatter(
                points[tags == tag, 0],
                points[tags == tag, 1],
                s=3,
                color=colour,
                label=f"{name} ({(tags == tag).sum()} states)",
            )
        axis.plot(*query.start, marker="*", markersize=16, color="tab:green", markeredgecolor="black", label="start")
        axis.plot(*query.goal, marker="X", markersize=13, color="tab:red", markeredgecolor="black", label="goal")
        axis.set_xlim(0, 1)
        axis.set_ylim(0, 1)
        axis.set_aspect("equal")
        ending = "solved after" if done < iterations else "stopped after"
        axis.set_title(
            f"{'balanced' if balance else 'alternating'} growth, {ending} {done} iteration{'s' * (done != 1)}",
            fontsize=10,
        )
        axis.legend(loc="lower right", fontsize=8, markerscale=0.6)
    figure.suptitle(f"{problem}: BalancedRRTConnect with balance_tree_sizes on / off, seed {seed}")
    figure.text(0.5, 0.005, TREES_CAPTION, ha="center", va="bottom", fontsize=8, wrap=True)
    figure.get_layout_engine().set(rect=(0, 0.07, 1, 0.93))
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


def _read_experiment(out: Path) -> Experiment:
    path = out / "experiment.json"
    try:
        return Experiment.from_dict(json.loads(path.read_text()))
    except OSError as error:
        raise ExperimentError(
            str(out), f"is not an output folder of ompl-balance bench or compare -o: {error}"
        ) from error
    except (json.JSONDecodeError, KeyError, TypeError) as error:
        raise ExperimentError(
            str(path), f"cannot be read as an experiment ({type(error).__name__}: {error})"
        ) from error


def plot_folder(out: str | Path, baseline: str | None = None, tree_iterations: int = 300) -> list[Path]:
    """All plots and summary tables of a ``bench``/``compare -o`` output folder; returns the files written."""
    out = Path(out)
    experiment = _read_experiment(out)
    records = experiment_records(experiment, ResultStore(out / "results.jsonl"))
    folder = out / "plots"
    folder.mkdir(exist_ok=True)
    labels = [p.label for p in experiment.planners]
    baseline = baseline or experiment.baseline_label
    summaries = summarize(records, baseline, labels)
    (folder / "summary.md").write_text(format_markdown(summaries, baseline) + "\n")
    (folder / "summary.csv").write_text(format_csv(summaries))
    written = [folder / "summary.md", folder / "summary.csv"]
    if any(problem.kind == "mbm" for problem in experiment.problems):  # MotionBenchMaker: also per scenario
        pooled = summarize(pooled_by_scenario(records), baseline, labels)
        (folder / "summary_by_scenario.md").write_text(format_markdown(pooled, baseline) + "\n")
        (folder / "summary_by_scenario.csv").write_text(format_csv(pooled))
        written += [folder / "summary_by_scenario.md", folder / "summary_by_scenario.csv"]
    if not records:
        return written
    for problem in experiment.problems:
        if any(r["problem"] == problem.name for r in records):
            written.append(plot_problem(records, problem.name, labels, folder / f"{problem.name}.png"))
            progress = plot_progress(records, experiment, problem.name, folder / f"progress_{problem.name}.png")
            if progress is not None:
                written.append(progress)
    written.append(plot_success(records, experiment, folder / "success_vs_time.png"))
    for problem in experiment.problems:
        if problem.kind == "builtin":
            written.append(
                plot_trees(problem.source, tree_iterations, folder / f"trees_{problem.name}.png", experiment.seed)
            )
    return written
