"""Plots of a benchmark output folder (matplotlib: ``pip install 'ompl-balance[plot]'``).

:func:`plot_folder` writes into ``OUT/plots/`` (files of an earlier definition go to
``OUT/superseded/plots/``):

* ``<problem>.png``: per planner, how its runs ended (solved, not solved, crashed or
  killed) and the success rate; the time to a solution and the validity checks of its
  solved runs, as box plots with every run drawn as a point;
* ``success_vs_time.png``: per problem, the fraction of runs that have a solution at time
  ``t``, for ``t`` up to the time limit (log scale when the solutions span more than a
  decade); crashed and unsolved runs count as runs without one;
* ``progress_<problem>.png`` for problems where planners that keep improving their
  solution (RRT*, BIT*, AORRTC, BallRadiusRRTstar) ran: the median over runs of the best
  cost so far against time, per such planner;
* ``summary.md`` and ``summary.csv``: medians, bootstrap 95 % intervals, ratios to
  the baseline planner (and pooled per scenario for MotionBenchMaker problems);
* ``trees_<problem>.png`` for each built-in 2-D problem: the start tree and the goal
  tree of ``BalancedRRTConnect`` with balancing on and off, seeded alike and stopped
  after the same number of iterations; one panel, saying so, where both made the same
  trees (balancing never chose another tree than alternation).

*Time to a solution* is the run's ``time`` for planners that stop at their first solution;
for planners that keep improving it until the time limit, whose ``time`` is the limit, it
is their ``first solution time`` (looked at once an iteration, see
:class:`~ompl_balance.bench.progress_sampler.FirstSolutionWatch`).
Curves differ by colour, marker and line style, so they stay apart where they overlap
and in grey print.
"""

from __future__ import annotations

import json
import math
import textwrap
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from itertools import count
from pathlib import Path
from typing import Any

import numpy as np
from ompl import base as ob

from ..core.planner import GOAL_TAG, START_TAG
from ..planners import BalancedRRTConnect
from ..worlds.boxes import PROBLEMS
from .errors import ExperimentError, MissingExtraError
from .execution import FIRST_SOLUTION_TIME
from .experiment import Experiment
from .problems import PROBLEM_KINDS
from .progress_sampler import BEST_COST_PROPERTIES
from .results import Record, ResultStore
from .resume import experiment_records, supersede_files
from .summary import format_csv, format_markdown, pooled_by_scenario, summarize

MATPLOTLIB_MISSING = "plots need matplotlib: pip install 'ompl-balance[plot]'"

#: How a run ended, in the order the outcome bars stack them, with their colours.
OUTCOMES = (("solved", "tab:green"), ("not solved", "tab:orange"), ("crashed or killed", "tab:red"))


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


def outcome(record: Record) -> str:
    """How a run ended: one of the names of :data:`OUTCOMES`."""
    if record["status"] == "CRASH" or record["error"]:
        return "crashed or killed"
    return "solved" if record["properties"].get("solved BOOLEAN") else "not solved"


def _best_cost_column(record: Record) -> int | None:
    names = (record.get("progress") or {}).get("properties", [])
    return next((names.index(n) for n in BEST_COST_PROPERTIES if n in names), None)


def time_to_solution(record: Record) -> float | None:
    """Seconds from the start of the solve to the run's (first) exact solution; ``None`` when
    it has none. For a planner that keeps improving its solution, its ``first solution time``;
    else (and for an improving planner that reports no best cost) the end of its solve."""
    if outcome(record) != "solved":
        return None
    properties = record["properties"]
    return float(properties.get(FIRST_SOLUTION_TIME, properties["time REAL"]))


