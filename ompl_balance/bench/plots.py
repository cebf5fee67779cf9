"""Plots of a benchmark output folder (matplotlib: ``pip install 'ompl-balance[plot]'``).

:func:`plot_folder` writes into ``OUT/plots/``:

* ``<problem>.png``: box plots of time and of validity checks per planner;
* ``success_vs_time.png``: per problem, the fraction of runs solved within ``t``
  seconds as ``t`` grows to the time limit;
* ``summary.md`` and ``summary.csv``: medians, bootstrap 95 % intervals, ratios to
  the baseline planner;
* ``trees_<problem>.png`` for each built-in 2-D problem: the start tree and the goal
  tree of ``BalancedRRTConnect`` with balancing on and off, seeded alike and stopped
  after the same number of iterations.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from ompl import base as ob

from ..core.planner import GOAL_TAG, START_TAG
from ..planners import BalancedRRTConnect
from ..worlds.boxes import PROBLEMS
from .compare import experiment_records
from .experiment import Experiment
from .runner import Record, ResultStore
from .summary import format_csv, format_markdown, pooled_by_scenario, summarize


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as error:
        raise ImportError("plots need matplotlib: pip install 'ompl-balance[plot]'") from error
    return plt


def _by_planner(records: Sequence[Record], labels: Sequence[str], name: str) -> list[list[float]]:
    return [
        [r["properties"][name] for r in records if r["planner"] == label and r["properties"].get(name) is not None]
        for label in labels
    ]


def plot_problem(records: Sequence[Record], problem: str, labels: Sequence[str], path: Path) -> Path:
    """Box plots of time (s) and validity checks per planner on ``problem``."""
    plt = _pyplot()
    mine = [r for r in records if r["problem"] == problem]
    figure, axes = plt.subplots(1, 2, figsize=(4 + 1.2 * len(labels), 4))
    for axis, (name, title) in zip(axes, (("time REAL", "time (s)"), ("validity checks INTEGER", "validity checks"))):
        axis.boxplot(_by_planner(mine, labels, name), showfliers=True)
        axis.set_xticks(range(1, len(labels) + 1), labels, rotation=20, ha="right", fontsize=8)
        axis.set_yscale("log")
        axis.set_title(f"{problem}: {title}")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


def plot_success(records: Sequence[Record], experiment: Experiment, path: Path) -> Path:
    """Per problem, the fraction of runs solved within ``t`` seconds, ``t`` up to the time limit."""
    plt = _pyplot()
    problems = [p.name for p in experiment.problems if any(r["problem"] == p.name for r in records)]
    columns = min(4, len(problems))
    rows = -(-len(problems) // columns)
    figure, axes = plt.subplots(rows, columns, figsize=(4 * columns, 3 * rows), squeeze=False)
    limits = np.linspace(0.0, experiment.time_limit, 200)
    for axis, problem in zip(axes.flat, problems):
        for planner in experiment.planners:
            runs = [r for r in records if r["problem"] == problem and r["planner"] == planner.label]
            if not runs:
                continue
            solved_at = np.array([r["properties"]["time REAL"] for r in runs if r["properties"].get("solved BOOLEAN")])
            axis.plot(limits, [(solved_at <= t).sum() / len(runs) for t in limits], label=planner.label)
        axis.set_title(problem, fontsize=9)
        axis.set_xlabel("time limit (s)")
        axis.set_ylim(0, 1.05)
    axes.flat[0].set_ylabel("success rate")
    axes.flat[0].legend(fontsize=7)
    for axis in list(axes.flat)[len(problems) :]:
        axis.set_visible(False)
    figure.tight_layout()
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


def plot_trees(problem: str, iterations: int, path: Path, seed: int = 1) -> Path:
    """Start tree (blue) and goal tree (orange) of balanced vs alternating growth, side by side."""
    plt = _pyplot()
    figure, axes = plt.subplots(1, 2, figsize=(10, 5))
    for axis, balance in zip(axes, (True, False)):
        data, done = grow_trees(problem, balance, iterations, seed)
        for x_min, y_min, x_max, y_max in PROBLEMS[problem].boxes:
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
        axis.set_xlim(0, 1)
        axis.set_ylim(0, 1)
        axis.set_aspect("equal")
        axis.set_title(f"{'balanced' if balance else 'alternating'} growth, {done} iterations", fontsize=10)
        axis.legend(loc="lower right", fontsize=8)
    figure.suptitle(f"{problem}: BalancedRRTConnect, balance_tree_sizes on / off, seed {seed}")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


def plot_folder(out: str | Path, baseline: str | None = None, tree_iterations: int = 300) -> list[Path]:
    """All plots and summary tables of a ``bench``/``compare -o`` output folder; returns the files written."""
    out = Path(out)
    if not (out / "experiment.json").is_file():
        raise FileNotFoundError(f"{out} holds no experiment.json: is it an output folder of ompl-balance bench?")
    experiment = Experiment.from_dict(json.loads((out / "experiment.json").read_text()))
    records = experiment_records(experiment, ResultStore(out / "results.jsonl"))
    folder = out / "plots"
    folder.mkdir(exist_ok=True)
    labels = [p.label for p in experiment.planners]
    baseline = baseline or experiment.baseline_label
    summaries = summarize(records, baseline, labels)
    (folder / "summary.md").write_text(format_markdown(summaries, baseline) + "\n")
    (folder / "summary.csv").write_text(format_csv(summaries))
    written = [folder / "summary.md", folder / "summary.csv"]
    if any("." in problem.name for problem in experiment.problems):  # MotionBenchMaker: also per scenario
        pooled = summarize(pooled_by_scenario(records), baseline, labels)
        (folder / "summary_by_scenario.md").write_text(format_markdown(pooled, baseline) + "\n")
        (folder / "summary_by_scenario.csv").write_text(format_csv(pooled))
        written += [folder / "summary_by_scenario.md", folder / "summary_by_scenario.csv"]
    for problem in experiment.problems:
        if any(r["problem"] == problem.name for r in records):
            written.append(plot_problem(records, problem.name, labels, folder / f"{problem.name}.png"))
    written.append(plot_success(records, experiment, folder / "success_vs_time.png"))
    for problem in experiment.problems:
        if problem.kind == "builtin":
            written.append(
                plot_trees(problem.source, tree_iterations, folder / f"trees_{problem.name}.png", experiment.seed)
            )
    return written