def _log_axis(axis: Any, which: str, low: float, high: float) -> None:
    """A log scale on ``which`` (``"x"``/``"y"``) for values from ``low`` to ``high``, labelled at
    1, 2 and 5 times each power of ten when it spans up to two decades, at 1 and 3 up to
    three, else at the powers of ten: always several labels, never crowded."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    decades = math.log10(high / low)
    subs = (1.0, 2.0, 5.0) if decades <= 2 else (1.0, 3.0) if decades <= 3 else (1.0,)
    scaled = axis.xaxis if which == "x" else axis.yaxis
    (axis.set_xscale if which == "x" else axis.set_yscale)("log")
    scaled.set_major_locator(LogLocator(subs=subs))
    scaled.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    scaled.set_minor_formatter(NullFormatter())


def _spans_a_decade(values: Sequence[float]) -> bool:
    positive = [v for v in values if v > 0]
    return bool(positive) and max(positive) > 10 * min(positive)


def _outcome_counts(runs: Sequence[Record]) -> dict[str, int]:
    ended = [outcome(r) for r in runs]
    return {name: ended.count(name) for name, _ in OUTCOMES}


def _save(figure: Any, path: Path) -> Path:
    """Write ``figure`` to ``path`` (PNG, 120 dpi) and close it."""
    figure.savefig(path, dpi=120)
    _pyplot().close(figure)
    return path


def plot_problem(records: Sequence[Record], problem: str, labels: Sequence[str], time_limit: float, path: Path) -> Path:
    """:func:`problem_figure` written to ``path``."""
    return _save(problem_figure(records, problem, labels, time_limit), path)


def problem_figure(records: Sequence[Record], problem: str, labels: Sequence[str], time_limit: float) -> Any:
    """How each planner's runs on ``problem`` ended, and the time to a solution and the validity
    checks of its solved runs (box plots, every run a point): a matplotlib figure."""
    plt = _pyplot()
    mine = [r for r in records if r["problem"] == problem]
    labels = [label for label in labels if any(r["planner"] == label for r in mine)]
    runs = {label: [r for r in mine if r["planner"] == label] for label in labels}
    solved = {label: [r for r in runs[label] if outcome(r) == "solved"] for label in labels}
    # the planners' labels once, left of the first panel: repeated, long labels would squeeze the others
    figure, axes = plt.subplots(
        1, 3, figsize=(15, 2.2 + 0.4 * len(labels)), layout="constrained", sharey=True, squeeze=False
    )
    bars, times, checks = axes[0]
    positions = np.arange(len(labels))
    left = np.zeros(len(labels))
    for name, colour in OUTCOMES:
        widths = np.array([_outcome_counts(runs[label])[name] for label in labels])
        bars.barh(positions, widths, left=left, color=colour, label=name)
        left += widths
    for position, label in zip(positions, labels):
        rate = len(solved[label]) / len(runs[label])
        bars.text(left[position], position, f" {rate:.0%} solved", va="center", fontsize=8)
    bars.set_xlim(0, 1.35 * max(left))
    bars.set_xlabel("runs")
    bars.set_title("how the runs ended", fontsize=9)
    bars.legend(fontsize=7, ncols=3, loc="upper center", bbox_to_anchor=(0.5, -0.12 - 0.3 / len(labels)))
    for axis, values, title in (
        (times, [[time_to_solution(r) for r in solved[label]] for label in labels], "time to a solution (s)"),
        (
            checks,
            [[r["properties"]["validity checks INTEGER"] for r in solved[label]] for label in labels],
            "validity checks of the whole solve",
        ),
    ):
        _box_plot(axis, values)
        axis.set_title(f"{title}, solved runs", fontsize=9)
    bars.set_yticks(positions, labels, fontsize=8)
    bars.set_ylim(len(labels) - 0.5, -0.5)  # the first planner on top
    counts = {len(r) for r in runs.values()}
    per_planner = f"{counts.pop()} runs per planner" if len(counts) == 1 else "runs per planner as on the bars"
    figure.suptitle(f"{problem}: {per_planner}, time limit {time_limit:g} s", fontsize=10)
    return figure


def _horizontal() -> dict[str, Any]:
    """``boxplot``'s argument for horizontal boxes (``orientation`` since matplotlib 3.10, ``vert`` before)."""
    import matplotlib

    major, minor = (int(part) for part in matplotlib.__version__.split(".")[:2])
    return {"orientation": "horizontal"} if (major, minor) >= (3, 10) else {"vert": False}


def _box_plot(axis: Any, values: Sequence[Sequence[float | None]]) -> None:
    """Horizontal box plots of ``values`` per planner at rows 0, 1, ... (the labels are the shared
    y axis's), each value a point; "none solved" where empty."""
    positions = np.arange(len(values))
    present = [[v for v in cell if v is not None] for cell in values]
    filled = [i for i, cell in enumerate(present) if cell]
    if filled:
        axis.boxplot(
            [present[i] for i in filled],
            positions=positions[filled],
            showfliers=False,
            manage_ticks=False,  # the rows' ticks are the planners' labels
            **_horizontal(),
        )
        jitter = np.random.default_rng(0)
        for i in filled:
            offsets = jitter.uniform(-0.15, 0.15, len(present[i]))
            axis.scatter(present[i], i + offsets, s=6, color="tab:blue", alpha=0.5, zorder=3)
        every = [v for i in filled for v in present[i]]
        if _spans_a_decade(every) and min(every) > 0:
            _log_axis(axis, "x", min(every), max(every))
    for i, cell in enumerate(present):
        if not cell:
            axis.text(0.02, i, "none solved", transform=axis.get_yaxis_transform(), va="center", fontsize=8)
    axis.tick_params(axis="x", labelsize=8)


def _grid(count: int) -> tuple[int, int]:
    columns = min(4, count)
    return -(-count // columns), columns


def _time_grid(axis: Any, solution_times: Sequence[float], limit: float) -> np.ndarray:
    """Set a time axis from the first solution to ``limit`` (log when that spans more than a decade);
    returns the times to evaluate curves at."""
    first = min((t for t in solution_times if t > 0), default=limit)
    if _spans_a_decade([first, limit]):
        _log_axis(axis, "x", first, limit)
        axis.set_xlim(first / 1.2, limit * 1.05)
        return np.geomspace(first / 1.2, limit, 300)
    axis.set_xlim(0.0, limit * 1.02)
    return np.linspace(0.0, limit, 300)


def fraction_solved(runs: Sequence[Record], times: np.ndarray) -> np.ndarray:
    """The fraction of ``runs`` that have a solution at each of ``times`` (s since their solve
    began; :func:`time_to_solution`): unsolved and crashed runs count as runs without one."""
    solved_at = np.array([t for t in map(time_to_solution, runs) if t is not None])
    return np.array([(solved_at <= t).sum() / len(runs) for t in times])


def plot_success(records: Sequence[Record], experiment: Experiment, path: Path) -> Path:
    """Per problem, the fraction of runs with a solution at time ``t``, up to the time limit."""
    plt = _pyplot()
    problems = [p.name for p in experiment.problems if any(r["problem"] == p.name for r in records)]
    rows, columns = _grid(len(problems))
    figure, axes = plt.subplots(
        rows, columns, figsize=(4 * columns, 3 * rows + 1.2), squeeze=False, layout="constrained"
    )
    handles: dict[str, Any] = {}
    for axis, problem in zip(axes.flat, problems):
        mine = [r for r in records if r["problem"] == problem]
        solved_at = [t for t in map(time_to_solution, mine) if t is not None]
        grid = _time_grid(axis, solved_at, experiment.time_limit)
        for index, (planner, style) in enumerate(zip(experiment.planners, _styles())):
            runs = [r for r in mine if r["planner"] == planner.label]
            if not runs:
                continue
            # markers staggered from curve to curve, so curves on top of each other stay apart
            (line,) = axis.plot(
                grid, fraction_solved(runs, grid), markevery=((7 * index) % 50, 50), markersize=4, **style
            )
            handles[planner.label] = line
        axis.set_title(problem, fontsize=9)
        axis.set_xlabel("time (s)")
        axis.set_ylim(-0.02, 1.05)
    for axis in axes[:, 0]:
        axis.set_ylabel("fraction of the runs solved")
    for axis in list(axes.flat)[len(problems) :]:
        axis.set_visible(False)
    figure.legend(
        list(handles.values()), list(handles), loc="outside lower center", ncols=min(4, len(handles)), fontsize=8
    )
    figure.suptitle(
        f"{experiment.name}: fraction of the runs with a solution by time t (time limit {experiment.time_limit:g} s)",
        fontsize=10,
    )
    return _save(figure, path)


def _best_cost_series(record: Record) -> tuple[np.ndarray, np.ndarray] | None:
    """``(times, best costs)`` of a run whose planner reports its best cost while it runs: the
    progress samples (``inf`` before a path), then the cost of its solution when the solve
    ended (``time REAL``). ``None`` for a run without that progress property."""
    column = _best_cost_column(record)
    if column is None or record["properties"].get("time REAL") is None:
        return None
    progress = record["progress"]
    time_column = progress["properties"].index("time REAL")
    times = [float(sample[time_column]) for sample in progress["samples"]]
    costs = [float(sample[column]) if sample[column] else math.inf for sample in progress["samples"]]
    end = record["properties"]["time REAL"]
    solved = record["properties"].get("solved BOOLEAN") and "solution length REAL" in record["properties"]
    if not times or end > times[-1]:
        last = (costs or [math.inf])[-1]
        # the samples hold 6 significant digits (as OMPL writes them): the end's cost never exceeds the last one
        times.append(end)
        costs.append(min(last, record["properties"]["solution length REAL"]) if solved else last)
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


PROGRESS_CAPTION = (
    "Median over each planner's runs of the best path cost found so far, sampled every 0.05 s while it plans "
    "(a run's last value holds after it ends); the line starts once half of the runs have a solution. Only "
    "planners that keep improving their solution are drawn."
)


def plot_progress(records: Sequence[Record], experiment: Experiment, problem: str, path: Path) -> Path | None:
    """Median best cost against time per planner that keeps improving its solution, on ``problem``;
    ``None`` when no such planner has a median path at any time."""
    improving = [
        r for r in records if r["problem"] == problem and r.get("improves_cost") and _best_cost_series(r) is not None
    ]
    if not improving:
        return None
    plt = _pyplot()
    figure, axis = plt.subplots(figsize=(8, 5), layout="constrained")
    first = [t for r in improving if (t := time_to_solution(r)) is not None]
    grid = _time_grid(axis, first, experiment.time_limit)
    drawn = False
    for planner, style in zip(experiment.planners, _styles()):
        runs = [r for r in improving if r["planner"] == planner.label]
        median = median_best_cost(runs, grid)
        if runs and np.isfinite(median).any():
            shown = np.where(np.isfinite(median), median, np.nan)  # no line until half the runs have a path
            axis.plot(grid, shown, label=f"{planner.label} ({len(runs)} runs)", markevery=30, markersize=4, **style)
            drawn = True
    if not drawn:
        plt.close(figure)
        return None
    axis.ticklabel_format(axis="y", useOffset=False)
    low, high = axis.dataLim.y0, axis.dataLim.y1
    margin = 0.1 * max(high - low, 0.01 * abs(high))  # a flat median shows as flat, not as noise magnified
    axis.set_ylim(low - margin, high + margin)
    axis.set_xlabel("time (s)")
    axis.set_ylabel("median best cost (path length)")
    axis.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    axis.set_title(f"{problem}: median best cost while planning", fontsize=10)
    figure.supxlabel(textwrap.fill(PROGRESS_CAPTION, 140), fontsize=8)
    return _save(figure, path)


def grow_trees(problem: str, balance: bool, iterations: int, seed: int = 1) -> tuple[ob.PlannerData, int]:
    """``BalancedRRTConnect`` on built-in ``problem`` stopped after ``iterations`` iterations
    (or at the solution); returns its trees and the iterations run."""
    ss = PROBLEMS[problem].setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setBalanceTreeSizes(balance)
    planner.setSeed(seed)
    planner.setEngine("python")  # polls its condition every iteration (the compiled engine every millisecond)
    ss.setPlanner(planner)
    ss.setup()
    checks = 0

    def stop() -> bool:  # the planner asks once per iteration
        nonlocal checks
        checks += 1
        return checks > iterations

    ss.solve(ob.PlannerTerminationCondition(stop))
    return planner.plannerData(), planner.stats.iterations


@dataclass(frozen=True)
class TreePicture:
    """The two trees of a planner graph as drawn: states' ``(x, y)``, their tags (start or goal
    tree), the edges, and the iterations that grew them."""

    points: np.ndarray  # (n, 2)
    tags: np.ndarray  # (n,)
    edges: tuple[tuple[int, int], ...]
    iterations: int

    @classmethod
    def grown(cls, problem: str, balance: bool, iterations: int, seed: int) -> TreePicture:
        """The trees of :func:`grow_trees`."""
        data, done = grow_trees(problem, balance, iterations, seed)
        vertices = [data.getVertex(i) for i in range(data.numVertices())]
        return cls(
            points=np.array([[v.getState()[0], v.getState()[1]] for v in vertices]).reshape(-1, 2),
            tags=np.array([v.getTag() for v in vertices]),
            edges=tuple((i, int(j)) for i in range(len(vertices)) for j in data.getEdges(i)),
            iterations=done,
        )

    def same_as(self, other: TreePicture) -> bool:
        """Whether ``other`` holds the same trees."""
        return (
            self.iterations == other.iterations
            and self.edges == other.edges
            and np.array_equal(self.tags, other.tags)
            and np.array_equal(self.points, other.points)
        )

    def size(self, tag: int) -> int:
        return int((self.tags == tag).sum())


TREES_CAPTION = (
    "Both panels use the same seed. Balanced growth departs from alternating growth only once the tree "
    "sizes differ by max_tree_size_ratio; until then the two draw the same samples into the same trees."
)

SAME_TREES_CAPTION = (
    "Seeded alike, balanced and alternating growth made the same trees: balancing grows the smaller tree once the "
    "tree sizes differ by max_tree_size_ratio, and here it never chose another tree than alternation would have "
    "(the trees stay alike in size), so both drew the same samples. Problems where one tree is trapped show the "
    "difference."
)


def tree_panels(problem: str, iterations: int, seed: int = 1) -> list[tuple[str, TreePicture]]:
    """The panels of :func:`plot_trees`, each a title and trees: balanced growth and alternating
    growth, or one panel when both made the same trees (the same picture twice would look like
    a comparison)."""
    balanced, alternating = (TreePicture.grown(problem, balance, iterations, seed) for balance in (True, False))
    if balanced.same_as(alternating):
        return [("balanced and alternating growth: the same trees", balanced)]
    return [("balanced growth", balanced), ("alternating growth", alternating)]


def plot_trees(problem: str, iterations: int, path: Path, seed: int = 1) -> Path:
    """Start tree (blue) and goal tree (orange) of balanced vs alternating growth, side by side; one
    panel, saying so, when both made the same trees (:func:`tree_panels`)."""
    plt = _pyplot()
    panels = tree_panels(problem, iterations, seed)
    same = len(panels) == 1
    figure, axes = plt.subplots(
        1, len(panels), figsize=(7, 7) if same else (10, 6.6), layout="constrained", squeeze=False
    )
    query = PROBLEMS[problem]
    for axis, (growth, trees) in zip(axes[0], panels):
        for x_min, y_min, x_max, y_max in query.boxes:
            axis.add_patch(plt.Rectangle((x_min, y_min), x_max - x_min, y_max - y_min, color="0.6"))
        for tag, colour, name in ((START_TAG, "tab:blue", "start tree"), (GOAL_TAG, "tab:orange", "goal tree")):
            for i, j in trees.edges:
                if trees.tags[i] == tag:
                    axis.plot(trees.points[[i, j], 0], trees.points[[i, j], 1], color=colour, linewidth=0.6)
            mine = trees.points[trees.tags == tag]
            axis.scatter(mine[:, 0], mine[:, 1], s=3, color=colour, label=name)
        axis.plot(*query.start, marker="*", markersize=16, color="tab:green", markeredgecolor="black", label="start")
        axis.plot(*query.goal, marker="X", markersize=13, color="tab:red", markeredgecolor="black", label="goal")
        axis.set_xlim(0, 1)
        axis.set_ylim(0, 1)
        axis.set_aspect("equal")
        ending = "solved after" if trees.iterations < iterations else "stopped after"
        axis.set_title(
            f"{growth}\n{ending} {trees.iterations} iteration{'s' * (trees.iterations != 1)}\n"
            f"start tree {trees.size(START_TAG)} states, goal tree {trees.size(GOAL_TAG)} states",
            fontsize=10,
        )
        axis.legend(loc="upper center", bbox_to_anchor=(0.5, -0.06), ncols=4, fontsize=8, markerscale=0.8)
    figure.suptitle(f"{problem}: BalancedRRTConnect with balance_tree_sizes on / off, seed {seed}")
    figure.supxlabel(textwrap.fill(SAME_TREES_CAPTION if same else TREES_CAPTION, 110 if same else 170), fontsize=8)
    return _save(figure, path)


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
    """All plots and summary tables of a ``bench``/``compare -o`` output folder; returns the files
    written (those an earlier call wrote that this one does not go to ``superseded/plots``)."""
    out = Path(out)
    experiment = _read_experiment(out)
    labels = [p.label for p in experiment.planners]
    baseline = baseline or experiment.baseline_label
    if baseline not in labels:
        raise ExperimentError("baseline", f"{baseline!r} is not a planner of {out}; its planners: {', '.join(labels)}")
    records = experiment_records(experiment, ResultStore(out / "results.jsonl"))
    folder = out / "plots"
    folder.mkdir(exist_ok=True)
    summaries = summarize(records, baseline, labels)
    (folder / "summary.md").write_text(format_markdown(summaries, baseline) + "\n")
    (folder / "summary.csv").write_text(format_csv(summaries))
    written = [folder / "summary.md", folder / "summary.csv"]
    if any(PROBLEM_KINDS[problem.kind].scenarios for problem in experiment.problems):  # also per scenario
        pooled = summarize(pooled_by_scenario(records), baseline, labels)
        (folder / "summary_by_scenario.md").write_text(format_markdown(pooled, baseline) + "\n")
        (folder / "summary_by_scenario.csv").write_text(format_csv(pooled))
        written += [folder / "summary_by_scenario.md", folder / "summary_by_scenario.csv"]
    if records:
        for problem in experiment.problems:
            if any(r["problem"] == problem.name for r in records):
                written.append(
                    plot_problem(records, problem.name, labels, experiment.time_limit, folder / f"{problem.name}.png")
                )
                progress = plot_progress(records, experiment, problem.name, folder / f"progress_{problem.name}.png")
                if progress is not None:
                    written.append(progress)
        written.append(plot_success(records, experiment, folder / "success_vs_time.png"))
        for problem in experiment.problems:
            if problem.kind == "builtin":
                written.append(
                    plot_trees(problem.source, tree_iterations, folder / f"trees_{problem.name}.png", experiment.seed)
                )
    supersede_files(out, "plots", written)
    return written
